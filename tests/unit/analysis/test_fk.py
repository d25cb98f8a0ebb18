"""Frequency-wavenumber analysis (peridyn.analysis.fk) on synthetic wavefields."""

from __future__ import annotations

import numpy as np
import pytest

from peridyn.analysis.fk import (
    azimuthal_average,
    fk_transform,
    kxky_from_hdf5,
    kxky_transform,
    line_fk,
    pick_wavenumbers,
    point_grid,
    ring_radius,
)
from peridyn.discretization import geometry
from peridyn.errors import InputError
from peridyn.io.hdf5 import HDF5Writer

# VALIDATION.md V1 (Rayleigh-Lamb theory, 2 mm aluminium plate) at 150 kHz:
# wavenumbers (rad/m) and group velocities (m/s) of S0 and A0.
F0 = 150e3
K = {"S0": 176.34, "A0": 612.41}
CG = {"S0": 5330.9, "A0": 2582.2}
OMEGA = 2 * np.pi * F0
# Sampling: 0.5 us (Nyquist 1 MHz), 1 mm (Nyquist 3142 rad/m), 200 x 200 samples.
DT, DX, N = 0.5e-6, 1e-3, 200


def _space_time():
    t, x = np.arange(N) * DT, np.arange(N) * DX
    return np.meshgrid(t, x, indexing="ij")


def _relative_errors(found):
    return {mode: found[mode] / K[mode] - 1 for mode in K}


def test_two_steady_waves_are_recovered_within_one_percent():
    t, x = _space_time()
    u = np.cos(K["S0"] * x - OMEGA * t) + 0.7 * np.cos(K["A0"] * x - OMEGA * t + 0.3)
    freq, k, magnitude = fk_transform(u, DT, DX)
    errors = _relative_errors(pick_wavenumbers(freq, k, magnitude, F0, {"S0": 180, "A0": 600}))
    assert all(abs(e) < 0.01 for e in errors.values()), errors  # measured 3e-4 and 2e-5


def test_dispersive_bursts_are_recovered_within_one_percent():
    """Two wave groups with k(f) = k0 + 2 pi (f - f0) / cg (V1's k and cg at 150 kHz)."""
    t, x = _space_time()
    u = np.zeros_like(t)
    for f in np.linspace(50e3, 250e3, 201):
        envelope = np.exp(-0.5 * ((f - F0) / 25e3) ** 2)
        for mode, amplitude in (("S0", 1.0), ("A0", 0.7)):
            k = K[mode] + 2 * np.pi * (f - F0) / CG[mode]
            u += amplitude * envelope * np.cos(k * x - 2 * np.pi * f * (t - 20e-6))
    freq, k, magnitude = fk_transform(u, DT, DX, f_max=500e3)
    assert freq[-1] <= 500e3
    errors = _relative_errors(pick_wavenumbers(freq, k, magnitude, F0, {"S0": 180, "A0": 600}))
    assert all(abs(e) < 0.01 for e in errors.values()), errors  # measured 2e-4 and 2e-5


def test_sign_convention_and_amplitude_on_a_bin():
    """A wave A cos(k x - w t) on an exact bin peaks at +k with A / 2 (module docstring)."""
    t, x = _space_time()
    f, k = 20 / (2 * N * DT), 2 * np.pi * 30 / (2 * N * DX)  # bins of the twice padded grid
    forward = 3.0 * np.cos(k * x - 2 * np.pi * f * t)
    freq, kk, magnitude = fk_transform(forward, DT, DX)
    i, j = np.unravel_index(np.argmax(magnitude), magnitude.shape)
    assert np.isclose(freq[i], f) and np.isclose(kk[j], k)
    assert np.isclose(magnitude[i, j], 1.5, rtol=1e-12)
    backward = np.cos(k * x + 2 * np.pi * f * t)
    peak = pick_wavenumbers(*fk_transform(backward, DT, DX), f, n_peaks=1)
    assert np.isclose(peak[0], -k, rtol=1e-6)


@pytest.mark.bitwise
def test_hann_window_is_scipy_periodic_hann_to_the_bit():
    """The Hann window computed without importing scipy.signal (0.65 s) is scipy.signal's
    ``get_window("hann", n)`` (periodic: the DFT-even window of spectral analysis) bit for bit. Both are
    ``0.5 + 0.5 cos`` of the same ``np.linspace(-pi, pi, n + 1)`` values with NumPy's elementwise
    functions, in one process: the same bits on any CPU."""
    from scipy.signal import get_window

    from peridyn.analysis.fk import _window

    for n in (1, 2, 3, 200, 747, 4096):
        assert np.array_equal(_window("hann", n), get_window("hann", n)), n
    assert np.array_equal(_window(("tukey", 0.25), 64), get_window(("tukey", 0.25), 64))


def test_n_peaks_and_bad_requests():
    t, x = _space_time()
    u = np.cos(K["S0"] * x - OMEGA * t) + np.cos(K["A0"] * x - OMEGA * t)
    freq, k, magnitude = fk_transform(u, DT, DX)
    peaks = pick_wavenumbers(freq, k, magnitude, F0, n_peaks=2)
    assert np.allclose(peaks, [K["S0"], K["A0"]], rtol=0.01)
    assert np.isnan(pick_wavenumbers(freq, k, magnitude, F0, {"S1": 1500.0})["S1"])
    with pytest.raises(InputError, match="outside"):
        pick_wavenumbers(freq, k, magnitude, 2e6, n_peaks=1)
    with pytest.raises(InputError, match="either"):
        pick_wavenumbers(freq, k, magnitude, F0)
    with pytest.raises(InputError, match="pad_time"):
        fk_transform(u, DT, DX, pad_time=0.5)
    with pytest.raises(InputError, match="window"):
        fk_transform(u, DT, DX, window="no-such-window")


