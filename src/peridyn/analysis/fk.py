"""Frequency-wavenumber analysis of guided-wave records: f-k spectra, (kx, ky) maps, peaks.

Sign convention: a wave ``A cos(k . x - omega t)`` travelling along ``+k`` shows
at frequency ``f = omega / (2 pi) > 0`` and wavenumber ``+k``. Spectra are
``U(f, k) = sum_t sum_x w(t) w(x) u(x, t) exp(+i 2 pi f t) exp(-i k . x)``
divided by the sums of the windows, so such a wave peaks at ``A / 2`` when
``(f, k)`` falls on a bin. Only ``f >= 0`` is kept (``u`` is real); wavenumbers
are signed: on a line through a source, waves going to ``+x`` are at ``k > 0``
and waves going to ``-x`` (or reflected) at ``k < 0``.

- :func:`fk_transform`: the 2D FFT of a space-time record on a line (B-scan);
  :func:`line_fk` reads a line-probe series of a results file for it.
- :func:`kxky_transform`, :func:`kxky_from_hdf5`: (kx, ky) maps of a plane
  record at chosen frequencies. The time transform is a direct projection on
  ``exp(+i 2 pi f t)`` at those frequencies only, accumulated over chunks of
  records, so a plane series larger than memory streams from the results file.
- :func:`pick_wavenumbers`, :func:`ring_radius`: peaks of a spectrum at one
  frequency and of the azimuthal average of a (kx, ky) map, refined between
  bins by a parabola through the logarithm of the peak sample and its two
  neighbours (exact for Gaussian peaks, close for Hann-windowed ones).
- :func:`point_grid`: the regular x-y grid of a plate layer's points, to
  place a record's values on the ``(n_x, n_y)`` array the transforms need.
- :func:`mirror_parts`: the symmetric (S) and antisymmetric (A) parts of a plate
  record from its top and bottom faces, so that S0 and A0 are measured apart.
- :func:`phase_wavenumber`: the wavenumber of an outgoing wave from the phase
  along a line of its time Fourier transform at one frequency, which has no
  wavenumber-bin limit; :func:`line_mode_wavenumbers` applies it to S0 (from the
  in-plane divergence) and A0 of a run's line probes on both faces.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from scipy.fft import next_fast_len
from scipy.special import hankel1

from peridyn.errors import InputError
from peridyn.io.results import Results
from peridyn.physics.loads import parse_components

__all__ = [
    "PointGrid",
    "azimuthal_average",
    "fk_transform",
    "kxky_from_hdf5",
    "kxky_transform",
    "line_fk",
    "line_mode_wavenumbers",
    "mirror_parts",
    "phase_wavenumber",
    "pick_wavenumbers",
    "point_grid",
    "ring_radius",
]

#: Relative spread of the time steps accepted as uniform.
_UNIFORM_STEP = 1e-6
#: Coordinates are compared after rounding to this many decimals (m): 1 nm.
_COORD_DECIMALS = 9
#: Largest distance (in grid steps) of a point from its grid node.
_GRID_TOLERANCE = 1e-6
#: Records per chunk when streaming a series from a results file.
CHUNK_RECORDS = 256
#: Local maxima below this fraction of the largest value (-60 dB) are not peaks.
PEAK_THRESHOLD = 1e-3


def fk_transform(
    signal,
    dt: float,
    dx: float,
    window="hann",
    pad_time: float = 2.0,
    pad_space: float = 2.0,
    f_max: float | None = None,
):
    """Frequency-wavenumber spectrum of a space-time record on a line.

    Parameters
    ----------
    signal : (n_t, n_x) float
        One displacement component at ``n_x`` points ``dx`` apart, ``n_t``
        records ``dt`` apart.
    dt : float, s
        Time between records.
    dx : float, m
        Distance between points.
    window : str, tuple or None
        Window in time and in space, any name of
        :func:`scipy.signal.get_window` (``"hann"``, ``("tukey", 0.25)``);
        None for none.
    pad_time, pad_space : float >= 1
        Zero padding: the transforms have at least ``pad * n`` samples.
    f_max : float or None, Hz
        Keep only frequencies up to ``f_max``.

    Returns
    -------
    freq : (n_f,) float64, Hz
        ``0 <= f <= min(f_max, 1 / (2 dt))``, ascending.
    k : (n_k,) float64, rad/m
        Signed wavenumbers, ascending from ``-pi / dx``.
    magnitude : (n_f, n_k) float64, units of ``signal``
        ``|U(f, k)|`` (module docstring).
    """
    u = _real_array(signal, 2, "signal")
    dt, dx = _positive("dt", dt), _positive("dx", dx)
    n_t, n_x = u.shape
    wt, wx = _window(window, n_t), _window(window, n_x)
    nt, nx = _padded(pad_time, n_t, "pad_time"), _padded(pad_space, n_x, "pad_space")
    freq = np.fft.rfftfreq(nt, dt)
    keep = freq <= (freq[-1] if f_max is None else _positive("f_max", f_max))
    in_time = np.conj(np.fft.rfft(u * wt[:, None], n=nt, axis=0)[keep])
    spectrum = np.fft.fftshift(np.fft.fft(in_time * wx, n=nx, axis=1), axes=1)
    k = 2.0 * np.pi * np.fft.fftshift(np.fft.fftfreq(nx, dx))
    return freq[keep], k, np.abs(spectrum) / (wt.sum() * wx.sum())


def line_fk(path: Results | str | os.PathLike, series_name: str, spacing: float, component="z", **options):
    """:func:`fk_transform` of a line-probe series of a results file.

    Parameters
    ----------
    path : Results, str or path-like
        A ``results.h5`` (``peridyn.io.results.Results`` or its path).
    series_name : str
        E.g. ``"line_axis"``: records (n_points, 3) along the line.
    spacing : float, m
        Distance between the line's points.
    component : "x", "y", "z" or 0, 1, 2
    **options
        ``window``, ``pad_time``, ``pad_space``, ``f_max`` of :func:`fk_transform`.

    Returns
    -------
    freq, k, magnitude
        As :func:`fk_transform`.
    """
    _, times, data = Results.of(path).series(series_name)
    return fk_transform(data[:, :, _component(component)], _uniform_step(times), spacing, **options)


def kxky_transform(
    plane, dt: float, dx: float, dy: float, frequencies, window="hann", pad_space: float = 2.0
):
    """(kx, ky) maps of a plane record at chosen frequencies.

    Parameters
    ----------
    plane : (n_t, n_x, n_y) float
        One displacement component on a regular grid (zeros where no point).
    dt : float, s
        Time between records.
    dx, dy : float, m
        Grid steps.
    frequencies : float or (n_freq,) float, Hz
    window : str, tuple or None
        Window in time, x and y (see :func:`fk_transform`).
    pad_space : float >= 1
        Zero padding in x and y.

    Returns
    -------
    kx : (n_kx,) float64, rad/m
    ky : (n_ky,) float64, rad/m
        Signed, ascending.
    maps : (n_freq, n_kx, n_ky) float64
        ``|U(f, kx, ky)|``.
    """
    u = _real_array(plane, 3, "plane")
    omega = _angular(frequencies)
    times = np.arange(len(u)) * _positive("dt", dt)
    wt = _window(window, len(u))
    projected = _project(times, wt, u, omega)
    return _spatial_maps(projected, wt.sum(), _positive("dx", dx), _positive("dy", dy), window, pad_space)


def kxky_from_hdf5(
    path: Results | str | os.PathLike,
    series_name: str,
    grid: PointGrid,
    frequencies,
    component="z",
    window="hann",
    pad_space: float = 2.0,
    chunk_records: int = CHUNK_RECORDS,
):
    """:func:`kxky_transform` of a series of a results file, read ``chunk_records`` at a time.

    Parameters
    ----------
    path : Results, str or path-like
        A ``results.h5`` (``peridyn.io.results.Results`` or its path).
    series_name : str
        A series of (n_points, 3) records, e.g. ``"plane_top"`` or ``"field_u"``.
    grid : PointGrid
        Where each used entry of a record lies on the grid (:func:`point_grid`).
    frequencies : float or (n_freq,) float, Hz
    component : "x", "y", "z" or 0, 1, 2
    window, pad_space
        As in :func:`kxky_transform`.
    chunk_records : int
        Records in memory at once.

    Returns
    -------
    kx, ky, maps
        As :func:`kxky_transform`; the record times come from the file.
    """
    omega = _angular(frequencies)
    column = _component(component)
    results = Results.of(path)
    wt = _window(window, results.n_records(series_name))
    projected, start = 0.0, 0
    for times, data in results.iter_series(series_name, chunk_records):
        projected = projected + _project(times, wt[start : start + len(times)], data[:, :, column], omega)
        start += len(times)
    # placed on the grid once, after the projection in time (both are linear)
    return _spatial_maps(grid.scatter(projected), wt.sum(), grid.dx, grid.dy, window, pad_space)


def pick_wavenumbers(
    freq,
    k,
    magnitude,
    frequency: float,
    expected: dict | None = None,
    n_peaks: int | None = None,
    tolerance: float = 0.2,
    threshold: float = PEAK_THRESHOLD,
):
    """Wavenumbers of the spectral peaks at one frequency.

    The spectrum at ``frequency`` is interpolated linearly between the two
    nearest rows; its local maxima are refined by a parabola through the log
    magnitude of three samples.

    Parameters
    ----------
    freq : (n_f,) float, Hz
    k : (n_k,) float, rad/m
        Evenly spaced.
    magnitude : (n_f, n_k) float
        From :func:`fk_transform`.
    frequency : float, Hz
        Within ``freq``.
    expected : dict of str to float, optional
        Mode name to a guess of its wavenumber (rad/m, signed): each mode gets
        the highest peak within ``tolerance * |guess|`` of its guess, NaN if
        there is none.
    n_peaks : int, optional
        Instead of ``expected``: the ``n_peaks`` highest peaks.
    tolerance : float
        Relative search window around each guess.
    threshold : float
        Local maxima below ``threshold`` times the largest value are not peaks
        (leakage, round-off).

    Returns
    -------
    dict of str to float, or (n_peaks,) float64, rad/m
        With ``expected``: the wavenumber of each mode; with ``n_peaks``: the
        peaks' wavenumbers, ascending (fewer when there are fewer peaks).
    """
    freq = np.asarray(freq, dtype=float)
    magnitude = np.asarray(magnitude, dtype=float)
    if magnitude.shape != (len(freq), len(k)):
        raise InputError(f"magnitude must have shape ({len(freq)}, {len(k)}), got {magnitude.shape}")
    if not freq[0] <= frequency <= freq[-1]:
        raise InputError(
            f"frequency {frequency!r} Hz lies outside the spectrum [{freq[0]:g}, {freq[-1]:g}] Hz"
        )
    j = int(np.clip(np.searchsorted(freq, frequency), 1, len(freq) - 1))
    share = (frequency - freq[j - 1]) / (freq[j] - freq[j - 1])
    row = (1.0 - share) * magnitude[j - 1] + share * magnitude[j]
    return _pick(np.asarray(k, dtype=float), row, expected, n_peaks, tolerance, threshold)


def azimuthal_average(kx, ky, kmap):
    """Mean of a (kx, ky) map over rings ``|k|`` one wavenumber step wide.

    Parameters
    ----------
    kx : (n_kx,) float, rad/m
    ky : (n_ky,) float, rad/m
        Evenly spaced, as from :func:`kxky_transform`.
    kmap : (n_kx, n_ky) float

    Returns
    -------
    k_r : (n_r,) float64, rad/m
        Ring centres, from 0 to the largest full circle in the map.
    profile : (n_r,) float64
        Mean of ``kmap`` in each ring.
    """
    kx, ky = np.asarray(kx, dtype=float), np.asarray(ky, dtype=float)
    kmap = np.asarray(kmap, dtype=float)
    if kmap.shape != (len(kx), len(ky)):
        raise InputError(f"map must have shape ({len(kx)}, {len(ky)}), got {kmap.shape}")
    step = max(kx[1] - kx[0], ky[1] - ky[0])
    radius = np.hypot(*np.meshgrid(kx, ky, indexing="ij"))
    n_r = int(min(kx.max(), -kx.min(), ky.max(), -ky.min()) / step)
    ring = np.rint(radius / step).astype(np.int64).ravel()
    inside = ring < n_r
    counts = np.bincount(ring[inside], minlength=n_r)
    sums = np.bincount(ring[inside], weights=kmap.ravel()[inside], minlength=n_r)
    return np.arange(n_r) * step, sums / np.maximum(counts, 1)


def ring_radius(
    kx,
    ky,
    kmap,
    expected: dict | None = None,
    n_peaks: int | None = None,
    tolerance: float = 0.2,
    threshold: float = PEAK_THRESHOLD,
):
    """Radii of the rings of a (kx, ky) map: peaks of its azimuthal average times ``sqrt(|k|)``.

    The 2D transform of a wave spreading from a point source,
    ``exp(i k r) / sqrt(r)``, is its Hankel transform, whose far-field kernel
    ``J0(|k| r) ~ sqrt(2 / (pi |k| r)) cos(|k| r - pi / 4)`` makes the ring
    fall as ``1 / sqrt(|k|)`` across its width and pulls a plain peak below
    ``k``: measured on ``sin(k r - omega t) / sqrt(r)`` under a Hann window,
    by 2.2% with 8.5 wavelengths across the map and 7% with 4.5. The
    ``sqrt(|k|)`` factor removes the leading part of that bias (left: 0.75%
    and 1.8%; ``tests/unit/analysis/test_fk.py``).

    Parameters
    ----------
    kx, ky, kmap
        As in :func:`azimuthal_average`.
    expected, n_peaks, tolerance, threshold
        As in :func:`pick_wavenumbers` (guesses are radii, rad/m).

    Returns
    -------
    dict of str to float, or (n_peaks,) float64, rad/m
    """
    k_r, profile = azimuthal_average(kx, ky, kmap)
    return _pick(k_r, profile * np.sqrt(k_r), expected, n_peaks, tolerance, threshold)


@dataclass(frozen=True, eq=False)
class PointGrid:
    """Positions of points on a regular x-y grid.

    Attributes
    ----------
    x : (n_x,) float64, m
    y : (n_y,) float64, m
        Grid lines, ascending and evenly spaced.
    ix, iy : (n_sel,) int64
        Grid position of each point.
    index : (n_sel,) int64
        Entry of each point in a record of a series.
    """

    x: np.ndarray
    y: np.ndarray
    ix: np.ndarray
    iy: np.ndarray
    index: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """``(n_x, n_y)``."""
        return len(self.x), len(self.y)

    @property
    def dx(self) -> float:
        """Grid step along x, m."""
        return float(self.x[1] - self.x[0])

    @property
    def dy(self) -> float:
        """Grid step along y, m."""
        return float(self.y[1] - self.y[0])

    def scatter(self, values, fill: float = 0.0) -> np.ndarray:
        """Place record values on the grid.

        Parameters
        ----------
        values : (..., n_record) float
            Values of every entry of a record (or of a stack of records).
        fill : float
            Value of grid nodes without a point (holes, outline).

        Returns
        -------
        (..., n_x, n_y) float64 (complex128 for complex ``values``)
        """
        values = np.asarray(values)
        dtype = complex if np.iscomplexobj(values) else float
        out = np.full((*values.shape[:-1], *self.shape), fill, dtype=dtype)
        out[..., self.ix, self.iy] = values[..., self.index]
        return out


def point_grid(points, index=None) -> PointGrid:
    """The regular x-y grid that the points lie on (one plate layer, a plane probe).

    Parameters
    ----------
    points : (n_sel, 2 or 3) float, m
        Coordinates of the points; z is ignored.
    index : (n_sel,) int, optional
        Entry of each point in a series record (default ``0 .. n_sel - 1``).

    Returns
    -------
    PointGrid

    Raises
    ------
    InputError
        Points off a regular grid, or two points on one node (several layers).
    """
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] not in (2, 3):
        raise InputError(f"points must have shape (n, 2 or 3), got {pts.shape}")
    index = np.arange(len(pts)) if index is None else np.asarray(index, dtype=np.int64)
    if index.shape != (len(pts),):
        raise InputError(f"index must have shape ({len(pts)},), got {index.shape}")
    (x, ix), (y, iy) = _grid_axis(pts[:, 0], "x"), _grid_axis(pts[:, 1], "y")
    if len(np.unique(ix * len(y) + iy)) < len(pts):
        raise InputError("several points lie on one grid node: pass the points of one layer")
    return PointGrid(x, y, ix, iy, index)


def mirror_parts(top, bottom) -> dict[str, np.ndarray]:
    """Symmetric and antisymmetric parts of a plate record about its mid-plane.

    S modes (S0, S1, ...) have u_x and u_y even and u_z odd in z; A modes the opposite.
    With ``top`` and ``bottom`` recorded at mirror-image heights, the S part is
    ``((t + b) / 2, (t + b) / 2, (t - b) / 2)`` and the A part
    ``((t - b) / 2, (t - b) / 2, (t + b) / 2)`` per component (x, y, z); each holds
    only its family's modes.

    Parameters
    ----------
    top, bottom : (..., 3) float
        Displacements at mirror-image points (e.g. the top and bottom line probes).

    Returns
    -------
    dict "S", "A" to (..., 3) float64
    """
    t, b = np.asarray(top, dtype=float), np.asarray(bottom, dtype=float)
    if t.shape != b.shape or t.shape[-1:] != (3,):
        raise InputError(f"top and bottom records must have one shape (..., 3), got {t.shape} and {b.shape}")
    even, odd = 0.5 * (t + b), 0.5 * (t - b)
    in_plane = np.array([True, True, False])
    return {"S": np.where(in_plane, even, odd), "A": np.where(in_plane, odd, even)}


def phase_wavenumber(
    signal,
    dt: float,
    x,
    frequency: float,
    source: float,
    r_range,
    order: int | None = 0,
    iterations: int = 20,
) -> float:
    """Wavenumber of an outgoing wave from the phase along a line at one frequency.

    ``U(x) = sum_t u(x, t) exp(+i 2 pi f t) dt`` is, for a record that holds the whole
    packet at each point, the source spectrum times the wave's transfer function, so its
    phase along the line has no finite-window or wavenumber-bin error. A wave spreading
    from a point source has ``U ~ H_n(k r)`` (Hankel function of the first kind: order 1
    for the radial displacement of a radially symmetric source, 0 for the out-of-plane
    one), whose phase is ``k r - (2 n + 1) pi / 4 + (4 n^2 - 1) / (8 k r) + ...``; the last
    term would bias a straight-line fit by ``-(4 n^2 - 1) / (8 (k r)^2)`` (-1.4 % for S0 at
    150 kHz, 30 mm). The fit removes it: ``k`` is the common slope, one intercept per side
    of the source, of ``phase - (arg H_n(k r) - k r)``, iterated from the straight line.

    Parameters
    ----------
    signal : (n_t, n_x) float
        One displacement component at the points ``x``, records ``dt`` apart from the
        start of the excitation; the packet must have passed each used point by the end.
    dt : float, s
    x : (n_x,) float, m
        Positions along the line, ascending, less than half a wavelength apart.
    frequency : float, Hz
    source : float, m
        Position of the source on the line.
    r_range : (float, float), m
        Distances from the source used for the fit (outside the near field, inside any
        absorbing layers).
    order : 0, 1 or None
        Hankel order of the wave; None: a straight-crested wave (plain linear fit).
    iterations : int
        Fixed-point iterations of the spreading correction.

    Returns
    -------
    float, rad/m
    """
    u = _real_array(signal, 2, "signal")
    x = np.asarray(x, dtype=float)
    if x.shape != (u.shape[1],) or np.any(np.diff(x) <= 0):
        raise InputError(f"x must hold {u.shape[1]} ascending positions, got shape {x.shape}")
    r_min, r_max = (float(v) for v in r_range)
    if not 0 <= r_min < r_max:
        raise InputError(f"r_range must be two distances 0 <= r_min < r_max (m), got {r_range!r}")
    if order not in (0, 1, None):
        raise InputError(f"order must be 0, 1 or None, got {order!r}")
    omega = 2.0 * np.pi * _positive("frequency", frequency)
    times = np.arange(len(u)) * _positive("dt", dt)
    spectrum = np.exp(1j * omega * times) @ u
    sides = [
        (x > source) & (np.abs(x - source) >= r_min) & (np.abs(x - source) <= r_max),
        (x < source) & (np.abs(x - source) >= r_min) & (np.abs(x - source) <= r_max),
    ]
    sides = [side for side in sides if side.sum() >= 2]
    if not sides:
        raise InputError(
            f"no two points of the line lie {r_min:g} to {r_max:g} m from the source "
            f"at {source:g} m on one side"
        )
    r = [np.sort(np.abs(x[side] - source)) for side in sides]
    phase = [np.unwrap(np.angle(spectrum[side][np.argsort(np.abs(x[side] - source))])) for side in sides]
    design = np.zeros((sum(len(ri) for ri in r), 1 + len(sides)))
    design[:, 0] = np.concatenate(r)
    start = 0
    for j, ri in enumerate(r):
        design[start : start + len(ri), 1 + j] = 1.0
        start += len(ri)
    k = 0.0
    for _ in range(1 if order is None else iterations + 1):
        spreading = (
            np.concatenate([np.unwrap(np.angle(hankel1(order, k * ri))) - k * ri for ri in r])
            if k > 0
            else 0.0
        )
        k = float(np.linalg.lstsq(design, np.concatenate(phase) - spreading, rcond=None)[0][0])
        if not k > 0:
            raise InputError(
                "the phase does not grow away from the source: no outgoing wave "
                f"at {frequency:g} Hz in the fit range"
            )
    return abs(k)


#: Suffixes of the line series :func:`line_mode_wavenumbers` reads: the line on the top face,
#: on the bottom face, and one grid step to +y and -y of each.
LINE_SUFFIXES = ("", "_bottom", "_yp", "_ym", "_bottom_yp", "_bottom_ym")


def line_mode_wavenumbers(
    path: str | os.PathLike, line: str, x, dy: float, frequency: float, source: float, r_range
) -> dict[str, float]:
    """S0 and A0 wavenumbers of a run from line probes along x through a source.

    The series ``line_<line><suffix>`` (:data:`LINE_SUFFIXES`) hold the line on the top
    face, on the bottom face, and each of them shifted by ``+dy`` and ``-dy`` in y.
    S0 is read from the in-plane divergence of the symmetric part (:func:`mirror_parts`),
    ``d u_x / dx + d u_y / dy`` by central differences: a radial S0 wave has the divergence
    ``-k^2 phi ~ H_0(k r)``, and shear-horizontal waves (SH0), which a square source and
    the lattice also send along the line, have none. A0 is read from u_z of the
    antisymmetric part (``~ H_0(k r)``). Both by :func:`phase_wavenumber`, order 0.

    Parameters
    ----------
    path : Results, str or path-like
        A ``results.h5`` (``peridyn.io.results.Results`` or its path).
    line : str
        Name of the top-face line (e.g. ``"x_axis"``).
    x : (n_x,) float, m
        Positions of the lines' points along x (the same for all six lines).
    dy : float, m
        Shift in y of the ``_yp`` and ``_ym`` lines.
    frequency, source, r_range
        As in :func:`phase_wavenumber`.

    Returns
    -------
    dict "S0", "A0" to float, rad/m
    """
    records = {}
    results = Results.of(path)
    for suffix in LINE_SUFFIXES:
        _, times, records[suffix] = results.series(f"line_{line}{suffix}")
        if records[suffix].shape != records[""].shape:
            raise InputError(f"series line_{line}{suffix} does not have the shape of line_{line}")
    dt = _uniform_step(times)
    x = np.asarray(x, dtype=float)
    centre = mirror_parts(records[""], records["_bottom"])
    plus = mirror_parts(records["_yp"], records["_bottom_yp"])["S"]
    minus = mirror_parts(records["_ym"], records["_bottom_ym"])["S"]
    divergence = np.gradient(centre["S"][:, :, 0], x, axis=1) + (plus[:, :, 1] - minus[:, :, 1]) / (
        2.0 * _positive("dy", dy)
    )
    return {
        "S0": phase_wavenumber(divergence, dt, x, frequency, source, r_range, 0),
        "A0": phase_wavenumber(centre["A"][:, :, 2], dt, x, frequency, source, r_range, 0),
    }


# -- helpers ------------------------------------------------------------------------------


def _grid_axis(coord: np.ndarray, name: str) -> tuple[np.ndarray, np.ndarray]:
    """Evenly spaced grid lines covering ``coord`` and each value's line index."""
    levels = np.unique(np.round(coord, _COORD_DECIMALS))
    if len(levels) < 2:
        raise InputError(f"the points span a single {name} value: a grid needs two or more")
    step = float(np.min(np.diff(levels)))
    position = (coord - levels[0]) / step
    line = np.rint(position).astype(np.int64)
    if np.max(np.abs(position - line)) > _GRID_TOLERANCE:
        raise InputError(f"the points are not on a regular grid along {name} (step {step:g} m)")
    return levels[0] + step * np.arange(line.max() + 1), line


