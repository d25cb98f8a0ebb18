"""Sweep files (``SWEEP.yaml``): a base case, the parameters varied over it, and their runs.

A sweep file holds ``base`` (a case file, relative to the sweep file), ``command`` (``run``,
``modal``, ``fatigue``, or ``bloch``: the Bloch prediction alone; the job each run is),
``reference`` (a case file, e.g. the healthy body, run once with the sweep's ``set``: a modal
sweep compares every run's modes with its modes by MAC; a run sweep's dataset holds its series
as the baseline, e.g. the healthy plate's sensor signals), ``set`` (overrides for every run),
``vary`` (one block or a list of blocks, combined as a product; a block is ``product``,
``zip``, ``list`` or ``random``), ``labels`` (varied names that are not case entries, e.g. a
damage type, usable in expressions), ``derived`` (case entries computed from the others with
the expressions of :mod:`peridyn.physics.expressions`, in order), ``derived_by`` (more derived
entries chosen by the value of a label: ``{label: {value: {key: expression}}}``) and
``outputs`` (which summary scalars and which results series to collect). A parameter is named
by its ``--set`` path (``material.E``, ``precracks.0.end.1``). docs/sweeps.md describes the
format with examples.

:func:`expand` turns a sweep file into its runs, each with its parameters, its validated case
and its id (the case's hash, :func:`peridyn.setup.identity.case_identity`); every case is validated
before anything runs.
"""

from __future__ import annotations

import copy
import itertools
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import (
    Case,
    apply_override,
    first_problem,
    load_case,
    parse_yaml,
    read_yaml_mapping,
    validate_case,
)
from peridyn.io.text_file import read_input_text
from peridyn.physics.expressions import evaluate
from peridyn.setup.identity import case_identity

