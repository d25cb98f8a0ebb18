"""How a run's S0 and A0 wavenumbers compare with the Bloch prediction, and how much of the
difference is the estimator and how much time integration, for a Lamb case.

Two estimators are measured (``peridyn.analysis.fk``): the f-k pick (``fk_transform`` +
``pick_wavenumbers``, Hann windows, the case's padding) and the phase fit
(``phase_wavenumber``: the slope of the phase along the line of the record's Fourier transform
at the centre frequency, with the Hankel near-field term removed, over ``--r-range``).

*Estimator bias.* A synthetic line record is built from the Bloch branches of the case's
discrete plate: each mode leaves the actuator as the case's tone burst with the exact discrete
dispersion k(f) as a cylindrical wave, u(r, f) = S(f) H_n(k(f) r) (Hankel function, outgoing;
n = 1 for S0's u_x, 0 for S0's in-plane divergence and A0's u_z), sampled on the case's line
probe at the run's record times, optionally with (even image) free-edge reflections. Each
estimator's pick on it, against the Bloch wavenumber, is its bias: finite line and time window,
bins and peak refinement, with no time integration and no other wave.

*Time integration.* Velocity Verlet advances a mode of frequency f as if its frequency were
f_s = sin(pi f dt) / (pi dt); the run's wavenumber is the Bloch one at f_s, so its share is
k_Bloch(f_s) / k_Bloch(f) - 1 (about -(c_p / c_g) (2 pi f dt)^2 / 24).

*Run* (with RUN_DIR, a finished run of the case): the f-k pick of the run (its summary's
``fk_peaks_rad_m``) and the phase fit of its six line probes (``line_mode_wavenumbers``: S0
from the in-plane divergence of the symmetric part, A0 from u_z of the antisymmetric part).

    PYTHONPATH=src python benchmarks/bloch_vs_fk.py cases/lamb_plate_absorbing.yaml [RUN_DIR] \
        --r-range 0.02,0.09 [--edges]
"""

from __future__ import annotations

import argparse
import json

import numpy as np
from scipy.special import hankel1

from peridyn.analysis.bloch import BlochLattice, bloch_cell, plate_basis, zone_edge
from peridyn.analysis.bloch_study import predict
from peridyn.analysis.fk import fk_transform, line_mode_wavenumbers, phase_wavenumber, pick_wavenumbers
from peridyn.analysis.lamb import lamb_modes
from peridyn.io.case import load_case
from peridyn.io.results import Results
from peridyn.jobs.lamb_analysis import centre_frequency
from peridyn.physics.timefunctions import from_spec

#: Per mode: Bloch family, Hankel order of the f-k pick's record (u_x, u_z) and of the phase
#: fit's record (divergence, u_z).
MODES = {"S0": ("S", 1, 0), "A0": ("A", 0, 0)}


def branch_wavenumber_of(cell, basis, frequencies: np.ndarray) -> np.ndarray:
    """k(f) (rad/m) of the lowest branch of ``basis`` by interpolation of omega(k)."""
    k = np.linspace(0.0, zone_edge(cell), 2000)
    f = np.array([cell.frequencies((kk, 0.0, 0.0), basis)[0] for kk in k]) / (2 * np.pi)
    rising = np.concatenate([[True], np.diff(f) > 0])
    top = np.argmin(rising) if not rising.all() else len(k)
    return np.interp(frequencies, f[:top], k[:top], right=np.nan)


def synthetic_record(signal, times, x, x_source, k_of_f, order: int, edges=None) -> np.ndarray:
    """(n_t, n_x) record of a burst ``signal`` leaving ``x_source`` as a cylindrical wave
    ``H_order(k(f) r)`` (outgoing), with dispersion k(f).

    ``edges`` (x_min, x_max), m: add the reflections from free plate edges there as image
    sources (even images, one and two reflections; no mode conversion).
    """
    dt = times[1] - times[0]
    n = 4 * len(times)
    spectrum = np.fft.rfft(signal(np.arange(n) * dt))
    f = np.fft.rfftfreq(n, dt)
    k = k_of_f(f)
    spectrum[np.isnan(k) | (f == 0)] = 0.0
    k = np.where(spectrum != 0, np.nan_to_num(k), 1.0)
    sources = [x_source]
    if edges is not None:
        a, b = edges
        sources += [2 * a - x_source, 2 * b - x_source, x_source + 2 * (b - a), x_source - 2 * (b - a)]
    field = 0.0
    for xs in sources:
        r = np.maximum(np.abs(x - xs), 0.5 * np.min(np.diff(x)))
        # numpy's irfft sums exp(+i omega t): the outgoing wave is exp(-i k r) ~ conj(H^(1))
        waves = np.conj(hankel1(order, k[:, None] * r[None, :]))
        field = field + np.fft.irfft(spectrum[:, None] * waves, n=n, axis=0)[: len(times)]
    return field


