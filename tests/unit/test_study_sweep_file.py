"""The sweep file of ``peridyn study`` (``peridyn.jobs.study.study_sweep``): its levels are the cases
the study solved before it ran them as a sweep, i.e. ``load_case`` with the user's overrides,
then ``solver.type=modal``, ``solver.modes``, the spacing, the horizon factor and
``discretization.horizon_m=null`` (with the modes' figures off), in the order horizon, spacing.
Validation only: nothing is built or solved."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from peridyn.errors import CaseFileError
from peridyn.io.case import load_case
from peridyn.jobs.study import study_sweep
from peridyn.jobs.sweep_spec import expand

CASE = str(Path(__file__).resolve().parents[2] / "cases" / "pmma_plate.yaml")


def _expanded(tmp_path, *args, **kwargs):
    path = tmp_path / "study-sweep.yaml"
    path.write_text(json.dumps(study_sweep(CASE, *args, **kwargs)))
    return expand(path)


def test_levels_are_the_cases_the_study_solved(tmp_path):
    overrides = ["geometry.size=[0.096,0.048,0.008]", "solver.modes=3", "discretization.horizon_m=0.01"]
    spacings, factors = [4e-3, 8e-3 / 3], [1.4143, 3.001]
    sweep = _expanded(tmp_path, spacings, factors, n_modes=8, overrides=overrides)
    levels = [(h, m) for m in factors for h in spacings]  # horizon outer, spacing inner
    assert [
        (r.parameters["discretization.spacing"], r.parameters["discretization.horizon"]) for r in sweep.runs
    ] == levels
    for run, (h, m) in zip(sweep.runs, levels, strict=True):
        before = [
            *overrides,
            "solver.type=modal",
            "solver.modes=8",  # --modes wins over a --set of it
            f"discretization.spacing={h!r}",
            f"discretization.horizon={m!r}",
            "discretization.horizon_m=null",  # the horizon is the multiple of the spacing
            "output.plots=false",
        ]
        assert run.case == load_case(CASE, before)


def test_an_override_may_turn_the_level_figures_on_and_a_bad_one_is_named(tmp_path):
    sweep = _expanded(tmp_path, [4e-3], [1.4143], overrides=["output.plots=true"])
    assert sweep.runs[0].case.output.plots is True
    with pytest.raises(CaseFileError, match="key.path=value"):
        study_sweep(CASE, [4e-3], [1.4143], overrides=["solver.modes"])
