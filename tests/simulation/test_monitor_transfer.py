"""The monitoring job's two damage transfers (docs/monitoring.md, "Damage transfer") on a crack
that is a clean cut: the small notched-hole plate of cases/monitoring/monitor_small.yaml whose
fatigue may break only the bonds across the notch's plane y = 20 mm (``fatigue.crack_plane``),
so the fatigue grows a mode-I crack along it and no damage band. Interrogated at 0, 5.5 and
6.5 mm of crack (the crack then crosses the path t0-t1, x = 22 mm, at least 3.5 mm, more than a
horizon, behind its tip) by the default transfer (``bonds``: the fatigue model's broken bonds
through the thickness), each repeated by the ``cut`` (the crack path as through-thickness cuts).

Where the crack is a clean cut, both give the wave model the same bonds (tests/unit/
test_monitor_plan.py); they still differ at the tip. The cut ends where the crack path of the
points at the tip's damage threshold ends (the tip rule's point); the fatigue model's broken
bonds do not stop there: some across the plane behind that point still hold, and about as many
beyond it have broken (13 bonds at 5.5 mm, 15 at 6.5 mm), a process zone about 1.5 mm long. The
bonds route's crack reaches farther, and the index of a path that the crack crosses grows with
its length (here 31% per mm), so the bonds route's indices are the higher ones: by 13% (residual
energy) and 14-15% (correlation) at 5.5 and 6.5 mm, outside the 10% the monitoring acceptance
asks. That line is a strict xfail naming this cause: a cut that ended where the broken bonds do
would have to make it pass.

The job (fatigue of 80 steps on 1 568 points, 15 wave runs of 4 704 points, two processes of one
thread) takes 34 s on 2 cores at load 4-6, 49 s at load 9.
"""

from pathlib import Path

import numpy as np
import pytest
import yaml

from peridyn.jobs.monitor import read_history, run_monitor

CASES = Path(__file__).parents[2] / "cases" / "monitoring"
#: The notch's plane (the crack plane), m: the notch runs along y = 20 mm to its root at x = 20 mm.
PLANE_Y, ROOT_X = 0.020, 0.020
INDICES = ("residual_energy_index", "correlation_index")


@pytest.fixture(scope="module")
def job(tmp_path_factory):
    """The clean-crack monitoring job: (summary's monitoring block, fatigue history)."""
    folder = tmp_path_factory.mktemp("clean")
    fatigue = yaml.safe_load((CASES / "monitor_small_fatigue.yaml").read_text())
    fatigue["fatigue"]["crack_plane"] = {"axis": "y", "at": PLANE_Y}
    fatigue["fatigue"]["mapping"] = [{"steps": 80, "tau": 5.0e-4}]  # to a crack of about 8 mm
    (folder / "fatigue.yaml").write_text(yaml.safe_dump(fatigue))
    mon = yaml.safe_load((CASES / "monitor_small.yaml").read_text())
    mon.update(
        fatigue_case="fatigue.yaml",
        wave_case=str(CASES / mon["wave_case"]),
        schedule={"every_crack_growth": 5.5e-3, "until_crack_length": 6.5e-3},
        output={"plots": False},
    )
    (folder / "monitor.yaml").write_text(yaml.safe_dump(mon))
    out = folder / "out"
    summary = run_monitor(folder / "monitor.yaml", out, executor="processes", workers=2, threads=1)
    return summary["monitoring"], read_history(out / "fatigue")


def _crossing_x(points: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """x (m) at which each bond ((n, 2) point indices) crosses the plane y = PLANE_Y."""
    a, b = points[pairs[:, 0]], points[pairs[:, 1]]
    return a[:, 0] + (PLANE_Y - a[:, 1]) / (b[:, 1] - a[:, 1]) * (b[:, 0] - a[:, 0])


def test_on_a_clean_crack_the_bonds_route_reaches_past_the_cut_and_gives_the_higher_indices(job):
    m, history = job
    t = m["transfer"]
    assert (t["route"], t["check"]) == ("bonds", "cut") and m["crossed_paths"] == ["t0-t1"]
    assert t["interrogations"] == [1, 2] and m["final_crack_length_m"] == pytest.approx(6.5e-3)
    # the crack is confined to the plane: every bond the fatigue broke crosses it
    y = history.points[history.broken_pairs, 1]
    assert np.all((y[:, 0] - PLANE_Y) * (y[:, 1] - PLANE_Y) < 0)
    # and its broken bonds reach past the tip rule's point (the cut's end) at the last one
    x = _crossing_x(history.points, history.broken_pairs)
    assert np.count_nonzero(x > ROOT_X + m["final_crack_length_m"]) > 0
    for name in INDICES:
        bonds, cut = np.array(t[name]["bonds"]), np.array(t[name]["cut"])
        assert np.all(cut > 0) and np.all(bonds > cut), name


@pytest.mark.xfail(
    strict=True,
    reason="the cut ends at the tip rule's point, short of the fatigue model's partly broken bonds "
    "ahead of it (about 1.5 mm of process zone): 13-15% apart at 5.5 and 6.5 mm",
)
def test_on_a_clean_crack_the_two_transfers_agree_within_ten_percent(job):
    """The monitoring acceptance's line: the two damage-transfer routes agree on the crossed
    paths' indices within 10% at every interrogation after the crack grew."""
    m, _ = job
    for name in INDICES:
        assert m["transfer"][name]["relative_difference_max"] <= 0.10, name