def time_integration_shares(disc, cell, f0: float, dt: float) -> dict[str, float]:
    """k_Bloch(f_s) / k_Bloch(f0) - 1 per mode, f_s = sin(pi f0 dt) / (pi dt)."""
    f_s = np.sin(np.pi * f0 * dt) / (np.pi * dt)
    at = {f: {m["mode"]: m["wavenumber_rad_m"] for m in predict(disc, [f], cell)} for f in (f0, f_s)}
    return {mode: at[f_s][mode] / at[f0][mode] - 1 for mode in MODES}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case")
    parser.add_argument("run_dir", nargs="?")
    parser.add_argument("--records", type=int, default=1500)
    parser.add_argument(
        "--r-range", default="0.02,0.09", help="distances from the source (m) of the phase fit, 'r_min,r_max'"
    )
    parser.add_argument("--edges", action="store_true", help="add the plate-edge reflections")
    args = parser.parse_args()
    r_range = tuple(float(v) for v in args.r_range.split(","))
    case = load_case(args.case)
    disc = BlochLattice.from_case(case)
    cell = bloch_cell(disc)
    f0 = centre_frequency(case)
    fk = case.analysis.fk
    line = case.output.lines[fk.line]
    x = np.linspace(line.start[0], line.end[0], line.points)
    if args.run_dir:
        _, times, _ = Results(f"{args.run_dir}/results.h5").series(f"line_{fk.line}")
    else:
        times = np.linspace(0.0, case.solver.time, args.records + 1)
    actuator = next(iter(case.actuators.values()))
    signal = from_spec(actuator.signal, "actuator signal")
    theory = {
        m.mode: m.wavenumber_rad_m
        for m in lamb_modes(disc.E, disc.nu, disc.density, disc.thickness, [f0], max_order=0)
    }
    bloch = {m["mode"]: m["wavenumber_rad_m"] for m in predict(disc, [f0], cell)}
    edges = None
    if args.edges:
        origin = case.geometry.origin or (0.0, 0.0, 0.0)
        edges = (origin[0], origin[0] + case.geometry.size[0])
    out = {}
    for mode, (family, fk_order, phase_order) in MODES.items():
        basis = plate_basis(cell, family)

        def record(order, b=basis):
            return synthetic_record(
                signal, times, x, actuator.center[0], lambda f: branch_wavenumber_of(cell, b, f), order, edges
            )

        freq, k, mag = fk_transform(
            record(fk_order),
            times[1] - times[0],
            x[1] - x[0],
            window="hann",
            pad_time=fk.pad,
            pad_space=fk.pad,
            f_max=3 * f0,
        )
        picked = pick_wavenumbers(freq, k, mag, f0, {mode: theory[mode]}, tolerance=fk.tolerance)[mode]
        fitted = phase_wavenumber(
            record(phase_order), times[1] - times[0], x, f0, actuator.center[0], r_range, phase_order
        )
        out[mode] = {
            "bloch_rad_m": bloch[mode],
            "fk_pick_bias": float(picked) / bloch[mode] - 1,
            "phase_fit_bias": fitted / bloch[mode] - 1,
            "bloch_error_vs_rayleigh_lamb": bloch[mode] / theory[mode] - 1,
            "k_bin_rad_m": float(2 * np.pi / (line.points * (x[1] - x[0]))),
        }
    result = {"case": case.name, "frequency_hz": f0, "r_range_m": r_range, "modes": out}
    if args.run_dir:
        results = f"{args.run_dir}/results.h5"
        summary = Results(results).summary()
        run = line_mode_wavenumbers(results, fk.line, x, disc.spacing, f0, actuator.center[0], r_range)
        shares = time_integration_shares(disc, cell, f0, summary["dt_s"])
        result["omega_dt"] = 2 * np.pi * f0 * summary["dt_s"]
        for mode in MODES:
            out[mode].update(
                {
                    "run_phase_fit_rad_m": run[mode],
                    "run_phase_fit_error": run[mode] / bloch[mode] - 1,
                    "run_fk_pick_rad_m": summary["fk_peaks_rad_m"][mode],
                    "run_fk_pick_error": summary["fk_peaks_rad_m"][mode] / bloch[mode] - 1,
                    "time_integration_share": shares[mode],
                }
            )
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