# -- (kx, ky) maps ------------------------------------------------------------------------

#: A 300 x 300 mm plate at the seed's 1.2 mm spacing (VALIDATION V2), source at its centre.
N_XY, DXY = 251, 1.2e-3


def _circular_waves(modes, n_t=40):
    """sum over modes of sin(k r - w t) / sqrt(r): (n_t, n, n) records DT apart."""
    x = (np.arange(N_XY) - N_XY // 2) * DXY
    r = np.maximum(np.hypot(*np.meshgrid(x, x, indexing="ij")), 0.5 * DXY)
    return np.stack(
        [sum(np.sin(K[m] * r - OMEGA * t) for m in modes) / np.sqrt(r) for t in np.arange(n_t) * DT]
    )


@pytest.mark.parametrize("modes", [("S0",), ("A0",), ("S0", "A0")], ids="+".join)
def test_ring_of_a_circular_wave_within_two_percent(modes):
    kx, ky, maps = kxky_transform(_circular_waves(modes), DT, DXY, DXY, [F0])
    assert maps.shape == (1, len(kx), len(ky))
    found = ring_radius(kx, ky, maps[0], {m: K[m] for m in modes})
    errors = {m: found[m] / K[m] - 1 for m in modes}
    # measured: S0 -0.75% alone, -1.4% beside A0; A0 -0.11% alone, +0.05% beside S0
    assert all(abs(e) < 0.02 for e in errors.values()), errors


def test_azimuthal_average_of_a_constant_map():
    k = np.linspace(-100.0, 100.0, 41)
    k_r, profile = azimuthal_average(k, k, np.ones((41, 41)))
    assert np.allclose(profile, 1.0) and k_r[0] == 0.0 and k_r[-1] <= 100.0


def _plate_records(tmp_path, n_t=23):
    """A results file with a 2-layer plate and a field series of a plane wave on it."""
    body = geometry.plate(16e-3, 12e-3, 2e-3, 1e-3, layers=2)
    top = geometry.layer(body, -1)
    times = np.arange(n_t) * DT
    u = np.zeros((n_t, body.n_points, 3))
    x, y = body.points[:, 0], body.points[:, 1]
    u[:, :, 2] = np.cos(K["A0"] * (0.6 * x + 0.8 * y)[None, :] - OMEGA * times[:, None])
    path = tmp_path / "results.h5"
    with HDF5Writer(path, body.points, body.volumes, {"case": "test"}) as out:
        out.create_series("field_u", (body.n_points, 3))
        for step, (t, record) in enumerate(zip(times, u, strict=True)):
            out.append("field_u", step, t, record)
    return path, body, top, u


def test_streamed_hdf5_maps_equal_in_memory_maps(tmp_path):
    path, body, top, u = _plate_records(tmp_path)
    grid = point_grid(body.points[top], np.flatnonzero(top))
    assert grid.shape == (16, 12) and np.isclose(grid.dx, 1e-3) and np.isclose(grid.dy, 1e-3)
    frequencies = [110e3, 150e3]
    streamed = kxky_from_hdf5(path, "field_u", grid, frequencies, chunk_records=7)
    in_memory = kxky_transform(grid.scatter(u[:, :, 2]), DT, grid.dx, grid.dy, frequencies)
    for a, b in zip(streamed, in_memory, strict=True):
        assert np.allclose(a, b, rtol=1e-12, atol=1e-12 * np.max(b))


def test_line_fk_reads_a_series(tmp_path):
    path, body, top, u = _plate_records(tmp_path)
    line = np.flatnonzero(top)[::12]  # points along x at the lowest y of the top layer
    with HDF5Writer(tmp_path / "line.h5", body.points, body.volumes, {}) as out:
        out.create_series("line_axis", (len(line), 3))
        for step, record in enumerate(u):
            out.append("line_axis", step, step * DT, record[line])
    freq, k, magnitude = line_fk(tmp_path / "line.h5", "line_axis", 1e-3, "z")
    expected = fk_transform(u[:, line, 2], DT, 1e-3)
    assert np.allclose(magnitude, expected[2]) and np.allclose(k, expected[1])


def test_point_grid_handles_holes_and_refuses_non_grids():
    body = geometry.plate(10e-3, 8e-3, 1e-3, 1e-3, layers=1).remove(
        lambda p: np.hypot(p[:, 0] - 5e-3, p[:, 1] - 4e-3) < 1.5e-3
    )
    grid = point_grid(body.points)
    assert grid.shape == (10, 8)
    image = grid.scatter(np.ones(body.n_points), fill=np.nan)
    assert np.isnan(image).sum() == 80 - body.n_points
    with pytest.raises(InputError, match="one grid node"):
        point_grid(geometry.plate(10e-3, 8e-3, 2e-3, 1e-3, layers=2).points)
    with pytest.raises(InputError, match="regular grid"):
        point_grid(np.array([[0.0, 0.0], [1.0, 0.0], [2.5, 1.0]]))
