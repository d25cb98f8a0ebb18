"""How much of a run's f-k wavenumber error is the f-k pick itself, for a Lamb case.

A synthetic line record is built from the Bloch branches of the case's discrete plate:
each mode (S0 from u_x, A0 from u_z) leaves the actuator as the case's tone burst with
the exact discrete dispersion k(f), u(r, f) = S(f) exp(-i k(f) r) / sqrt(r) (cylindrical
spreading), sampled on the case's line probe at the run's record times. The same
analysis the run uses (``fk_transform`` + ``pick_wavenumbers``, Hann windows, padding 2)
picks a wavenumber from it; its difference from the Bloch wavenumber is the bias of the
f-k pick (finite line and time window, peak refinement), with no time integration.

Run from the repository root (RUN_DIR: a finished run of the case, for its record times;
without it the times are the case's end time split into ``--records`` steps):

    PYTHONPATH=src python benchmarks/bloch_vs_fk.py cases/lamb_plate.yaml [RUN_DIR]
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from peridyn.analysis.bloch import Discretisation, bloch_cell, plate_basis, zone_edge
from peridyn.analysis.bloch_study import predict
from peridyn.analysis.fk import fk_transform, pick_wavenumbers
from peridyn.analysis.lamb import lamb_modes
from peridyn.io.case import load_case
from peridyn.io.hdf5 import read_series
from peridyn.postprocess import centre_frequency
from peridyn.timefunctions import from_spec


def branch_wavenumber_of(cell, basis, frequencies: np.ndarray) -> np.ndarray:
    """k(f) (rad/m) of the lowest branch of ``basis`` by interpolation of omega(k)."""
    k = np.linspace(0.0, zone_edge(cell), 2000)
    f = np.array([cell.frequencies((kk, 0.0, 0.0), basis)[0] for kk in k]) / (2 * np.pi)
    rising = np.concatenate([[True], np.diff(f) > 0])
    top = np.argmin(rising) if not rising.all() else len(k)
    return np.interp(frequencies, f[:top], k[:top], right=np.nan)


def synthetic_record(signal, times, x, x_source, k_of_f, edges=None) -> np.ndarray:
    """(n_t, n_x) record of a burst ``signal`` leaving ``x_source`` with dispersion k(f).

    ``edges`` (x_min, x_max), m: add the reflections from free plate edges there as image
    sources (even images, one and two reflections; no mode conversion).
    """
    dt = times[1] - times[0]
    n = 4 * len(times)
    spectrum = np.fft.rfft(signal(np.arange(n) * dt))
    f = np.fft.rfftfreq(n, dt)
    k = k_of_f(f)
    spectrum[np.isnan(k)] = 0.0
    k = np.nan_to_num(k)
    sources = [x_source]
    if edges is not None:
        a, b = edges
        sources += [2 * a - x_source, 2 * b - x_source, x_source + 2 * (b - a),
                    x_source - 2 * (b - a)]
    field = 0.0
    for xs in sources:
        r = np.maximum(np.abs(x - xs), 0.5 * np.min(np.diff(x)))
        field = field + np.fft.irfft(spectrum[:, None] * np.exp(-1j * k[:, None] * r[None, :]),
                                     n=n, axis=0)[: len(times)] / np.sqrt(r)[None, :]
    return field


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case")
    parser.add_argument("run_dir", nargs="?")
    parser.add_argument("--records", type=int, default=1500)
    parser.add_argument("--edges", action="store_true", help="add the plate-edge reflections")
    args = parser.parse_args()
    case = load_case(args.case)
    disc = Discretisation.from_case(case)
    cell = bloch_cell(disc)
    f0 = centre_frequency(case)
    line = case.output.lines[case.analysis.fk.line]
    x = np.linspace(line.start[0], line.end[0], line.points)
    if args.run_dir:
        _, times, _ = read_series(f"{args.run_dir}/results.h5", f"line_{case.analysis.fk.line}")
    else:
        times = np.linspace(0.0, case.solver.time, args.records + 1)
    actuator = next(iter(case.actuators.values()))
    signal = from_spec(actuator.signal, "actuator signal")
    theory = {m.mode: m.wavenumber_rad_m for m in lamb_modes(disc.E, disc.nu, disc.density,
                                                             disc.thickness, [f0], max_order=0)}
    bloch = {m["mode"]: m["wavenumber_rad_m"] for m in predict(disc, [f0], cell)}
    out = {}
    for mode, family in (("S0", "S"), ("A0", "A")):
        basis = plate_basis(cell, family)
        edges = None
        if args.edges:
            origin = case.geometry.origin or (0.0, 0.0, 0.0)
            edges = (origin[0], origin[0] + case.geometry.size[0])
        record = synthetic_record(signal, times, x, actuator.center[0],
                                  lambda f, b=basis: branch_wavenumber_of(cell, b, f), edges)
        freq, k, mag = fk_transform(record, times[1] - times[0], x[1] - x[0], window="hann",
                                    pad_time=case.analysis.fk.pad, pad_space=case.analysis.fk.pad,
                                    f_max=3 * f0)
        picked = pick_wavenumbers(freq, k, mag, f0, {mode: theory[mode]},
                                  tolerance=case.analysis.fk.tolerance)[mode]
        out[mode] = {"bloch_rad_m": bloch[mode], "fk_of_bloch_record_rad_m": float(picked),
                     "fk_bias": float(picked) / bloch[mode] - 1,
                     "bloch_error_vs_rayleigh_lamb": bloch[mode] / theory[mode] - 1,
                     "k_bin_rad_m": float(2 * np.pi / (line.points * (x[1] - x[0])))}
    print(json.dumps({"case": case.name, "frequency_hz": f0, "modes": out}, indent=1))


if __name__ == "__main__":
    main()
