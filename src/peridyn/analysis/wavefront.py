"""Wave fronts of a point excitation (the dispersion study, section 4): speeds from axis probes.

A displacement pulse along x at the centre of a cube sends a P wave along x
and S waves (polarised along x) along y and z. On the axes, u_x itself mixes
P, S and near-field terms: on the x axis the near field carries an S-speed
arrival of relative size ``2 k_S / (k_P^2 r)`` (60% at 20 mm and 250 kHz in
steel, Stokes' solution), so in a cube a few wavelengths wide the envelope of
u_x does not move at either speed. The dilatation ``div u`` holds only
P-speed terms and the rotation ``curl u`` only S-speed terms (Helmholtz
decomposition), so the fronts are measured on them:

- P along the pulse axis: the dilatation;
- S along another axis a: the rotation about the third axis,
  ``du_p/da - du_a/dp`` (p the pulse axis).

The derivatives are central differences over the 3 x 3-point tubes recorded
around each axis (plane probes ``tube_x``, ``tube_y``, ``tube_z`` of the case:
line probes with their eight neighbouring lines). At each station the arrival
time is the peak of the Hilbert envelope (refined by a parabola through the
three samples around it); the front speed is the inverse slope of the
least-squares line through (distance, arrival time) over the stations between
``r_min`` and ``r_max`` from the source, on both sides. An envelope peak moves
at the group velocity at the signal's dominant frequency, here the centroid of
its power spectrum; :func:`compare_with_relation` takes the relation's group
velocity at the wavenumber where ``omega(k)`` equals it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import hilbert

from peridyn.analysis.dispersion import DispersionRelation
from peridyn.errors import InputError
from peridyn.io.results import Results

__all__ = [
    "FrontSpeed",
    "axis_signals",
    "compare_with_relation",
    "envelope_peak_times",
    "front_speed",
    "measure_fronts",
    "predicted_group_velocity",
]


@dataclass(frozen=True)
class FrontSpeed:
    """Speed of a wave front along one axis.

    Attributes
    ----------
    axis : str
    speed : float, m/s
        Inverse slope of the arrival times against distance.
    frequency : float, Hz
        Dominant frequency: centroid of the power spectrum of the stations used.
    distances : (n,) float64, m
        Distances of the stations used from the source.
    arrival_times : (n,) float64, s
        Envelope-peak times at those stations.
    residual : float, s
        Root-mean-square deviation of the arrival times from the fitted line.
    """

    axis: str
    speed: float
    frequency: float
    distances: np.ndarray
    arrival_times: np.ndarray
    residual: float


def envelope_peak_times(times: np.ndarray, signals: np.ndarray) -> np.ndarray:
    """Time of the peak of the Hilbert envelope of each signal.

    Parameters
    ----------
    times : (n_t,) float64, s
        Evenly spaced.
    signals : (n_t, n_stations) float64

    Returns
    -------
    (n_stations,) float64, s
    """
    envelope = np.abs(hilbert(signals, axis=0))
    i = np.clip(np.argmax(envelope, axis=0), 1, len(times) - 2)
    cols = np.arange(signals.shape[1])
    y0, y1, y2 = envelope[i - 1, cols], envelope[i, cols], envelope[i + 1, cols]
    curvature = y0 - 2.0 * y1 + y2
    shift = np.where(curvature < 0, 0.5 * (y0 - y2) / np.where(curvature < 0, curvature, 1.0), 0.0)
    return times[i] + shift * (times[1] - times[0])


def dominant_frequency(times: np.ndarray, signals: np.ndarray) -> float:
    """Centroid (Hz) of the summed power spectra of the signals (n_t, n_stations)."""
    n = 8 * len(times)
    power = np.sum(np.abs(np.fft.rfft(signals, n, axis=0)) ** 2, axis=1)
    freq = np.fft.rfftfreq(n, times[1] - times[0])
    return float(np.sum(freq * power) / np.sum(power))


def front_speed(
    times: np.ndarray, distances: np.ndarray, signals: np.ndarray, axis: str, r_min: float, r_max: float
) -> FrontSpeed:
    """Front speed from the signals of the stations along one axis.

    Parameters
    ----------
    times : (n_t,) float64, s
    distances : (n_stations,) float64, m
        Distance of each station from the source.
    signals : (n_t, n_stations) float64
    axis : str
        Name reported in the result.
    r_min, r_max : float, m
        Stations between these distances are used (at least 3).
    """
    used = (distances >= r_min) & (distances <= r_max)
    if used.sum() < 3:
        raise InputError(
            f"axis {axis!r}: {int(used.sum())} stations between {r_min:g} and "
            f"{r_max:g} m from the source; need at least 3"
        )
    arrival = envelope_peak_times(times, signals[:, used])
    slope, intercept = np.polyfit(distances[used], arrival, 1)
    residual = float(np.sqrt(np.mean((arrival - (slope * distances[used] + intercept)) ** 2)))
    return FrontSpeed(
        axis,
        float(1.0 / slope),
        dominant_frequency(times, signals[:, used]),
        distances[used],
        arrival,
        residual,
    )


def axis_signals(results, axis: str, centre=(0.0, 0.0, 0.0), pulse: str = "x"):
    """Dilatation (``axis == pulse``) or rotation (otherwise) on an axis, from its tube probe.

    Parameters
    ----------
    results : path
        ``results.h5`` with the plane series ``plane_tube_<axis>`` (a 3 x 3-point tube
        of lattice points around the axis through ``centre``).
    axis, pulse : {"x", "y", "z"}
    centre : 3 floats, m

    Returns
    -------
    times : (n_t,) float64, s
    distances : (n_stations,) float64, m
    signals : (n_t, n_stations) float64, 1/1 (strain)
    """
    stored = Results(results)
    index = stored.array(f"probes/plane_tube_{axis}")
    points = stored.array("geometry/points")[index] - np.asarray(centre, dtype=float)
    _, times, data = stored.series(f"plane_tube_{axis}")
    a, p = "xyz".index(axis), "xyz".index(pulse)
    along = np.unique(np.round(points[:, a], 12))
    h = float(np.min(np.diff(along)))
    lattice = np.rint(points / h).astype(int)
    column = {tuple(ijk): c for c, ijk in enumerate(lattice)}

    def derivative(station: int, direction: int, component: int) -> np.ndarray:
        """du_component / dx_direction at a station, central difference."""
        ends = []
        for step in (1, -1):
            ijk = [0, 0, 0]
            ijk[a] += station
            ijk[direction] += step
            if tuple(ijk) not in column:
                raise InputError(
                    f"{results}: tube_{axis} lacks the point {ijk} (spacing {h:g} m) around the {axis} axis"
                )
            ends.append(data[:, column[tuple(ijk)], component].astype(np.float64))
        return (ends[0] - ends[1]) / (2.0 * h)

    stations = np.unique(lattice[:, a])[1:-1]
    if axis == pulse:
        columns = [sum(derivative(s, c, c) for c in range(3)) for s in stations]
    else:
        columns = [derivative(s, a, p) - derivative(s, p, a) for s in stations]
    return times, np.abs(stations) * h, np.stack(columns, axis=1)


def measure_fronts(results, r_min: float, r_max: float, centre=(0.0, 0.0, 0.0), pulse: str = "x") -> dict:
    """P front along the pulse axis and S fronts along the other two.

    Parameters
    ----------
    results : path
        A run's ``results.h5`` with the tube probes ``tube_x``, ``tube_y`` and ``tube_z``.
    r_min, r_max : float, m
        Distances from the source used in the fits.
    centre : 3 floats, m
        The source.
    pulse : {"x", "y", "z"}
        The direction of the pulse.

    Returns
    -------
    dict of axis to FrontSpeed
    """
    return {
        axis: front_speed(*axis_signals(results, axis, centre, pulse), axis, r_min, r_max) for axis in "xyz"
    }


def predicted_group_velocity(relation: DispersionRelation, frequency: float) -> dict:
    """Wavenumber and group velocity of each branch where omega = 2 pi ``frequency``.

    The wavenumber is the first crossing of the sampled omega(k) (linear
    interpolation between samples, omega(0) = 0); the group velocity is
    interpolated there, so sample the relation densely.

    Returns
    -------
    dict of str to (wavenumber rad/m, group velocity m/s)
    """
    omega = 2.0 * np.pi * frequency
    out = {}
    for name, branch in relation.branches.items():
        above = np.flatnonzero(branch.frequency >= omega)
        if not len(above):
            raise InputError(
                f"{frequency:g} Hz is above the {name} branch's highest frequency "
                f"{branch.frequency.max() / (2 * np.pi):g} Hz on this grid"
            )
        k_pair = np.concatenate([[0.0], branch.wavenumber])[above[0] : above[0] + 2]
        w_pair = np.concatenate([[0.0], branch.frequency])[above[0] : above[0] + 2]
        k = float(np.interp(omega, w_pair, k_pair))
        out[name] = (k, float(np.interp(k, branch.wavenumber, branch.group_velocity)))
    return out


def compare_with_relation(fronts: dict, relation: DispersionRelation, pulse: str = "x") -> dict:
    """Measured front speeds against the relation's group velocities.

    Parameters
    ----------
    fronts : dict of axis to FrontSpeed
        From :func:`measure_fronts`.
    relation : DispersionRelation
        The discrete relation of the run's grid along the pulse axis (by cubic
        symmetry its shear branches are the S waves along the other axes).
    pulse : {"x", "y", "z"}

    Returns
    -------
    dict of axis to dict with ``speed_m_s``, ``frequency_hz``, ``wavenumber_rad_m``,
    ``group_velocity_m_s`` and ``error`` (speed / group velocity - 1)
    """
    shear = iter(("shear_1", "shear_2"))
    branch_of = {axis: "longitudinal" if axis == pulse else next(shear) for axis in "xyz"}
    rows = {}
    for axis, front in fronts.items():
        k, group = predicted_group_velocity(relation, front.frequency)[branch_of[axis]]
        rows[axis] = {
            "speed_m_s": front.speed,
            "frequency_hz": front.frequency,
            "wavenumber_rad_m": k,
            "group_velocity_m_s": group,
            "error": front.speed / group - 1.0,
        }
    return rows
