"""Figures of Lamb-wave runs: wavefield snapshots, f-k and (kx, ky) maps with theory, cuts, sensors.

Every function draws on an Agg canvas (never a window), saves a PNG at ``path``
and returns that path. Results-file figures read ``results.h5`` as written by
:class:`peridyn.io.recorder.Recorder`: ``/geometry/points`` and the ``field_u``
snapshots. The layer of each point of a plate is recovered from its z
coordinate (layers numbered from the bottom, as ``Body.layer_index``). B-scans
of line probes are drawn by :func:`peridyn.plotting.fields.plot_bscan`.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from peridyn.analysis.fk import point_grid
from peridyn.analysis.lamb import DispersionBranch, LambMode
from peridyn.errors import InputError
from peridyn.io.results import Results
from peridyn.physics.loads import parse_components

__all__ = [
    "plot_fk_map",
    "plot_kxky_maps",
    "plot_sensor_signals",
    "plot_through_thickness",
    "plot_wavefield_snapshots",
]

COMPONENTS = "xyz"
#: Coordinates are compared after rounding to this many decimals (m): 1 nm.
_COORD_DECIMALS = 9
#: Default depth of the dB colour scales of spectra.
DYNAMIC_RANGE_DB = 40.0


def plot_wavefield_snapshots(
    results: Results | str | os.PathLike,
    path: str | os.PathLike,
    times,
    components: str = "xyz",
    layers=None,
    series: str = "field_u",
) -> Path:
    """Maps of displacement components on each layer at chosen times.

    One row per (time, layer), one column per component; each column shares
    a symmetric colour scale.

    Parameters
    ----------
    results : Results, str or path-like
        A ``results.h5`` (``peridyn.io.results.Results`` or its path).
    path : str or path-like
        The PNG to write.
    times : sequence of float, s
        Each snapshot shown is the one recorded nearest to a time.
    components : str
        Any of ``"x"``, ``"y"``, ``"z"``.
    layers : sequence of int, optional
        Layers to show (0 = bottom, negative from the top); default all.
    series : str
        A series of whole-body records (n_points, 3).

    Returns
    -------
    Path
    """
    results = Results.of(results)
    points = results.array("geometry/points")
    layer, n_layers = _layers(points)
    shown = range(n_layers) if layers is None else [_layer_number(i, n_layers) for i in layers]
    columns = parse_components(components)
    found, records = _records_near(results, series, times)
    grids = {i: point_grid(points[layer == i], np.flatnonzero(layer == i)) for i in shown}
    rows = [(t, record, i) for t, record in zip(found, records, strict=True) for i in shown]
    fig, axes = _panel_figure(len(rows), len(columns))
    for col, c in enumerate(columns):
        limit = float(np.max(np.abs(records[:, :, c]))) or 1.0
        for row, (t, record, i) in enumerate(rows):
            image = _draw_layer(axes[row, col], grids[i], record[:, c], limit)
            axes[row, col].set_title(f"u{COMPONENTS[c]}, layer {i}, t = {t * 1e6:.1f} us", fontsize=9)
        fig.colorbar(image, cax=_column_colorbar_axes(fig, axes[:, col]), label=f"u{COMPONENTS[c]} (m)")
    return _save(fig, path)


def plot_fk_map(
    freq,
    k,
    magnitude,
    path: str | os.PathLike,
    theory: dict[str, DispersionBranch] | None = None,
    peaks: dict[str, tuple[float, float]] | None = None,
    f_max: float | None = None,
    k_max: float | None = None,
    dynamic_range_db: float = DYNAMIC_RANGE_DB,
) -> Path:
    """Frequency-wavenumber map (dB) with Rayleigh-Lamb curves overlaid.

    Parameters
    ----------
    freq : (n_f,) float, Hz
    k : (n_k,) float, rad/m
    magnitude : (n_f, n_k) float
        From :func:`peridyn.analysis.fk.fk_transform`.
    path : str or path-like
        The PNG to write.
    theory : dict of str to DispersionBranch, optional
        From :func:`peridyn.analysis.lamb.dispersion_curves`; drawn at ``+k``
        and, when the map has negative wavenumbers, at ``-k``.
    peaks : dict of str to (float, float), optional
        Picked peaks: mode name to (frequency Hz, wavenumber rad/m).
    f_max : float, optional, Hz
    k_max : float, optional, rad/m
        Axis limits (default: the whole map).
    dynamic_range_db : float
        Depth of the colour scale below the maximum.

    Returns
    -------
    Path
    """
    freq, k = np.asarray(freq, dtype=float), np.asarray(k, dtype=float)
    fig, axes = _figure(1, 1, (7.5, 5.5))
    ax = axes[0, 0]
    image = ax.pcolormesh(
        k,
        freq / 1e3,
        _decibels(magnitude, dynamic_range_db),
        cmap="viridis",
        shading="nearest",
        rasterized=True,
    )
    fig.colorbar(image, ax=ax, label="magnitude (dB)")
    signs = (1.0, -1.0) if k.min() < 0 else (1.0,)
    for n, (label, branch) in enumerate((theory or {}).items()):
        for sign in signs:
            ax.plot(
                sign * branch.wavenumber_rad_m,
                branch.frequency_hz / 1e3,
                color=f"C{n % 10}",
                lw=1.0,
                ls="-" if label.startswith("S") else "--",
                label=label if sign > 0 else None,
            )
    for label, (f, kp) in (peaks or {}).items():
        ax.plot(kp, f / 1e3, "w+", ms=12, mew=2)
        ax.annotate(label, (kp, f / 1e3), color="w", xytext=(5, 5), textcoords="offset points")
    k_max = k_max if k_max is not None else float(np.max(np.abs(k)))
    ax.set(
        xlim=(-k_max if len(signs) == 2 else 0.0, k_max),
        ylim=(0.0, (f_max if f_max is not None else freq[-1]) / 1e3),
        xlabel="wavenumber (rad/m)",
        ylabel="frequency (kHz)",
        title="Frequency-wavenumber map",
    )
    if theory:
        ax.legend(fontsize="small", loc="upper right", title="Rayleigh-Lamb")
    return _save(fig, path)


def plot_kxky_maps(
    kx,
    ky,
    maps,
    frequencies,
    path: str | os.PathLike,
    theory: list[LambMode] | None = None,
    k_max: float | None = None,
    dynamic_range_db: float = DYNAMIC_RANGE_DB,
) -> Path:
    """(kx, ky) maps (dB) at several frequencies with the theoretical rings.

    Parameters
    ----------
    kx : (n_kx,) float, rad/m
    ky : (n_ky,) float, rad/m
    maps : (n_freq, n_kx, n_ky) float
        From :func:`peridyn.analysis.fk.kxky_transform`.
    frequencies : (n_freq,) float, Hz
    path : str or path-like
        The PNG to write.
    theory : list of LambMode, optional
        From :func:`peridyn.analysis.lamb.lamb_modes` at ``frequencies``:
        each mode is a circle of radius its wavenumber on its frequency's map.
    k_max : float, optional, rad/m
        Half width of the axes (default: the whole map).
    dynamic_range_db : float
        Depth of the colour scales below each map's maximum.

    Returns
    -------
    Path
    """
    maps = np.asarray(maps, dtype=float)
    frequencies = np.atleast_1d(np.asarray(frequencies, dtype=float))
    if maps.shape != (len(frequencies), len(kx), len(ky)):
        raise InputError(f"maps must have shape ({len(frequencies)}, {len(kx)}, {len(ky)}), got {maps.shape}")
    fig, axes = _figure(1, len(frequencies), (4.2 * len(frequencies), 4.2))
    for ax, f, kmap in zip(axes[0], frequencies, maps, strict=True):
        ax.pcolormesh(
            kx, ky, _decibels(kmap, dynamic_range_db).T, cmap="viridis", shading="nearest", rasterized=True
        )
        for n, mode in enumerate(m for m in theory or [] if np.isclose(m.frequency_hz, f)):
            k = mode.wavenumber_rad_m
            ax.add_patch(Circle((0.0, 0.0), k, fill=False, ls="--", lw=1.0, color=f"C{n + 1}"))
            ax.annotate(mode.mode, (k / np.sqrt(2.0), k / np.sqrt(2.0)), color=f"C{n + 1}")
        half = k_max if k_max is not None else float(min(np.max(np.abs(kx)), np.max(np.abs(ky))))
        ax.set(
            xlim=(-half, half),
            ylim=(-half, half),
            aspect="equal",
            title=f"{f / 1e3:g} kHz",
            xlabel="kx (rad/m)",
            ylabel="ky (rad/m)",
        )
    return _save(fig, path)


def plot_through_thickness(
    results: Results | str | os.PathLike,
    path: str | os.PathLike,
    time: float,
    center,
    x_range=None,
    series: str = "field_u",
) -> Path:
    """Displacement on the x-z cut through a point (the actuator): vectors and profiles.

    The top panel shows (ux, uz) arrows at the points of the cut (z
    exaggerated); below, ux and uz along x on each layer: S0 moves the layers
    in phase in x and in opposition in z, A0 the other way round.

    Parameters
    ----------
    results : Results, str or path-like
        A ``results.h5`` of a plate (``peridyn.io.results.Results`` or its path).
    path : str or path-like
        The PNG to write.
    time : float, s
        The snapshot nearest to it is shown.
    center : 2 or 3 floats, m
        The cut is the grid line of y nearest to ``center[1]``.
    x_range : (float, float), optional, m
        Part of the cut shown (default: all of it).
    series : str
        A series of whole-body records (n_points, 3).

    Returns
    -------
    Path
    """
    results = Results.of(results)
    points = results.array("geometry/points")
    if points.shape[1] != 3:
        raise InputError("a through-thickness cut needs a 3D body")
    found, records = _records_near(results, series, [time])
    y = np.round(points[:, 1], _COORD_DECIMALS)
    levels = np.unique(y)
    cut = y == levels[np.argmin(np.abs(levels - center[1]))]
    if x_range is not None:
        cut &= (points[:, 0] >= x_range[0]) & (points[:, 0] <= x_range[1])
    if not cut.any():
        raise InputError(f"no point on the cut through {list(center)} within x_range {x_range}")
    x, z, u = points[cut, 0] * 1e3, points[cut, 2] * 1e3, records[0][cut]
    fig, axes = _figure(3, 1, (9.0, 8.0))
    axes[0, 0].quiver(
        x, z, u[:, 0], u[:, 2], np.hypot(u[:, 0], u[:, 2]), cmap="viridis", angles="xy", pivot="middle"
    )
    axes[0, 0].set(ylabel="z (mm)", title=f"(ux, uz) on the x-z cut, t = {found[0] * 1e6:.1f} us")
    layer, n_layers = _layers(points[cut])
    for i in range(n_layers):
        order = np.argsort(x[layer == i])
        label = f"layer {i} (z = {z[layer == i][0]:.2f} mm)"
        for row, c in ((1, 0), (2, 2)):
            axes[row, 0].plot(x[layer == i][order], u[layer == i][order, c], label=label)
    for row, c in ((1, 0), (2, 2)):
        axes[row, 0].set(ylabel=f"u{COMPONENTS[c]} (m)")
        axes[row, 0].grid(alpha=0.3)
    axes[1, 0].legend(fontsize="small")
    axes[2, 0].set_xlabel("x (mm)")
    return _save(fig, path)


def plot_sensor_signals(times, signals: dict, path: str | os.PathLike, excitation=None) -> Path:
    """PZT sensor signals (mean in-plane strain) against time, under the excitation.

    Parameters
    ----------
    times : (n_t,) float, s
    signals : dict of str to (n_t,) float
        Sensor name to signal, e.g. from :func:`peridyn.physics.transducers.pzt_sensor_signal`.
    path : str or path-like
        The PNG to write.
    excitation : (n_t,) float, optional
        The actuator's time function at ``times``, drawn in a panel above.

    Returns
    -------
    Path
    """
    t = np.asarray(times, dtype=float) * 1e6
    panels = 1 if excitation is None else 2
    fig, axes = _figure(panels, 1, (8.0, 2.2 + 2.2 * panels))
    if excitation is not None:
        axes[0, 0].plot(t, excitation, color="k")
        axes[0, 0].set(ylabel="excitation")
    ax = axes[-1, 0]
    for name, signal in signals.items():
        ax.plot(t, signal, label=name)
    ax.set(xlabel="time (us)", ylabel="eps_xx + eps_yy (mean)")
    ax.legend(fontsize="small")
    for a in axes[:, 0]:
        a.grid(alpha=0.3)
    return _save(fig, path)


# -- helpers ------------------------------------------------------------------------------


def _figure(rows: int, cols: int, size) -> tuple[Figure, np.ndarray]:
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig, np.asarray(fig.subplots(rows, cols, squeeze=False))


#: Panel grid of the wavefield figure, inches: each panel's axes and the margins around it
#: (left: y tick labels and label; right: the column's colour bar, its ticks and label; top: the
#: title; bottom: x tick labels and label).
_PANEL_AXES = (2.18, 1.5)
_PANEL_MARGINS = {"left": 0.62, "right": 1.0, "top": 0.3, "bottom": 0.5}
#: Colour bar of a column: gap to the axes and width (inches), share of the column's height.
_COLORBAR = (0.25, 0.12, 0.45)


def _panel_figure(rows: int, cols: int) -> tuple[Figure, np.ndarray]:
    """A ``rows`` x ``cols`` grid of map panels at fixed positions, with room for a colour bar
    right of each column: no layout engine (which measures every tick label of every panel
    twice before drawing)."""
    (width, height), m = _PANEL_AXES, _PANEL_MARGINS
    column, row = m["left"] + width + m["right"], m["top"] + height + m["bottom"]
    fig = Figure(figsize=(column * cols, row * rows))
    FigureCanvasAgg(fig)
    axes = fig.subplots(
        rows,
        cols,
        squeeze=False,
        gridspec_kw={
            "left": m["left"] / (column * cols),
            "right": 1.0 - m["right"] / (column * cols),
            "bottom": m["bottom"] / (row * rows),
            "top": 1.0 - m["top"] / (row * rows),
            "wspace": (m["right"] + m["left"]) / width,
            "hspace": (m["top"] + m["bottom"]) / height,
        },
    )
    return fig, np.asarray(axes)


def _column_colorbar_axes(fig: Figure, column_axes) -> object:
    """Axes of a colour bar right of a column of panels, centred on it (``_COLORBAR``)."""
    top, bottom = column_axes[0].get_position(original=True), column_axes[-1].get_position(original=True)
    fig_width, _ = fig.get_size_inches()
    gap, width, share = _COLORBAR
    span = top.y1 - bottom.y0
    return fig.add_axes(
        (top.x1 + gap / fig_width, bottom.y0 + 0.5 * (1.0 - share) * span, width / fig_width, share * span)
    )


def _save(fig: Figure, path) -> Path:
    fig.savefig(path, format="png", dpi=120)
    return Path(path)


def _layers(points: np.ndarray) -> tuple[np.ndarray, int]:
    """Layer of each point from its z (0 = lowest), and the number of layers."""
    z = points[:, 2] if points.shape[1] == 3 else np.zeros(len(points))
    levels, layer = np.unique(np.round(z, _COORD_DECIMALS), return_inverse=True)
    return layer, len(levels)


def _layer_number(index, n_layers: int) -> int:
    if not -n_layers <= int(index) < n_layers:
        raise InputError(f"layer {index} out of range for a plate with {n_layers} layers")
    return int(index) % n_layers


def _records_near(results, series: str, times) -> tuple[np.ndarray, np.ndarray]:
    """The records nearest to each of ``times``, streamed one at a time.

    Returns (n_times,) record times (s) and (n_times, *record_shape) records.
    """
    wanted = np.atleast_1d(np.asarray(times, dtype=float))
    best_gap = np.full(len(wanted), np.inf)
    found, records = np.zeros(len(wanted)), [None] * len(wanted)
    for chunk_times, data in Results.of(results).iter_series(series, 1):
        gap = np.abs(wanted - chunk_times[0])
        for i in np.flatnonzero(gap < best_gap):
            best_gap[i], found[i], records[i] = gap[i], chunk_times[0], data[0]
    if records[0] is None:
        raise InputError(f"{os.fspath(results)}: series {series!r} has no record")
    return found, np.stack(records)


def _draw_layer(ax, grid, values: np.ndarray, limit: float):
    """Image of one layer's values (record order) on its grid, mm axes."""
    image = grid.scatter(values, fill=np.nan).T
    extent = 1e3 * np.array(
        [grid.x[0] - grid.dx / 2, grid.x[-1] + grid.dx / 2, grid.y[0] - grid.dy / 2, grid.y[-1] + grid.dy / 2]
    )
    ax.set(xlabel="x (mm)", ylabel="y (mm)")
    return ax.imshow(
        image, origin="lower", extent=extent, cmap="RdBu_r", vmin=-limit, vmax=limit, interpolation="nearest"
    )


def _decibels(magnitude, dynamic_range_db: float) -> np.ndarray:
    mag = np.asarray(magnitude, dtype=float)
    peak = mag.max() if mag.max() > 0 else 1.0
    return np.maximum(20.0 * np.log10(np.maximum(mag, 1e-300) / peak), -dynamic_range_db)