def _project(times, weights, block, omega) -> np.ndarray:
    """``sum_j w_j exp(+i omega t_j) block_j``: (n_freq, *block.shape[1:]) complex, as two real
    products (a real ``block`` is not copied to complex)."""
    phase = weights[None, :] * np.exp(1j * np.outer(omega, times))
    flat = block.reshape(len(block), -1)
    if np.iscomplexobj(flat):
        projected = phase @ flat
    else:
        projected = phase.real @ flat + 1j * (phase.imag @ flat)
    return projected.reshape(len(omega), *block.shape[1:])


def _spatial_maps(projected, time_gain, dx, dy, window, pad_space):
    """2D windowed, padded FFT of (n_freq, n_x, n_y) time projections -> kx, ky, |U|."""
    _, n_x, n_y = projected.shape
    wx, wy = _window(window, n_x), _window(window, n_y)
    nx, ny = _padded(pad_space, n_x, "pad_space"), _padded(pad_space, n_y, "pad_space")
    spectrum = np.fft.fft2(projected * np.outer(wx, wy), s=(nx, ny), axes=(1, 2))
    kx = 2.0 * np.pi * np.fft.fftshift(np.fft.fftfreq(nx, dx))
    ky = 2.0 * np.pi * np.fft.fftshift(np.fft.fftfreq(ny, dy))
    gain = time_gain * wx.sum() * wy.sum()
    return kx, ky, np.abs(np.fft.fftshift(spectrum, axes=(1, 2))) / gain


