"""Seed 000 Lamb-wave plate against Rayleigh-Lamb theory (slow: two ~1 minute runs).

The shipped cases keep the seed's discretisation (3 layers 1 mm apart, 1.2 mm, 3.015 dx) with
LPS and the shear-correction factor (VALIDATION.md V2). Theory: VALIDATION.md V1.
"""

import json
from pathlib import Path

import h5py
import numpy as np
import pytest

from peridyn.io.case import load_case
from peridyn.io.hdf5 import read_series
from peridyn.simulation import run_case

CASES = Path(__file__).resolve().parents[2] / "cases"
#: V1, 150 kHz: S0 and A0 wavenumbers (rad/m) and the S0 group velocity (m/s).
K_S0, K_A0 = 176.34, 612.41
CG_S0 = 5330.9


@pytest.fixture(scope="module")
def pristine(tmp_path_factory):
    out = tmp_path_factory.mktemp("lamb_plate")
    summary = run_case(load_case(CASES / "lamb_plate.yaml", ["output.plots=false"]), out)
    return out, summary


@pytest.fixture(scope="module")
def holed(tmp_path_factory):
    out = tmp_path_factory.mktemp("lamb_plate_hole")
    run_case(load_case(CASES / "lamb_plate_hole.yaml", ["output.plots=false"]), out)
    return out


def _sensor(out, name, component):
    """Times (s) and one displacement component (m) of a named sensor."""
    with h5py.File(out / "results.h5", "r") as f:
        names = json.loads(f["series/sensor_u"].attrs["names"])
    _, times, data = read_series(out / "results.h5", "sensor_u")
    return times, data[:, names.index(name), "xyz".index(component)]


def _line_point(out, x, component):
    """Times and one component of the top-layer line probe at the point nearest to x (m)."""
    _, times, data = read_series(out / "results.h5", "line_x_axis")
    xs = np.linspace(0.0006, 0.2994, data.shape[1])
    return times, data[:, np.argmin(np.abs(xs - x)), "xyz".index(component)]


@pytest.mark.slow
def test_fk_wavenumbers_at_150_khz(pristine):
    """S0 and A0 wavenumbers from the f-k map of the line through the PZT within 5% of V1."""
    _, summary = pristine
    assert summary["fk_peaks_rad_m"]["S0"] == pytest.approx(K_S0, rel=0.05)
    assert summary["fk_peaks_rad_m"]["A0"] == pytest.approx(K_A0, rel=0.05)


@pytest.mark.slow
def test_mode_structure_through_the_thickness(pristine):
    """At the sensor 50 mm away, split u_x on the faces into its mirror-symmetric part
    (top + bottom) / 2 (S0: in-plane motion even in z) and antisymmetric part (A0: odd in z).
    The mid layer must carry the symmetric part only: its deviation from it is below 10% of
    the antisymmetric (A0) surface amplitude (A0's in-plane motion vanishes at the mid-plane),
    and its amplitude equals the symmetric part's within 5% (S0 uniform through the thickness).
    """
    out, _ = pristine
    _, top = _sensor(out, "s50_top", "x")
    _, mid = _sensor(out, "s50_mid", "x")
    _, bottom = _sensor(out, "s50_bottom", "x")
    symmetric, antisymmetric = 0.5 * (top + bottom), 0.5 * (top - bottom)
    assert np.abs(mid - symmetric).max() < 0.10 * np.abs(antisymmetric).max()
    assert np.abs(mid).max() == pytest.approx(np.abs(symmetric).max(), rel=0.05)


@pytest.mark.slow
def test_hole_scatters_only_after_the_fastest_path(pristine, holed):
    """The hole (10 mm, centred 50 mm from the PZT) scatters waves back to the point 25 mm from
    the PZT: the difference of the two runs (u_z) stays below 2% of its peak until the fastest
    scattered wave can arrive (S0 out to the hole's near edge at 45 mm and back, 65 mm, leading
    edge of the burst), and the scattered packet is strong (over 10% of the direct wave)."""
    out_p, _ = pristine
    t, without = _line_point(out_p, 0.1758, "z")
    _, with_hole = _line_point(holed, 0.1758, "z")
    scattered = with_hole - without
    earliest = 0.065 / CG_S0
    assert np.abs(scattered[t < earliest]).max() < 0.02 * np.abs(scattered).max()
    assert np.abs(scattered).max() > 0.10 * np.abs(without).max()
