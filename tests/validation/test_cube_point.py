"""Point excitation in a maraging-steel cube (seed 001, section 4; VALIDATION.md V3).

The slow test runs ``cases/cube_point.yaml`` in full (about 2 minutes on 2 cores,
1 030 301 points) and compares the P front along x and the S fronts along y and z
with the group velocities the discrete dispersion relation of the same grid
predicts at the fronts' dominant frequencies (issue 4: within 3%). The fast tests
check the front measurement on synthetic fields.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

from peridyn.analysis.dispersion import Medium, dispersion_relation
from peridyn.analysis.wavefront import compare_with_relation, front_speed, measure_fronts
from peridyn.io.case import load_case
from peridyn.io.hdf5 import HDF5Writer

CASE = Path(__file__).resolve().parents[2] / "cases" / "cube_point.yaml"
#: Stations 15-35 mm from the source: beyond the P near field (k_P r > 9 at 500 kHz), before
#: the first reflections from the faces 50 mm away arrive.
R_MIN, R_MAX = 15e-3, 35e-3


def _burst(t, frequency=500e3, width=2e-6):
    """Gaussian-windowed sine, centred at t = 0."""
    return np.exp(-0.5 * (t / width) ** 2) * np.sin(2 * np.pi * frequency * t)


def test_front_speed_of_a_synthetic_pulse():
    times = np.arange(0.0, 30e-6, 0.05e-6)
    distances = np.arange(0.0, 40e-3, 1e-3)
    speed = 4321.0
    signals = _burst(times[:, None] - 5e-6 - distances[None, :] / speed)
    front = front_speed(times, distances, signals, "x", 10e-3, 30e-3)
    assert front.speed == pytest.approx(speed, rel=1e-3)
    assert front.frequency == pytest.approx(500e3, rel=0.02)
    assert len(front.distances) == 21


def _synthetic_results(path, speeds):
    """results.h5 with tubes around the axes and u_x = sum_a g(t - |x_a| / c_a)."""
    h = 1e-3
    grid = np.arange(-40, 41) * h
    points, tubes = [], {}
    for a, axis in enumerate("xyz"):
        start = len(points)
        for s in grid:
            for i in (-1, 0, 1):
                for j in (-1, 0, 1):
                    p = [i * h, j * h, 0.0]
                    p.insert(a, s)
                    points.append(p[:3])
        tubes[axis] = np.arange(start, len(points))
    points = np.array(points)
    times = np.arange(0.0, 25e-6, 0.05e-6)
    with HDF5Writer(path, points, np.full(len(points), h**3), {}) as out:
        for axis, index in tubes.items():
            x = points[index]
            out.write_array(f"probes/plane_tube_{axis}", index)
            out.create_series(f"plane_tube_{axis}", (len(index), 3))
            for step, t in enumerate(times):
                u = np.zeros((len(index), 3))
                u[:, 0] = sum(_burst(t - 4e-6 - np.abs(x[:, a]) / c) for a, c in enumerate(speeds))
                out.append(f"plane_tube_{axis}", step, t, u)


def test_fronts_from_dilatation_and_rotation_of_a_synthetic_field(tmp_path):
    speeds = (5300.0, 2800.0, 2700.0)
    _synthetic_results(tmp_path / "results.h5", speeds)
    fronts = measure_fronts(tmp_path / "results.h5", 10e-3, 35e-3)
    for axis, speed in zip("xyz", speeds, strict=True):
        assert fronts[axis].speed == pytest.approx(speed, rel=5e-3)


@pytest.mark.slow
def test_cube_fronts_travel_at_the_group_velocity_of_the_relation(tmp_path):
    from peridyn.jobs.run import run_case

    case = load_case(CASE, ["output.plots=false"])
    start = time.perf_counter()
    summary = run_case(case, tmp_path)
    seconds = time.perf_counter() - start
    d, m = case.discretization, case.material
    relation = dispersion_relation(
        m.model,
        Medium(m.E, m.nu, m.density),
        d.horizon * d.spacing,
        d.spacing,
        d.influence,
        discrete=True,
        partial_volumes=d.partial_volumes,
        points=3000,
    )
    fronts = measure_fronts(tmp_path / "results.h5", R_MIN, R_MAX)
    rows = compare_with_relation(fronts, relation)
    print(f"\ncube_point: {summary['points']} points, {summary['steps']} steps, {seconds:.0f} s")
    for axis, row in rows.items():
        print(
            f"  {axis}: front {row['speed_m_s']:.0f} m/s at {row['frequency_hz'] / 1e3:.0f} kHz, "
            f"group velocity {row['group_velocity_m_s']:.0f} m/s, error {row['error']:+.2%}"
        )
    for axis, row in rows.items():
        assert abs(row["error"]) < 0.03, axis  # issue 4 acceptance; measured -0.3%, +0.2%, +0.2%
    # the ellipsoid: P along x outruns S along y and z (ratio of the group velocities, 1.9)
    assert rows["x"]["speed_m_s"] / rows["y"]["speed_m_s"] == pytest.approx(
        rows["x"]["group_velocity_m_s"] / rows["y"]["group_velocity_m_s"], rel=0.03
    )