def _pick(axis: np.ndarray, values: np.ndarray, expected, n_peaks, tolerance, threshold):
    """Refined local maxima of ``values`` on the evenly spaced ``axis``."""
    if (expected is None) == (n_peaks is None):
        raise InputError("give either expected (mode name -> wavenumber guess) or n_peaks")
    interior = np.arange(1, len(values) - 1)
    middle = values[1:-1]
    peaks = interior[(middle > values[:-2]) & (middle >= values[2:]) & (middle >= threshold * values.max())]
    if n_peaks is not None:
        if int(n_peaks) != n_peaks or n_peaks < 1:
            raise InputError(f"n_peaks must be a positive integer, got {n_peaks!r}")
        best = peaks[np.argsort(values[peaks])[::-1][: int(n_peaks)]]
        return np.sort([_refine(axis, values, i) for i in best])
    found = {}
    for name, guess in expected.items():
        near = peaks[np.abs(axis[peaks] - guess) <= tolerance * abs(guess)]
        found[name] = _refine(axis, values, near[np.argmax(values[near])]) if len(near) else float("nan")
    return found


def _refine(axis: np.ndarray, values: np.ndarray, i: int) -> float:
    """Vertex of the parabola through the log of ``values[i-1:i+2]``."""
    y0, y1, y2 = np.log(np.maximum(values[i - 1 : i + 2], np.finfo(float).tiny))
    curvature = y0 - 2.0 * y1 + y2
    offset = 0.5 * (y0 - y2) / curvature if curvature < 0 else 0.0
    return float(axis[i] + offset * (axis[i + 1] - axis[i]))


