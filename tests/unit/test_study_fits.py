"""Series grouping and fits of ``peridyn.jobs.study`` on runs built from f = a + b h^p.

Synthetic runs (no solve): the model of seed 002 eq. 6.5 truncated to one term, with the
thesis's order range (table 6.1: 1 < p < 2); expected limits are the a of the formula.
"""

import csv
import json
import time

import numpy as np
import pytest

from peridyn.errors import InputError
from peridyn.jobs.study import StudyRun, fit_series, write_study

#: Continuum values (Hz) and orders of two mode types; FE values of issue 9.
LIMITS = {"1st bending": (1706.1, 1.6), "1st torsional": (1982.9, 1.9)}


def _runs(spacings, factors, slope=2.0e6, outlier=None):
    runs = []
    for m in factors:
        for h in spacings:
            modes = {label: a + slope * m * h**p for label, (a, p) in LIMITS.items()}
            if outlier is not None and h == outlier:
                modes = {k: v * 0.9 for k, v in modes.items()}  # a pre-asymptotic coarse run
            runs.append(StudyRun(h, m, points=1, modes=modes))
    return runs


def test_delta_m_series_recover_each_modes_limit_and_order():
    fits = fit_series(_runs([1e-3, 1.5e-3, 2e-3, 3e-3], [1.4143, 3.001]))
    assert len(fits) == 4  # 2 horizon factors x 2 mode types
    for fit in fits:
        a, p = LIMITS[fit["mode"]]
        assert abs(fit["value_hz"] - a) / a < 1e-10 and abs(fit["order"] - p) < 1e-8
        assert fit["x"] == sorted(fit["x"]) and fit["fitted_runs"] == 4


def test_finest_leaves_a_pre_asymptotic_coarse_run_out():
    runs = _runs([1e-3, 1.5e-3, 2e-3, 3e-3], [2.0], outlier=3e-3)
    assert all("oscillating" in f["error"] for f in fit_series(runs))
    for fit in fit_series(runs, finest=3):
        a, p = LIMITS[fit["mode"]]
        assert abs(fit["value_hz"] - a) / a < 1e-10 and fit["fitted_runs"] == 3


def test_m_series_groups_runs_of_equal_horizon_in_metres():
    # 1 mm x 3, 1.5 mm x 2 and 3 mm x 1 share delta = 3 mm: one m-convergence series
    runs = [
        StudyRun(h, m, modes={"1st bending": 1706.1 + 1e6 * h**2})
        for h, m in ((1e-3, 3.0), (1.5e-3, 2.0), (3e-3, 1.0), (2e-3, 3.0))
    ]
    fits = fit_series(runs, series=("m",))
    (three,) = [f for f in fits if "value_hz" in f]
    assert three["group"] == "horizon 3 mm" and abs(three["value_hz"] - 1706.1) < 1e-8
    assert [f["error"] for f in fits if f is not three] == [
        "1 run(s) with this mode: richardson: needs at least three resolutions, got 1"
    ]


def test_references_give_the_errors_of_the_finest_run_and_of_the_limit(tmp_path):
    runs = _runs([1e-3, 2e-3, 4e-3], [3.0])
    fits = fit_series(runs, references={"1st bending": 1706.1})
    bending = next(f for f in fits if f["mode"] == "1st bending")
    assert abs(bending["value_error"]) < 1e-12
    assert bending["finest_error"] == pytest.approx(2e6 * 3 * 1e-3**1.6 / 1706.1, rel=1e-12)
    summary = write_study(tmp_path, runs, fits, {"case": "synthetic"}, time.perf_counter())
    assert json.loads((tmp_path / "study.json").read_text()) == summary  # the whole summary
    rows = list(csv.DictReader(open(tmp_path / "study.csv")))
    assert [r["mode"] for r in rows] == ["1st bending", "1st torsional"]
    assert float(rows[0]["value_hz"]) == pytest.approx(1706.1, rel=1e-9)
    assert len(list(csv.DictReader(open(tmp_path / "runs.csv")))) == 6  # 3 runs x 2 modes


def test_skipped_runs_are_left_out_of_the_fits():
    runs = _runs([1e-3, 2e-3, 4e-3, 8e-3], [3.0])
    runs[0].skipped, runs[0].modes = "too large", {}
    fits = fit_series(runs)
    assert all(f["x"] == [2e-3, 4e-3, 8e-3] for f in fits)
    assert np.allclose([f["value_hz"] for f in fits], [a for a, _ in LIMITS.values()], rtol=1e-10)


def test_a_diverging_series_has_no_limit_and_says_why_in_the_result_and_the_table():
    # Issue 19: 1st bending of the 96 x 48 x 8 mm PMMA plate at 3.001 h with the energy
    # correction, measured at 1.6, 2 and 8/3 mm: 1691.3, 1628.7, 1564.8 Hz. The differences
    # (62.6, 63.9 Hz) do not shrink although the steps grow (0.4, 0.67 mm), so f = f_inf + C h^p
    # needs p <= 0 (Roache 1998, ch. 5: no asymptotic range): no value, and the reason.
    from peridyn.cli.study_cmd import format_table

    runs = [
        StudyRun(h, 3.001, modes={"1st bending": f})
        for h, f in ((1.6e-3, 1691.3), (2e-3, 1628.7), (8e-3 / 3, 1564.8))
    ]
    (fit,) = fit_series(runs, references={"1st bending": 1847.8})
    assert "value_hz" not in fit and fit["value_error"] is None
    assert fit["error"].startswith(
        "diverging: the differences do not shrink with the spacing "
        "(1691.3 at 0.0016, 1628.7 at 0.002, 1564.8 at 0.00266667)"
    )
    table = format_table(
        {"runs": [r.to_dict() for r in runs], "fits": [fit], "finest": None, "output_dir": "out"}
    ).splitlines()
    row = next(k for k, line in enumerate(table) if line.lstrip().startswith("1st bending"))
    assert "no fit: diverging" in table[row] and table[row + 1].strip() == fit["error"]


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"series": ("delta-m", "dm")}, "unknown convergence series ['dm']"),
        ({"finest": 2}, "finest = 2: a Richardson fit needs at least three runs"),
    ],
)
def test_bad_fit_options_are_named(kwargs, message):
    with pytest.raises(InputError, match=message.replace("[", r"\[").replace("]", r"\]")):
        fit_series(_runs([1e-3, 2e-3, 4e-3], [3.0]), **kwargs)
