"""Fuzzing the files a user gives peridyn: Peridigm decks (XML and YAML), meshes (text and
Exodus), sweep files and expressions, mutated at random (tests/fuzz/file_mutations.py) and read
in-process by the functions the commands use. Every example holds to the contract of
tests/fuzz/fuzz_contract.py: it is read, or refused with one line naming the file, never a
traceback or a hang, and the files read keep every byte.

Examples are seeded (``random.Random(seed)``, seeds 0, 1, 2, ...): a failure names its seed and
what was done. The default run draws a few hundred examples in all, the slow run (``-m slow``)
thousands; ``pytest -s`` prints each campaign's counts.
"""

from __future__ import annotations

import copy
import random
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml
from file_mutations import (
    expression,
    expression_names,
    mutate_bytes,
    mutate_mapping,
    mutate_text_mesh,
    mutate_xml_deck,
    text_mesh,
)
from fuzz_contract import check_unchanged, fingerprint, outcome, report
from fuzz_mutations import ROOT

from peridyn.io.case import parse_yaml
from peridyn.io.exodus import body_from_exodus
from peridyn.io.mesh_text import from_text_mesh
from peridyn.io.peridigm_case import load_deck
from peridyn.jobs.sweep_spec import expand
from peridyn.physics.expressions import SpaceTime, evaluate

CORPUS = ROOT / "tests" / "data" / "peridigm_corpus"
#: Every deck of the Peridigm corpus.
DECKS = sorted(CORPUS.glob("*/*.xml")) + sorted(CORPUS.glob("*/*.yaml"))
#: Every Exodus mesh of the corpus (the meshes its decks name, and Peridigm's results).
EXODUS = sorted(CORPUS.glob("*/*.g")) + sorted(CORPUS.glob("*/*_gold.e"))[:4]
#: The sweep files fuzzed (their base cases are small bars and plates).
SWEEPS = [ROOT / "sweeps" / "demo.yaml", ROOT / "sweeps" / "lamb_layers.yaml"]


def _quiet(call):
    """``call`` with warnings silenced (a mutated file may be read with a warning: allowed)."""

    def quiet():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return call()

    return quiet


@pytest.fixture(scope="module")
def corpus(tmp_path_factory) -> Path:
    """A copy of the corpus (the decks and the meshes they name) that examples write into."""
    folder = tmp_path_factory.mktemp("corpus")
    shutil.copytree(CORPUS, folder, dirs_exist_ok=True)
    return folder


def fuzz_decks(n: int, corpus: Path) -> None:
    """``n`` mutated decks, each written beside its meshes and translated as ``run`` does."""
    for seed in range(n):
        rng = random.Random(seed)
        deck = rng.choice(DECKS)
        folder = corpus / deck.parent.name
        if deck.suffix == ".xml":
            data, what = mutate_xml_deck(deck.read_text(), rng)
        elif rng.random() < 0.3:
            data, what = mutate_bytes(deck.read_bytes(), rng)
        else:
            raw = parse_yaml(deck.read_text())
            what = mutate_mapping(raw, rng)
            data = yaml.safe_dump(raw, sort_keys=False, allow_unicode=True).encode()
        path = folder / f"fuzzed{deck.suffix}"
        path.write_bytes(data)
        before = fingerprint(folder)
        outcome(
            "Peridigm decks", _quiet(lambda path=path: load_deck(path)), f"seed {seed} {deck.name}: {what}"
        )
        check_unchanged("Peridigm decks", before, folder, f"seed {seed}")
    print("\n" + report("Peridigm decks"))


def test_mutated_peridigm_decks_are_read_or_refused_in_one_line(corpus):
    fuzz_decks(200, corpus)


@pytest.mark.slow
def test_mutated_peridigm_decks_are_read_or_refused_in_one_line_many(corpus):
    fuzz_decks(1500, corpus)


def fuzz_text_meshes(n: int, folder: Path) -> None:
    """``n`` mutated text meshes, read as a case's ``geometry.file`` is (3D, and 2D as a plate)."""
    path = folder / "mesh.txt"
    for seed in range(n):
        rng = random.Random(seed)
        dim = rng.choice([2, 3])
        text = text_mesh(rng, dim)
        data, what = mutate_text_mesh(text, rng)
        path.write_bytes(data)
        before = fingerprint(folder)
        thickness = 1.0e-3 if dim == 2 else None
        plane = "stress" if dim == 2 else None
        state, body = outcome(
            "text meshes",
            _quiet(lambda d=dim, t=thickness, p=plane: from_text_mesh(path, d, t, p)),
            f"seed {seed} ({dim}D): {what}",
            names=str(path),
        )
        if state == "ok":  # what was read is a body of finite points and positive volumes
            assert np.isfinite(body.points).all() and (body.volumes > 0).all(), f"seed {seed}: {what}"
        check_unchanged("text meshes", before, folder, f"seed {seed}")
    print("\n" + report("text meshes"))