#: Characters of the case hash that name a run's folder.
ID_LENGTH = 16


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class Distribution(_Strict):
    """One random parameter: ``uniform: [low, high]``, ``loguniform: [low, high]`` (low > 0)
    or ``choice: [values...]``."""

    uniform: Annotated[list[float], Field(min_length=2, max_length=2)] | None = None
    loguniform: Annotated[list[float], Field(min_length=2, max_length=2)] | None = None
    choice: Annotated[list[Any], Field(min_length=1)] | None = None

    @model_validator(mode="after")
    def _one(self):
        given = [k for k in ("uniform", "loguniform", "choice") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of uniform, loguniform, choice (got {given or 'none'})")
        if self.loguniform is not None and min(self.loguniform) <= 0:
            raise ValueError(f"loguniform bounds must be > 0, got {self.loguniform}")
        return self

    def draw(self, rng: np.random.Generator, n: int) -> list:
        """``n`` values (Python numbers, or the ``choice`` items)."""
        if self.uniform is not None:
            return [float(x) for x in rng.uniform(*self.uniform, n)]
        if self.loguniform is not None:
            low, high = (math.log(b) for b in self.loguniform)
            return [float(math.exp(x)) for x in rng.uniform(low, high, n)]
        return [self.choice[int(i)] for i in rng.integers(len(self.choice), size=n)]


class RandomBlock(_Strict):
    """``samples`` seeded random draws of ``parameters`` (each drawn independently, in the
    order given, from ``numpy.random.default_rng(seed)``)."""

    seed: int
    samples: Annotated[int, Field(ge=1)]
    parameters: Annotated[dict[str, Distribution], Field(min_length=1)]


#: name -> values (``product``, ``zip``)
ValueLists = Annotated[dict[str, Annotated[list[Any], Field(min_length=1)]], Field(min_length=1)]
#: explicit parameter sets (``list``)
ParameterSets = Annotated[list[Annotated[dict[str, Any], Field(min_length=1)]], Field(min_length=1)]


class Block(_Strict):
    """One way of varying parameters: exactly one of ``product`` (every combination of the
    value lists), ``zip`` (lists of one length taken together), ``list`` (explicit parameter
    sets) or ``random``."""

    product: ValueLists | None = None
    zip: ValueLists | None = None
    list: ParameterSets | None = None
    random: RandomBlock | None = None

    @model_validator(mode="after")
    def _one(self):
        given = [k for k in ("product", "zip", "list", "random") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of product, zip, list, random (got {given or 'none'})")
        if self.zip is not None and len({len(v) for v in self.zip.values()}) > 1:
            lengths = {k: len(v) for k, v in self.zip.items()}
            raise ValueError(f"zip: the value lists must have one length, got {lengths}")
        if self.list is not None and len({tuple(item) for item in self.list}) > 1:
            raise ValueError("list: every item must set the same parameters")
        return self

    def names(self) -> list[str]:
        """The parameters this block varies."""
        if self.random is not None:
            return [*self.random.parameters]
        if self.list is not None:
            return [*self.list[0]]
        return [*(self.product or self.zip)]

    def points(self) -> list[dict]:
        """The parameter sets of the block, in order."""
        if self.product is not None:
            keys = [*self.product]
            return [
                dict(zip(keys, values, strict=True)) for values in itertools.product(*self.product.values())
            ]
        if self.zip is not None:
            return [
                dict(zip(self.zip, values, strict=True)) for values in zip(*self.zip.values(), strict=True)
            ]
        if self.list is not None:
            return [dict(item) for item in self.list]
        rng = np.random.default_rng(self.random.seed)
        drawn = {name: dist.draw(rng, self.random.samples) for name, dist in self.random.parameters.items()}
        return [{name: values[i] for name, values in drawn.items()} for i in range(self.random.samples)]


class Outputs(_Strict):
    """What the dataset collects: ``scalars`` (flattened summary names, default: all),
    ``series`` (names of results.h5 series, e.g. ``sensor_u``, ``pzt_signal``) and ``bloch``
    (frequencies, Hz, at which each run's discretisation gets its Bloch wavenumbers of S0, A0
    and SH0 against Rayleigh-Lamb, ``peridyn.analysis.bloch_study.predict``); ``figures``:
    draw the scalars against the first varied parameter (``OUT/figures/``)."""

    scalars: list[str] | None = None
    series: list[str] = []
    bloch: list[Annotated[float, Field(gt=0)]] = []
    figures: bool = True

    @model_validator(mode="after")
    def _bloch(self):
        if len(set(self.bloch)) != len(self.bloch):
            raise ValueError(f"bloch: frequencies given twice in {self.bloch}")
        return self


class SweepSpec(_Strict):
    """A sweep file (see the module docstring)."""

    name: str | None = None
    description: str = ""
    base: str
    command: Literal["run", "modal", "fatigue", "bloch"] = "run"
    reference: str | None = None
    set: dict[str, Any] = {}
    vary: Annotated[list[Block], Field(min_length=1)]
    labels: list[str] = []
    derived: dict[str, str | float] = {}
    derived_by: dict[str, dict[str, dict[str, str | float]]] = {}
    outputs: Outputs = Outputs()

    @model_validator(mode="before")
    @classmethod
    def _one_block(cls, data):
        if isinstance(data, dict) and isinstance(data.get("vary"), dict):
            data = {**data, "vary": [data["vary"]]}
        return data

    @model_validator(mode="after")
    def _names(self):
        seen: dict[str, int] = {}
        for i, block in enumerate(self.vary):
            for name in block.names():
                if name in seen:
                    raise ValueError(f"parameter {name!r} is varied twice (blocks {seen[name]} and {i})")
                seen[name] = i
        for name in self.derived:
            if name in seen:
                raise ValueError(f"derived {name!r} is also varied (block {seen[name]})")
        for label, tables in self.derived_by.items():
            if label not in self.labels:
                raise ValueError(f"derived_by.{label}: {label!r} is not one of labels {self.labels}")
            keys = set().union(*tables.values())
            clash = sorted(keys & (set(self.derived) | set(seen)))
            if clash:
                raise ValueError(f"derived_by.{label}: {clash} are also varied or derived")
        if self.command == "bloch" and not self.outputs.bloch:
            raise ValueError("command bloch needs the frequencies of outputs.bloch")
        if self.reference is not None and self.command not in ("modal", "run"):
            raise ValueError(
                f"reference (a healthy body to compare with) needs command: modal or run, not {self.command}"
            )
        unused = sorted(set(self.labels) - set(seen))
        if unused:
            raise ValueError(f"labels {unused} are not varied by any block")
        return self

    def parameter_names(self) -> list[str]:
        """Varied then derived names, in order: the dataset's coordinates."""
        by_label = [n for tables in self.derived_by.values() for table in tables.values() for n in table]
        return [*(n for block in self.vary for n in block.names()), *self.derived, *dict.fromkeys(by_label)]

    def derived_for(self, parameters: dict) -> dict:
        """The derived entries of a run: ``derived``, then those of ``derived_by`` for the run's
        label values (a label value without a table derives nothing more)."""
        out = dict(self.derived)
        for label, tables in self.derived_by.items():
            out.update(tables.get(str(parameters[label]), {}))
        return out


@dataclass(frozen=True)
class SweepRun:
    """One run of a sweep.

    Attributes
    ----------
    index : int
        Its place in the sweep (0-based).
    parameters : dict
        Varied and derived values, by name.
    case : Case
        The validated case.
    run_id : str
        The first :data:`ID_LENGTH` hex digits of the case hash: the run's folder name.
    case_hash : str
        The whole SHA-256 of the case (with its run length).
    """

    index: int
    parameters: dict
    case: Case
    run_id: str
    case_hash: str


@dataclass(frozen=True)
class Sweep:
    """A sweep file expanded: its spec, its folder (``base_dir`` of the base case) and runs."""

    spec: SweepSpec
    path: Path
    base: Path
    runs: list[SweepRun]
    reference: SweepRun | None = None

    @property
    def name(self) -> str:
        """The sweep's name (the file's stem unless it gives one)."""
        return self.spec.name or self.path.stem


def read_spec(path) -> SweepSpec:
    """Read and validate a sweep file.

    Raises
    ------
    CaseFileError
        Missing or unreadable file, bad YAML, or an entry that is wrong (named with its path).
    """
    path = Path(path)
    raw = read_yaml_mapping(path, "YAML sweep file", "a mapping with base and vary")
    try:
        return SweepSpec.model_validate(raw)
    except ValidationError as exc:
        raise first_problem(exc, str(path)) from None


def expand(path, overrides=(), first: int | None = None) -> Sweep:
    """Read a sweep file and build every run's case (validated, not built).

    Parameters
    ----------
    path : path
    overrides : sequence of "key.path=value"
        ``--set`` items for every run, after the file's ``set`` (e.g. a smaller grid for a trial).
    first : int or None
        Keep only the first ``first`` runs (a trial of the sweep).

    Raises
    ------
    CaseFileError
        A bad sweep file, or a run whose case is not valid (the message names its parameters).
    InputError
        A derived expression that fails, or two runs with the same case.
    """
    path = Path(path)
    spec = read_spec(path)
    base = (path.parent / spec.base).resolve()
    points = [
        {k: v for part in combo for k, v in part.items()}
        for combo in itertools.product(*(block.points() for block in spec.vary))
    ][:first]
    base_case = _BaseCase(base)
    runs = []
    by_id: dict[str, int] = {}
    for index, values in enumerate(points):
        parameters, case = _run_case(spec, base_case, values, list(overrides))
        text, digest = case_identity(case, run_length=True)
        run_id = digest[:ID_LENGTH]
        if run_id in by_id:
            raise InputError(
                f"{path}: runs {by_id[run_id]} and {index} are the same case ({_describe(parameters)}): "
                "vary case entries, not only labels"
            )
        by_id[run_id] = index
        runs.append(SweepRun(index, parameters, case, run_id, digest))
    reference = None
    if spec.reference is not None:
        reference_case = _BaseCase((path.parent / spec.reference).resolve())
        _, case = _run_case(spec, reference_case, {}, list(overrides), derived=False)
        digest = case_identity(case, run_length=True)[1]
        reference = SweepRun(-1, {}, case, digest[:ID_LENGTH], digest)
    return Sweep(spec, path, base, runs, reference)


class _BaseCase:
    """A case file read once (and checked as ``load_case`` checks it), validated with each
    run's overrides as ``load_case(path, overrides)`` would."""

    def __init__(self, path: Path):
        load_case(path)  # a missing, unreadable or invalid base case is reported as for any case
        self.path = path
        self.raw = parse_yaml(read_input_text(path, "YAML case file"))

    def case(self, overrides: list) -> Case:
        raw = copy.deepcopy(self.raw)
        for item in overrides:
            apply_override(raw, item, str(self.path))
        return validate_case(raw, str(self.path))


def _run_case(
    spec: SweepSpec, base: _BaseCase, values: dict, extra: list, derived: bool = True
) -> tuple[dict, Case]:
    """One run's parameters (varied, then ``derived`` ones) and validated case."""
    overrides = [_override(k, v) for k, v in spec.set.items()] + extra
    if spec.command == "modal":
        overrides.append("solver.type=modal")
    overrides += [_override(k, v) for k, v in values.items() if k not in spec.labels]
    parameters = dict(values)
    try:
        case = base.case(overrides)
        expressions = spec.derived_for(parameters) if derived else {}
        if expressions:
            dumped = case.model_dump(mode="json")
            for key, expression in expressions.items():
                parameters[key] = evaluate(str(expression), lambda p: _lookup(p, parameters, dumped))
                apply_override(dumped, _override(key, parameters[key]), str(base.path))  # for later ones
            case = base.case(overrides + [_override(k, parameters[k]) for k in expressions])
    except (CaseFileError, InputError) as exc:
        exc.args = (f"run with {_describe(parameters)}: {exc}",)
        raise
    return parameters, case


def _override(key: str, value) -> str:
    """A ``--set`` item giving ``key`` the value ``value`` exactly (JSON is YAML: a float's
    shortest repr reads back bit for bit)."""
    return f"{key}={json.dumps(value)}"


def _lookup(path: str, parameters: dict, case: dict):
    """A name of an expression: a parameter, else a case entry (``a.b.0``); KeyError if neither."""
    if path in parameters:
        return parameters[path]
    node = case
    for part in path.split("."):
        if isinstance(node, list) and part.isdigit() and int(part) < len(node):
            node = node[int(part)]
        elif isinstance(node, dict) and part in node:
            node = node[part]
        else:
            raise KeyError(path)
    return node


def _describe(parameters: dict) -> str:
    return ", ".join(f"{k}={v!r}" for k, v in parameters.items())
