"""Seed 000 Lamb-wave plate against Rayleigh-Lamb theory (slow: two ~1 minute runs, and the
converged preset, ~5 minutes).

The shipped cases keep the seed's discretisation (3 layers 1 mm apart, 1.2 mm, 3.015 dx) with
LPS and the shear-correction factor (VALIDATION.md V2). Theory: VALIDATION.md V1.
"""

from pathlib import Path

import numpy as np
import pytest
from scipy.signal import hilbert

from peridyn.io.case import load_case
from peridyn.io.results import Results
from peridyn.jobs.run import run_case

CASES = Path(__file__).resolve().parents[2] / "cases"
#: V1, 150 kHz: S0 and A0 wavenumbers (rad/m) and group velocities (m/s).
K_S0, K_A0 = 176.34, 612.41
CG_S0, CG_A0 = 5330.9, 2582.2


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
    results = Results(out / "results.h5")
    names = results.series_attrs("sensor_u")["names"]
    _, times, data = results.series("sensor_u")
    return times, data[:, names.index(name), "xyz".index(component)]


def _line_point(out, x, component):
    """Times and one component of the top-layer line probe at the point nearest to x (m)."""
    _, times, data = Results(out / "results.h5").series("line_x_axis")
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


@pytest.fixture(scope="module")
def converged(tmp_path_factory):
    out = tmp_path_factory.mktemp("lamb_plate_converged")
    summary = run_case(load_case(CASES / "lamb_plate_converged.yaml", ["output.plots=false"]), out)
    return out, summary


def _envelope_peak_time(times, signal, start, end):
    """Time of the largest Hilbert envelope of ``signal`` within [start, end] (s)."""
    envelope = np.abs(hilbert(signal))
    window = (times >= start) & (times <= end)
    return times[window][np.argmax(envelope[window])]


@pytest.mark.slow
def test_converged_preset_arrival_times_and_wavenumbers(converged):
    """The converged preset (5 layers, 0.4 mm, 1.5 dx; VALIDATION.md V2: wavenumbers and
    arrival times within 5 % of Rayleigh-Lamb): the f-k S0 and A0 wavenumbers at 150 kHz are
    within 5% of V1, and the S0 and A0 packets, separated by mirror symmetry ((top + bottom)/2
    of u_x and of u_z), reach the sensors 50 mm from the PZT at the V1 group velocities within
    5%, taking the burst's envelope centre as the emission time."""
    out, summary = converged
    assert summary["fk_peaks_rad_m"]["S0"] == pytest.approx(K_S0, rel=0.05)
    assert summary["fk_peaks_rad_m"]["A0"] == pytest.approx(K_A0, rel=0.05)
    t, ux_top = _sensor(out, "s50_top", "x")
    _, ux_bottom = _sensor(out, "s50_bottom", "x")
    _, uz_top = _sensor(out, "s50_top", "z")
    _, uz_bottom = _sensor(out, "s50_bottom", "z")
    emitted = 0.5 * 3.5 / 150e3
    t_s0 = _envelope_peak_time(t, 0.5 * (ux_top + ux_bottom), 0.0, 28e-6)
    t_a0 = _envelope_peak_time(t, 0.5 * (uz_top + uz_bottom), 20e-6, 45e-6)
    assert 0.050 / (t_s0 - emitted) == pytest.approx(CG_S0, rel=0.05)
    assert 0.050 / (t_a0 - emitted) == pytest.approx(CG_A0, rel=0.05)