def test_mutated_text_meshes_are_read_or_refused_in_one_line(tmp_path):
    fuzz_text_meshes(100, tmp_path)


@pytest.mark.slow
def test_mutated_text_meshes_are_read_or_refused_in_one_line_many(tmp_path):
    fuzz_text_meshes(800, tmp_path)


def fuzz_exodus(n: int, folder: Path) -> None:
    """``n`` Exodus meshes with flipped, zeroed, removed or repeated bytes or cut short, read into
    a body as a deck's ``Input Mesh File`` is."""
    originals = {path: path.read_bytes() for path in EXODUS}
    path = folder / "mesh.g"
    for seed in range(n):
        rng = random.Random(seed)
        source = rng.choice(EXODUS)
        data, what = mutate_bytes(originals[source], rng)
        path.write_bytes(data)
        before = fingerprint(folder)
        state, body = outcome(
            "Exodus meshes",
            _quiet(lambda: body_from_exodus(path)),
            f"seed {seed} {source.parent.name}/{source.name}: {what}",
            names=str(path),
        )
        if state == "ok":
            assert np.isfinite(body.points).all() and (body.volumes > 0).all(), f"seed {seed}: {what}"
        check_unchanged("Exodus meshes", before, folder, f"seed {seed}")
    print("\n" + report("Exodus meshes"))


def test_mutated_exodus_meshes_are_read_or_refused_in_one_line(tmp_path):
    fuzz_exodus(60, tmp_path)


@pytest.mark.slow
def test_mutated_exodus_meshes_are_read_or_refused_in_one_line_many(tmp_path):
    fuzz_exodus(600, tmp_path)


def fuzz_sweeps(n: int, folder: Path) -> None:
    """``n`` mutated sweep files (their base case named by its absolute path), expanded into
    their runs' cases as ``peridyn sweep`` does before it runs them."""
    raws = {}
    for sweep in SWEEPS:
        raw = parse_yaml(sweep.read_text())
        raw["base"] = str((sweep.parent / raw["base"]).resolve())
        raws[sweep.name] = raw
    path = folder / "sweep.yaml"
    for seed in range(n):
        rng = random.Random(seed)
        name = rng.choice(sorted(raws))
        if rng.random() < 0.2:
            data, what = mutate_bytes(yaml.safe_dump(raws[name]).encode(), rng)
        else:
            raw = copy.deepcopy(raws[name])
            what = mutate_mapping(raw, rng)
            data = yaml.safe_dump(raw, sort_keys=False, allow_unicode=True).encode()
        path.write_bytes(data)
        before = fingerprint(folder)
        outcome("sweep files", _quiet(lambda: expand(path)), f"seed {seed} {name}: {what}")
        check_unchanged("sweep files", before, folder, f"seed {seed}")
    print("\n" + report("sweep files"))


def test_mutated_sweep_files_are_expanded_or_refused_in_one_line(tmp_path):
    fuzz_sweeps(40, tmp_path)


@pytest.mark.slow
def test_mutated_sweep_files_are_expanded_or_refused_in_one_line_many(tmp_path):
    fuzz_sweeps(400, tmp_path)


def fuzz_expressions(n: int) -> None:
    """``n`` random expressions, evaluated as a sweep's ``derived:`` value is and as a boundary
    condition's value in x, y, z and t is (``SpaceTime``)."""
    points = np.linspace(0.0, 1.0, 30).reshape(10, 3)
    for seed in range(n):
        rng = random.Random(seed)
        text = expression(rng)
        names = expression_names(rng)

        def lookup(name, names=names):
            return names[name]

        state, value = outcome(
            "expressions",
            _quiet(lambda text=text, lookup=lookup: evaluate(text, lookup)),
            f"seed {seed}: {text!r}",
        )
        if state == "ok":
            assert np.asarray(value).dtype.kind in "biuf", f"seed {seed}: {text!r} gave {value!r}"
        state, value = outcome(
            "expressions",
            _quiet(lambda text=text: SpaceTime(text).at(points, 1.0e-6)),
            f"seed {seed}: {text!r} in x, t",
        )
        if state == "ok":  # a boundary value is finite on every point
            assert value.shape == (10,) and np.isfinite(value).all(), f"seed {seed}: {text!r}"
    print("\n" + report("expressions"))


def test_random_expressions_are_evaluated_or_refused_in_one_line():
    fuzz_expressions(150)


@pytest.mark.slow
def test_random_expressions_are_evaluated_or_refused_in_one_line_many():
    fuzz_expressions(1000)
