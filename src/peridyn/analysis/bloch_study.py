"""Bloch predictions for a case and a sweep of plate discretisations, against theory.

Theory: Rayleigh-Lamb (``analysis.lamb``) for the S0 and A0 plate modes, ``omega / cT``
for SH0 (non-dispersive) and ``omega / cL``, ``omega / cT`` for the bulk P and S waves
of a block, with the case's E, nu and density.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import replace

import numpy as np

from peridyn.analysis.bloch import (
    BlochCell,
    BlochLattice,
    bloch_cell,
    block_wavenumbers,
    plate_wavenumbers,
)
from peridyn.analysis.lamb import bulk_speeds, lamb_modes
from peridyn.errors import InputError


def theory_wavenumbers(disc: BlochLattice, frequencies) -> dict[tuple[str, float], float]:
    """{(mode, frequency_hz): k (rad/m)} of the continuum for the modes Bloch reports."""
    nu = 0.25 if disc.nu is None else disc.nu
    cl, ct = bulk_speeds(disc.E, nu, disc.density)
    out = {}
    freqs = [float(f) for f in np.atleast_1d(frequencies)]
    if disc.kind == "plate":
        for m in lamb_modes(disc.E, nu, disc.density, disc.thickness, freqs, max_order=0):
            out[(m.mode, m.frequency_hz)] = m.wavenumber_rad_m
        for f in freqs:
            out[("SH0", f)] = 2 * np.pi * f / ct
    else:
        for f in freqs:
            out[("P", f)] = 2 * np.pi * f / cl
            out[("S", f)] = 2 * np.pi * f / ct
    return out


def predict(disc: BlochLattice, frequencies, cell: BlochCell | None = None) -> list[dict]:
    """Discrete and theoretical wavenumbers of each mode at each frequency (Hz).

    Returns dicts with mode, frequency_hz, wavenumber_rad_m, theory_wavenumber_rad_m and
    error = k / k0 - 1 (None where the discrete branch stays below the frequency).
    """
    freqs = _check_frequencies(frequencies)
    cell = bloch_cell(disc) if cell is None else cell
    modes = plate_wavenumbers(cell, freqs) if disc.kind == "plate" else block_wavenumbers(cell, freqs)
    theory = theory_wavenumbers(disc, freqs)
    for m in modes:
        k0 = theory.get((m["mode"], m["frequency_hz"]))
        k = m["wavenumber_rad_m"]
        m["theory_wavenumber_rad_m"] = k0
        m["error"] = None if k is None or k0 is None else k / k0 - 1.0
    return modes


def _check_frequencies(frequencies) -> np.ndarray:
    freqs = np.atleast_1d(np.asarray(frequencies, dtype=np.float64))
    if freqs.size == 0 or not np.all(np.isfinite(freqs)) or np.any(freqs <= 0):
        raise InputError(f"frequencies must be positive numbers (Hz), got {np.asarray(frequencies)}")
    return freqs


#: Default sweep of the study: layers, spacing (m), horizon (multiple of dx), correction.
STUDY_LAYERS = (3, 4, 5, 6, 7)
STUDY_SPACINGS = (1.2e-3, 0.8e-3, 0.6e-3, 0.4e-3, 0.3e-3)
STUDY_HORIZONS = (1.5, 3.015)
STUDY_CORRECTIONS = ("none", "shear-factor")


def study(
    base: BlochLattice,
    frequencies,
    layers=STUDY_LAYERS,
    spacings=STUDY_SPACINGS,
    horizons=STUDY_HORIZONS,
    corrections=STUDY_CORRECTIONS,
) -> list[dict]:
    """Errors and cost of every plate discretisation of the sweep (cartesian product).

    Layers are cell-centred (``layer_placement`` "cell", dz = thickness / layers); the
    rest (material, influence, partial volumes) comes from ``base``. Each row holds the
    discretisation, ``max_abs_error`` over S0 and A0 at the frequencies, the errors per
    mode and frequency, points per square metre of plate, bonds per point, the
    solver's stable step (s) and the seconds the row took.
    """
    if base.kind != "plate":
        raise InputError("the study sweeps plate discretisations: give a plate case")
    freqs = _check_frequencies(frequencies)
    rows = []
    for n_layers, dx, horizon, correction in itertools.product(layers, spacings, horizons, corrections):
        start = time.perf_counter()
        disc = replace(
            base,
            layers=int(n_layers),
            spacing=float(dx),
            horizon=float(horizon) * dx,
            surface_correction=correction,
            layer_placement="cell",
        )
        cell = bloch_cell(disc)
        modes = [m for m in predict(disc, freqs, cell) if m["mode"] in ("S0", "A0")]
        errors = [abs(m["error"]) if m["error"] is not None else np.inf for m in modes]
        rows.append(
            {
                "layers": int(n_layers),
                "spacing_m": float(dx),
                "horizon_dx": float(horizon),
                "surface_correction": correction,
                "max_abs_error": float(max(errors)),
                "errors": {f"{m['mode']}@{m['frequency_hz'] / 1e3:g}kHz": m["error"] for m in modes},
                "points_per_m2": n_layers / dx**2,
                "bonds_per_point": cell.bonds_per_point,
                "stable_step_s": cell.critical_time_step,
                "seconds": time.perf_counter() - start,
            }
        )
    return rows


def format_study(rows: list[dict]) -> str:
    """The study as a Markdown table, best first.

    Work is the bond updates per cm^2 of plate per microsecond simulated at the stable step
    (points per area x bonds per point / step): what a run of the discretisation costs.
    """
    lines = [
        "| layers | dx (mm) | horizon (dx) | correction | worst S0 (%) | worst A0 (%) | "
        "points per cm^2 | bonds per point | stable step (ns) | work (M bond updates "
        "per cm^2 per us) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in sorted(rows, key=lambda r: r["max_abs_error"]):
        worst = {
            mode: max(
                (e for key, e in r["errors"].items() if key.startswith(mode)),
                key=lambda e: np.inf if e is None else abs(e),
            )
            for mode in ("S0", "A0")
        }
        text = {mode: "-" if e is None else f"{100 * e:+.2f}" for mode, e in worst.items()}
        work = r["points_per_m2"] * 1e-4 * r["bonds_per_point"] / (r["stable_step_s"] * 1e6)
        lines.append(
            f"| {r['layers']} | {r['spacing_m'] * 1e3:g} | {r['horizon_dx']:g} | "
            f"{r['surface_correction']} | {text['S0']} | {text['A0']} | "
            f"{r['points_per_m2'] * 1e-4:.0f} | {r['bonds_per_point']:.1f} | "
            f"{r['stable_step_s'] * 1e9:.1f} | {work / 1e6:.2f} |"
        )
    return "\n".join(lines)
