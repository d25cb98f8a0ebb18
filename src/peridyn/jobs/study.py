"""A convergence study: modal runs of one case over a spacing x horizon grid, Richardson fits.

Each run is the case with ``discretization.spacing`` and ``discretization.horizon`` (a
multiple of the spacing) overridden, solved by :func:`peridyn.jobs.modal.modal_table`.
Modes are matched across runs by type and order ("1st bending", ...; rigid and
unclassified modes are left out) and each series of runs is extrapolated with
:func:`peridyn.analysis.convergence.richardson`. The series (seed 002, section 6.1,
after Bobaru et al. 2009):

- ``delta-m``: horizon factor m = delta/h fixed, spacing h -> 0 (so delta -> 0 too); the
  fit variable is h;
- ``delta``: spacing fixed, horizon delta -> 0; the fit variable is delta (m);
- ``m``: horizon delta (m) fixed, spacing -> 0 (m grows); the fit variable is h. Runs are
  grouped by equal delta, so the grid must hold such runs (e.g. 2 mm x 3 and 3 mm x 2).
"""

from __future__ import annotations

import csv
import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from peridyn import interrupts
from peridyn.analysis.convergence import ConvergenceError, richardson
from peridyn.errors import InputError
from peridyn.jobs.summary import finish_summary

#: The kinds of series a study can fit, see the module docstring.
SERIES = ("delta-m", "delta", "m")
#: Mode types not matched across runs (no single mode to follow).
UNMATCHED_TYPES = ("rigid", "other")
#: Horizons (m) equal to this relative tolerance form one ``m`` series.
SAME_HORIZON = 1e-6


@dataclass
class StudyRun:
    """One modal run of the grid.

    ``modes`` maps a mode label ("1st bending") to its frequency in Hz (the lowest if the
    label occurs twice); ``bonds`` counts directed bonds; ``seconds`` is the run's time (build
    and solve); ``skipped`` holds the reason when the run was not solved.
    """

    spacing: float
    horizon_factor: float
    points: int = 0
    bonds: int = 0
    seconds: float = 0.0
    modes: dict[str, float] = field(default_factory=dict)
    skipped: str | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def horizon(self) -> float:
        """Horizon delta in metres."""
        return self.horizon_factor * self.spacing

    def to_dict(self) -> dict:
        return {
            "spacing_m": self.spacing,
            "horizon_factor": self.horizon_factor,
            "horizon_m": self.horizon,
            "points": self.points,
            "bonds": self.bonds,
            "seconds": self.seconds,
            "modes": self.modes,
            "skipped": self.skipped,
            "notes": self.notes,
        }


