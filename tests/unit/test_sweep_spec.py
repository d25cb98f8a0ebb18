"""Sweep files expanded into runs (peridyn.jobs.sweep_spec, issue 21 item 1): the blocks give the
parameter sets their definition says (docs/sweeps.md), derived values follow their expressions,
every run's case carries its values, and bad sweep files are refused naming the entry."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from peridyn.errors import CaseFileError, InputError
from peridyn.jobs.sweep_spec import expand
from peridyn.physics.expressions import evaluate
from peridyn.setup.checks import check_without_bonds

ROOT = Path(__file__).resolve().parents[2]
BAR = str(ROOT / "cases" / "bar_pulse.yaml")


def sweep_file(tmp_path, **spec) -> Path:
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump({"base": BAR, **spec}))
    return path


def test_product_is_every_combination_in_order(tmp_path):
    E, rho = [150e9, 200e9], [7850, 2700, 4500]
    sweep = expand(sweep_file(tmp_path, vary={"product": {"material.E": E, "material.density": rho}}))
    expected = list(itertools.product(E, rho))
    assert [(r.parameters["material.E"], r.parameters["material.density"]) for r in sweep.runs] == expected
    assert [(r.case.material.E, r.case.material.density) for r in sweep.runs] == expected
    assert len({r.run_id for r in sweep.runs}) == len(expected)


def test_zip_and_list_blocks_combine_as_a_product(tmp_path):
    spec = {
        "vary": [
            {"zip": {"material.E": [150e9, 200e9], "material.density": [7000, 8000]}},
            {"list": [{"material.nu": 0.25}, {"material.nu": 0.3}]},
        ]
    }
    runs = expand(sweep_file(tmp_path, **spec)).runs
    got = [(r.case.material.E, r.case.material.density, r.case.material.nu) for r in runs]
    assert got == [(150e9, 7000, 0.25), (150e9, 7000, 0.3), (200e9, 8000, 0.25), (200e9, 8000, 0.3)]


@pytest.mark.bitwise
def test_random_block_is_seeded_and_within_its_distributions(tmp_path):
    """A random block draws the same runs from the same seed, within its distributions. The uniform
    draws are ``default_rng(seed).uniform`` called as here, the same bits; the log-uniform ones go
    through ``np.exp`` and are compared to rounding."""
    spec = {
        "random": {
            "seed": 7,
            "samples": 20,
            "parameters": {
                "material.E": {"uniform": [100e9, 200e9]},
                "material.density": {"loguniform": [1000, 10000]},
                "material.nu": {"choice": [0.2, 0.3]},
            },
        }
    }
    first = expand(sweep_file(tmp_path, vary=spec)).runs
    again = expand(sweep_file(tmp_path, vary=spec)).runs
    assert [r.parameters for r in first] == [r.parameters for r in again]  # same seed, same draws
    E = np.array([r.parameters["material.E"] for r in first])
    rho = np.array([r.parameters["material.density"] for r in first])
    assert np.all((E >= 100e9) & (E < 200e9)) and np.all((rho >= 1000) & (rho < 10000))
    assert {r.parameters["material.nu"] for r in first} <= {0.2, 0.3}
    # the draws are numpy's default_rng(seed), each parameter in turn (sweep_spec.RandomBlock)
    rng = np.random.default_rng(7)
    np.testing.assert_array_equal(E, rng.uniform(100e9, 200e9, 20))
    np.testing.assert_allclose(rho, np.exp(rng.uniform(math.log(1000), math.log(10000), 20)), rtol=1e-15)
    other = expand(sweep_file(tmp_path, vary={**spec, "random": {**spec["random"], "seed": 8}})).runs
    assert [r.parameters for r in other] != [r.parameters for r in first]


def test_derived_values_follow_their_expressions_in_order(tmp_path):
    spec = {
        "vary": {"product": {"discretization.spacing": [2.5e-3, 2.0e-3], "cells": [2, 3]}},
        "labels": ["cells"],
        "derived": {
            "output.sensors.x50.0": "cells * discretization.spacing + 0.05",
            "solver.time": "2 * output.sensors.x50[0] / sqrt(material.E / material.density)",
        },
    }
    for run in expand(sweep_file(tmp_path, **spec)).runs:
        h, cells = run.parameters["discretization.spacing"], run.parameters["cells"]
        x = cells * h + 0.05
        assert run.parameters["output.sensors.x50.0"] == x
        assert run.case.output.sensors["x50"][0] == x
        assert run.case.solver.time == 2 * x / math.sqrt(200e9 / 7850)  # E and rho of bar_pulse.yaml


def test_every_run_of_the_shipped_sweeps_validates():
    """The shipped sweep files expand, every run's case valid; the first and middle runs of each
    (lamb_damage: the first hole and the first notch; pmma_cracks: the first edge and the first
    back-face crack) also pass ``peridyn validate``'s checks that build the points (memory,
    placements, loads, time step). The largest runs of lamb_layers need a cluster's memory."""
    for path in sorted((ROOT / "sweeps").glob("*.yaml")):
        sweep = expand(path)
        assert sweep.runs, path
        assert len({r.run_id for r in sweep.runs}) == len(sweep.runs), path
        for run in (sweep.runs[0], sweep.runs[len(sweep.runs) // 2]):
            check_without_bonds(run.case, sweep.base.parent)


@pytest.mark.parametrize(
    "text",
    ["__import__('os').system('true')", "open('x')", "material.E if 1 else 2", "[1, 2]", "'a' * 3", "x.y()"],
)
def test_expression_refuses_anything_but_arithmetic(text):
    with pytest.raises(InputError, match="not allowed"):
        evaluate(text, {"x": 1, "material.E": 1.0}.__getitem__)


def test_expression_names_unknown_names_and_arithmetic_errors():
    with pytest.raises(InputError, match="unknown name 'materal.E'"):
        evaluate("2 * materal.E", {}.__getitem__)
    with pytest.raises(InputError, match="ZeroDivisionError"):
        evaluate("1 / (a - a)", {"a": 1.0}.__getitem__)
    with pytest.raises(InputError, match="not valid"):
        evaluate("1 +", {}.__getitem__)


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ({"vary": {"zip": {"material.E": [1e9, 2e9], "material.density": [1000]}}}, "one length"),
        ({"vary": {"product": {"material.E": [1e9]}, "zip": {"material.nu": [0.2]}}}, "exactly one"),
        (
            {"vary": [{"product": {"material.E": [1e9]}}, {"list": [{"material.E": 2e9}]}]},
            "'material.E' is varied twice",
        ),
        ({"vary": {"product": {"material.E": [1e9]}}, "labels": ["kind"]}, "not varied"),
        ({"vary": {"product": {"material.E": [1e9]}}, "command": "bend"}, "command"),
        ({"vary": {"random": {"seed": 0, "samples": 2, "parameters": {"a": {"loguniform": [0, 1]}}}}}, "> 0"),
    ],
)
def test_bad_sweep_files_are_refused_naming_the_entry(tmp_path, spec, match):
    with pytest.raises(CaseFileError, match=match):
        expand(sweep_file(tmp_path, **spec))


