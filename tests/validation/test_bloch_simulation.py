"""Bloch prediction of the discrete plate against a simulation's f-k wavenumbers (issue 10,
"prediction meets simulation"; slow: one ~1-3 minute run of the seed 000 plate).

The seed case (``cases/lamb_plate.yaml``: 3 layers, 1.2 mm, 3.015 dx, LPS + shear factor)
is run without its plane probe, snapshots and kx-ky map (they do not enter the f-k pick).
Time integration moves k by about -(omega dt)^2 / 24 = -0.04 % (omega dt = 0.10), so the
run's f-k wavenumbers should be the Bloch ones up to the f-k pick's own error.
"""

from pathlib import Path

import pytest

from peridyn.analysis.bloch import Discretisation
from peridyn.analysis.bloch_study import predict
from peridyn.io.case import load_case
from peridyn.simulation import run_case

CASES = Path(__file__).resolve().parents[2] / "cases"
SHORTER = ["analysis.kxky=null", "output.planes={}", "output.snapshot_times=[]",
           "output.pzt_sensors={}", "output.plots=false"]


@pytest.mark.slow
def test_seed_plate_fk_wavenumbers_match_bloch(tmp_path):
    """A0 at 150 kHz within 1.5 % of the Bloch wavenumber of the same discretisation.

    S0 is checked to one wavenumber bin of the line (2 pi / L = 21 rad/m, 12 % of k): the
    300 mm line holds four S0 wavelengths on each side of the source, and the pick of a
    synthetic record with the exact Bloch dispersion moves by -1.6 % (no edges) to -9 %
    (edge reflections added) (benchmarks/bloch_vs_fk.py), so 1.5 % is beyond this run's
    resolution for S0.
    """
    case = load_case(CASES / "lamb_plate.yaml", SHORTER)
    summary = run_case(case, tmp_path)
    bloch = {m["mode"]: m["wavenumber_rad_m"]
             for m in predict(Discretisation.from_case(case), [150e3])}
    picked = summary["fk_peaks_rad_m"]
    assert picked["A0"] == pytest.approx(bloch["A0"], rel=0.015)
    line = case.output.lines["x_axis"]
    length = (line.end[0] - line.start[0]) * line.points / (line.points - 1)
    assert abs(picked["S0"] - bloch["S0"]) < 2 * 3.141592653589793 / length
