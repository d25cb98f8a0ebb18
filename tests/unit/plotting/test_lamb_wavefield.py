"""Lamb-wave figures (peridyn.plotting.lamb_wavefield) on small synthetic results."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from peridyn.analysis.fk import fk_transform, kxky_transform
from peridyn.analysis.lamb import dispersion_curves, lamb_modes
from peridyn.discretization import geometry
from peridyn.errors import InputError
from peridyn.io.hdf5 import HDF5Writer
from peridyn.physics.timefunctions import ToneBurst
from peridyn.plotting.lamb_wavefield import (
    _column_colorbar_axes,
    _panel_figure,
    plot_fk_map,
    plot_kxky_maps,
    plot_sensor_signals,
    plot_through_thickness,
    plot_wavefield_snapshots,
)

# VALIDATION.md V1: 2 mm aluminium plate (E Pa, nu, rho kg/m^3, thickness m); V2: 3 layers
# on the faces and mid-plane, snapshots at 20 and 40 us.
PLATE = (68.9e9, 0.33, 2700.0, 0.002)
TIMES = (0.0, 20e-6, 40e-6)
#: Wavenumber (rad/m) of the synthetic field: A0 at 150 kHz (V1).
K_A0 = 612.41
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _assert_png(path):
    data = path.read_bytes()
    assert data.startswith(PNG_SIGNATURE) and len(data) > 1000


@pytest.fixture
def results(tmp_path):
    """A results.h5 of a 16 x 12 mm, 3-layer plate: an A0-like field (uz even, ux odd in z)."""
    body = geometry.plate(16e-3, 12e-3, 2e-3, 1e-3, layers=3, layer_placement="surface")
    x, z = body.points[:, 0], body.points[:, 2] - 1e-3
    path = tmp_path / "results.h5"
    with HDF5Writer(path, body.points, body.volumes, {"case": "synthetic"}) as out:
        out.create_series("field_u", (body.n_points, 3))
        for step, t in enumerate(TIMES):
            phase = K_A0 * x - 2 * np.pi * 150e3 * t
            u = np.stack([-1e3 * z * np.sin(phase), 0.1 * np.cos(phase), np.cos(phase)], axis=1)
            out.append("field_u", step, t, 1e-9 * u)
    return path


def test_wavefield_snapshots(results, tmp_path):
    png = plot_wavefield_snapshots(results, tmp_path / "snap.png", [20e-6, 40e-6], layers=[0, -1])
    _assert_png(png)
    with pytest.raises(InputError, match="component"):
        plot_wavefield_snapshots(results, tmp_path / "bad.png", [20e-6], components="w")
    with pytest.raises(InputError, match="out of range"):
        plot_wavefield_snapshots(results, tmp_path / "bad.png", [20e-6], layers=[3])


def test_wavefield_panels_and_colour_bars_do_not_overlap():
    """The fixed panel grid of the wavefield figure: no two panels overlap, and each column's
    colour bar lies right of its panels and left of the next column's (boxes in figure
    fractions, as placed before drawing)."""
    fig, axes = _panel_figure(4, 3)
    bars = [_column_colorbar_axes(fig, axes[:, col]) for col in range(3)]
    boxes = [ax.get_position(original=True) for ax in axes.flat]
    for a, b in itertools.combinations(boxes, 2):
        assert a.x1 <= b.x0 or b.x1 <= a.x0 or a.y1 <= b.y0 or b.y1 <= a.y0
    for col, bar in enumerate(bars):
        box = bar.get_position()
        assert box.x0 > max(ax.get_position(original=True).x1 for ax in axes[:, col])
        if col + 1 < 3:
            assert box.x1 < min(ax.get_position(original=True).x0 for ax in axes[:, col + 1])
        assert 0.0 < box.y0 < box.y1 < 1.0 and box.x1 < 1.0


def test_through_thickness_cut(results, tmp_path):
    png = plot_through_thickness(results, tmp_path / "cut.png", 20e-6, (8e-3, 6e-3), (2e-3, 14e-3))
    _assert_png(png)
    with pytest.raises(InputError, match="no point"):
        plot_through_thickness(results, tmp_path / "none.png", 20e-6, (8e-3, 6e-3), (1.0, 2.0))


def test_fk_map_with_theory_and_peaks(tmp_path):
    t, x = np.meshgrid(np.arange(64) * 0.5e-6, np.arange(48) * 1e-3, indexing="ij")
    freq, k, magnitude = fk_transform(np.cos(K_A0 * x - 2 * np.pi * 150e3 * t), 0.5e-6, 1e-3, f_max=400e3)
    curves = dispersion_curves(*PLATE, f_max=400e3, n=30, max_order=0)
    png = plot_fk_map(
        freq, k, magnitude, tmp_path / "fk.png", theory=curves, peaks={"A0": (150e3, K_A0)}, k_max=1500.0
    )
    _assert_png(png)


def test_kxky_maps_with_theory_rings(tmp_path):
    frequencies = [110e3, 150e3, 185e3, 225e3]  # the seed's (kx, ky) figures
    x = (np.arange(41) - 20) * 1e-3
    r = np.maximum(np.hypot(*np.meshgrid(x, x, indexing="ij")), 0.5e-3)
    plane = np.stack([np.sin(K_A0 * r - 2 * np.pi * 150e3 * t) / np.sqrt(r) for t in np.arange(16) * 0.5e-6])
    kx, ky, maps = kxky_transform(plane, 0.5e-6, 1e-3, 1e-3, frequencies)
    modes = lamb_modes(*PLATE, frequencies, max_order=0)
    png = plot_kxky_maps(kx, ky, maps, frequencies, tmp_path / "kxky.png", theory=modes, k_max=1000.0)
    _assert_png(png)
    with pytest.raises(InputError, match="shape"):
        plot_kxky_maps(kx, ky, maps[:2], frequencies, tmp_path / "bad.png")


def test_sensor_signals(tmp_path):
    times = np.arange(200) * 0.5e-6
    burst = ToneBurst(150e3, 3.5)
    signals = {"pzt_1": 1e-5 * burst(times - 20e-6), "pzt_2": 5e-6 * burst(times - 40e-6)}
    png = plot_sensor_signals(times, signals, tmp_path / "sensors.png", excitation=burst(times))
    _assert_png(png)