def _window(window, n: int) -> np.ndarray:
    """(n,) window: none (ones), the periodic Hann window, or any of scipy.signal.get_window."""
    if window is None:
        return np.ones(n)
    if window == "hann" and n > 1:  # scipy.signal's periodic Hann, the same bits, without its 0.65 s import
        return 0.5 + 0.5 * np.cos(np.linspace(-np.pi, np.pi, n + 1)[:-1])
    from scipy.signal import get_window

    try:
        return get_window(window, n)
    except (ValueError, TypeError) as exc:
        raise InputError(f"unknown window {window!r}: {exc}") from None


def _padded(pad: float, n: int, name: str) -> int:
    if not (np.isfinite(pad) and pad >= 1):
        raise InputError(f"{name} must be a number >= 1, got {pad!r}")
    return next_fast_len(int(np.ceil(pad * n)))


def _positive(name: str, value) -> float:
    if not (np.isfinite(value) and value > 0):
        raise InputError(f"{name} must be positive and finite, got {value!r}")
    return float(value)


def _real_array(data, ndim: int, name: str) -> np.ndarray:
    arr = np.asarray(data, dtype=float)
    if arr.ndim != ndim or min(arr.shape) < 3:
        raise InputError(
            f"{name} must be a {ndim}-D array with at least 3 samples per axis, got shape {arr.shape}"
        )
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name} has non-finite values")
    return arr


def _angular(frequencies) -> np.ndarray:
    f = np.atleast_1d(np.asarray(frequencies, dtype=float))
    if f.ndim != 1 or not np.all(np.isfinite(f) & (f >= 0)):
        raise InputError(f"frequencies must be a list of non-negative numbers (Hz), got {frequencies!r}")
    return 2.0 * np.pi * f


def _component(component) -> int:
    (column,) = parse_components([component])
    return column


def _uniform_step(times: np.ndarray) -> float:
    """The time step of evenly spaced records, s."""
    steps = np.diff(times)
    if len(steps) < 2 or np.ptp(steps) > _UNIFORM_STEP * steps.mean():
        raise InputError(
            "the records are not evenly spaced in time (or fewer than 3): "
            "an f-k transform needs a constant step"
        )
    return float(steps.mean())