@interrupts.deferred()
def run_grid(
    case_path, spacings, horizon_factors, n_modes: int | None = None, overrides=(), progress=None
) -> list[StudyRun]:
    """Solve the modal problem of every (spacing, horizon factor) combination.

    Parameters
    ----------
    case_path : str or Path
        A case file (any solver type; it is run as ``modal``).
    spacings : sequence of float, m
    horizon_factors : sequence of float
        Horizons as multiples of the spacing.
    n_modes : int or None
        Modes per run (rigid included); None keeps the case's ``solver.modes``.
    overrides : sequence of "key=value"
        Applied to every run before the spacing and horizon.
    progress : callable(str) or None
        Receives one line per run.

    Runs whose factorisation would not fit in memory
    (:func:`peridyn.jobs.modal.check_assembly_fits`) are skipped with the reason.
    """
    from peridyn.io.case import load_case
    from peridyn.jobs.build import build
    from peridyn.jobs.modal import check_assembly_fits, modal_table

    combos = [(h, m) for m in horizon_factors for h in spacings]
    runs = []
    for k, (h, m) in enumerate(combos, 1):
        interrupts.check(where=f"running the study (run {k} of {len(combos)})")
        run = StudyRun(float(h), float(m))
        start = time.perf_counter()
        case = load_case(
            case_path,
            [
                *overrides,
                "solver.type=modal",
                *([f"solver.modes={n_modes}"] if n_modes is not None else []),
                f"discretization.spacing={h!r}",
                f"discretization.horizon={m!r}",
                "discretization.horizon_m=null",
            ],
        )
        setup = build(case, Path(case_path).parent)
        run.points = setup.body.n_points
        run.bonds = setup.bonds.n_bonds
        run.notes += _geometry_notes(case, setup.body)
        try:
            check_assembly_fits(setup.model)
        except InputError as exc:
            run.skipped = str(exc)
        if run.skipped is None:
            fixed = setup.loading.constrained if setup.loading.has_loads else None
            _, _, rows = modal_table(setup.model, case.solver.modes, fixed=fixed)
            for row in rows:
                label = row["label"]
                if row["type"] in UNMATCHED_TYPES:
                    continue
                if label in run.modes:
                    run.notes.append(f"two modes classified {label}: kept the lower one")
                    continue
                run.modes[label] = row["frequency_hz"]
        run.seconds = time.perf_counter() - start
        runs.append(run)
        if progress is not None:
            state = f"skipped: {run.skipped}" if run.skipped else f"{len(run.modes)} modes matched"
            progress(
                f"[{k}/{len(combos)}] spacing {h * 1e3:g} mm, horizon {m:g} h: {run.points} "
                f"points, {run.seconds:.1f} s, {state}"
            )
            for note in run.notes:
                progress(f"      note: {note}")
    return runs


def _geometry_notes(case, body) -> list[str]:
    """Warn when a box's sides are not whole multiples of the spacing (the grid rounds them)."""
    if case.geometry.type != "box":
        return []
    grid = np.ptp(body.points, axis=0) + body.cells[0]
    size = np.asarray(case.geometry.size, dtype=float)
    if np.allclose(grid, size, rtol=1e-6, atol=0.0):
        return []
    dims = " x ".join(f"{v * 1e3:.4g}" for v in grid)
    return [
        f"the grid spans {dims} mm, not the case's "
        f"{' x '.join(f'{v * 1e3:.4g}' for v in size)} mm: the spacing does not divide the box, "
        "so this run models another body"
    ]


def fit_series(
    runs: list[StudyRun], series=("delta-m",), references=None, finest: int | None = None
) -> list[dict]:
    """Richardson fits of every mode over every series of runs.

    Returns one dict per (series, group, mode): ``series``, ``group`` (what is held fixed),
    ``variable`` (``spacing_m`` or ``horizon_m``), ``x`` and ``frequencies_hz`` (finest
    first), and either ``value_hz``, ``order``, ``gci``, ``rms_residual_hz`` or, when no
    value exists, ``error``: why (fewer than three runs with the mode; an oscillating,
    stagnating or diverging sequence, with its numbers).
    With ``references`` (label -> Hz), ``reference_hz`` and the relative errors of the
    extrapolated and of the finest value are added. With ``finest``, only that many of the
    finest runs of each series enter the fit (the asymptotic range, seed 002 section 6.1);
    ``fitted_runs`` says how many did.
    """
    if finest is not None and finest < 3:
        raise InputError(f"finest = {finest}: a Richardson fit needs at least three runs")
    unknown = [s for s in series if s not in SERIES]
    if unknown:
        raise InputError(f"unknown convergence series {unknown}: expected some of {', '.join(SERIES)}")
    solved = [r for r in runs if r.skipped is None]
    labels = _labels_in_order(solved)
    fits = []
    for kind in series:
        for group, members, variable in _groups(solved, kind):
            for label in labels:
                having = [r for r in members if label in r.modes]
                if not having:
                    continue
                x = np.array([r.spacing if variable == "spacing_m" else r.horizon for r in having])
                f = np.array([r.modes[label] for r in having])
                order = np.argsort(x)
                row = {
                    "series": kind,
                    "group": group,
                    "mode": label,
                    "variable": variable,
                    "x": x[order].tolist(),
                    "frequencies_hz": f[order].tolist(),
                }
                try:
                    fit = richardson(x[order][:finest], f[order][:finest])
                except ConvergenceError as exc:
                    row["error"] = str(exc)
                except InputError as exc:
                    row["error"] = f"{len(having)} run(s) with this mode: {exc}"
                else:
                    row.update(
                        fitted_runs=len(fit.spacings),
                        value_hz=fit.value,
                        order=fit.order,
                        gci=fit.gci,
                        coefficient=fit.coefficient,
                        rms_residual_hz=fit.rms_residual,
                    )
                if references and label in references:
                    ref = references[label]
                    row["reference_hz"] = ref
                    row["finest_error"] = row["frequencies_hz"][0] / ref - 1
                    row["value_error"] = row["value_hz"] / ref - 1 if "value_hz" in row else None
                fits.append(row)
    return fits