def test_a_run_with_an_invalid_case_is_refused_naming_its_parameters(tmp_path):
    path = sweep_file(tmp_path, vary={"product": {"material.E": [1e9, -1e9]}})
    with pytest.raises(CaseFileError, match=r"run with material.E=-1000000000.0: .*material.E"):
        expand(path)


def test_runs_that_are_the_same_case_are_refused(tmp_path):
    path = sweep_file(tmp_path, vary={"product": {"kind": ["a", "b"]}}, labels=["kind"])
    with pytest.raises(InputError, match="runs 0 and 1 are the same case"):
        expand(path)


def test_a_missing_sweep_file_is_named(tmp_path):
    with pytest.raises(CaseFileError, match="an existing YAML sweep file"):
        expand(tmp_path / "nope.yaml")


def test_derived_by_chooses_the_entries_of_the_label_value():
    """sweeps/lamb_damage.yaml: a hole is a cylinder of diameter ``size`` at (x, y); a notch a
    box one spacing wide along x and ``size`` long along y, centred at (x, y)."""
    sweep = expand(ROOT / "sweeps" / "lamb_damage.yaml")
    assert len(sweep.runs) == 2 * 50 * 3
    h = sweep.runs[0].case.discretization.spacing
    for run in sweep.runs:
        p, region = run.parameters, run.case.removals[0]
        if p["damage"] == "hole":
            assert region.type == "cylinder" and region.center[:2] == [p["x"], p["y"]]
            assert region.radius == p["size"] / 2
        else:
            assert region.type == "box"
            np.testing.assert_allclose(np.subtract(region.max, region.min)[:2], [h, p["size"]], rtol=1e-12)
            np.testing.assert_allclose(np.add(region.max, region.min)[:2] / 2, [p["x"], p["y"]], rtol=1e-12)
    positions = {(r.parameters["x"], r.parameters["y"]) for r in sweep.runs}
    assert len(positions) == 50  # the same 50 positions for both damages and all sizes


def test_derived_by_needs_a_declared_label(tmp_path):
    spec = {"vary": {"product": {"kind": ["a"]}}, "labels": ["kind"], "derived_by": {"other": {"a": {}}}}
    with pytest.raises(CaseFileError, match="'other' is not one of labels"):
        expand(sweep_file(tmp_path, **spec))


def test_bloch_command_needs_its_frequencies(tmp_path):
    with pytest.raises(CaseFileError, match="outputs.bloch"):
        expand(sweep_file(tmp_path, vary={"product": {"material.E": [1e9]}}, command="bloch"))