def _labels_in_order(runs: list[StudyRun]) -> list[str]:
    """Mode labels of all runs, ordered by their frequency in the finest run having them."""
    best: dict[str, tuple[float, float]] = {}
    for r in runs:
        for label, freq in r.modes.items():
            if label not in best or r.spacing < best[label][0]:
                best[label] = (r.spacing, freq)
    return sorted(best, key=lambda label: best[label][1])


def _groups(runs: list[StudyRun], kind: str):
    """(group label, runs, fit variable) of one kind of series."""
    if kind == "delta-m":
        for m in sorted({r.horizon_factor for r in runs}):
            yield f"horizon {m:g} h", [r for r in runs if r.horizon_factor == m], "spacing_m"
    elif kind == "delta":
        for h in sorted({r.spacing for r in runs}):
            yield f"spacing {h * 1e3:g} mm", [r for r in runs if r.spacing == h], "horizon_m"
    else:
        horizons: list[float] = []
        for r in sorted(runs, key=lambda r: r.horizon):
            if not horizons or r.horizon > horizons[-1] * (1 + SAME_HORIZON):
                horizons.append(r.horizon)
        for d in horizons:
            members = [r for r in runs if abs(r.horizon - d) <= SAME_HORIZON * d]
            yield f"horizon {d * 1e3:.4g} mm", members, "spacing_m"


def write_study(
    out: Path, runs: list[StudyRun], fits: list[dict], meta: dict, start: float, plots=()
) -> dict:
    """Write ``runs.csv`` (one row per run and mode), ``study.csv`` (one row per fit) and
    ``study.json`` (everything); returns the JSON summary (docs/user-guide.md, "Summaries and
    results files"). ``start``: ``time.perf_counter()`` when the study started; ``plots``: the
    figures drawn."""
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "runs.csv", "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(
            [
                "spacing_m",
                "horizon_factor",
                "horizon_m",
                "points",
                "seconds",
                "mode",
                "frequency_hz",
                "skipped",
            ]
        )
        for r in runs:
            for label, freq in r.modes.items() if r.modes else [("", "")]:
                writer.writerow(
                    [
                        r.spacing,
                        r.horizon_factor,
                        r.horizon,
                        r.points,
                        round(r.seconds, 3),
                        label,
                        freq,
                        r.skipped or "",
                    ]
                )
    columns = [
        "series",
        "group",
        "mode",
        "variable",
        "x",
        "frequencies_hz",
        "fitted_runs",
        "value_hz",
        "order",
        "gci",
        "coefficient",
        "rms_residual_hz",
        "reference_hz",
        "finest_error",
        "value_error",
        "error",
    ]
    with open(out / "study.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns)
        writer.writeheader()
        for row in fits:
            writer.writerow(
                {
                    k: (
                        " ".join(f"{v:.10g}" for v in row[k])
                        if isinstance(row.get(k), list)
                        else row.get(k, "")
                    )
                    for k in columns
                }
            )
    summary = {
        **meta,
        "runs": [r.to_dict() for r in runs],
        "fits": fits,
        "skipped_runs": sum(r.skipped is not None for r in runs),
    }
    finish_summary(summary, "study", out, start, plots)
    (out / "study.json").write_text(json.dumps(summary, indent=1))
    return summary
