"""What a case's ``analysis:`` section asks for after the run: f-k peaks, (kx, ky) rings, plots.

The theory (Rayleigh-Lamb) uses the case's material and plate thickness; a
bond-based material is compared with the Poisson ratio it implies (1/4 in 3D,
``Model.implied_poisson_ratio``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from peridyn.analysis.fk import kxky_from_hdf5, line_fk, pick_wavenumbers, point_grid, ring_radius
from peridyn.analysis.lamb import dispersion_curves, lamb_modes
from peridyn.discretization.body import Body
from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import Case
from peridyn.io.results import Results

#: Modes whose wavenumber is picked by default.
FUNDAMENTAL_MODES = ("S0", "A0")
#: Frequencies of the Rayleigh-Lamb curves drawn on an f-k map (one every 1% of its height:
#: a point every few pixels; each costs a root search per mode family).
FK_THEORY_POINTS = 100


def plate_theory(case: Case) -> tuple[float, float, float, float]:
    """(E, nu, rho, thickness) of the case's plate for Rayleigh-Lamb theory."""
    if case.geometry.type != "plate":
        raise CaseFileError(case.name, "analysis", None, "a plate geometry for Lamb-wave analysis")
    mat = case.material
    implied = case.material_class().implied_poisson_ratio(3)
    nu = mat.nu if implied is None else implied
    return mat.E, nu, mat.density, case.geometry.size[2]


def centre_frequency(case: Case) -> float:
    """The f-k analysis frequency: given, or the first actuator signal's ``frequency`` (Hz)."""
    fk = case.analysis.fk
    if fk.frequency is not None:
        return fk.frequency
    for name, actuator in case.actuators.items():
        if "frequency" in actuator.signal:
            return float(actuator.signal["frequency"])
        raise CaseFileError(
            case.name,
            f"actuators.{name}.signal",
            actuator.signal,
            "a signal with a frequency, or analysis.fk.frequency",
        )
    raise CaseFileError(case.name, "analysis.fk.frequency", None, "a frequency (Hz)")


def analyse(case: Case, body: Body, results: Results, plots: bool = True) -> tuple[dict, list]:
    """Run the case's analyses on a run's ``results``, their figures in the results' folder.

    Returns
    -------
    summary : dict
        Entries for the run summary (``fk_peaks_rad_m``, ``kxky_rings_rad_m``, ...). An
        analysis the records cannot support (e.g. a run too short for the frequency) is
        reported under ``analysis_warnings`` (and on stderr) instead of failing a finished run.
    figures : list of Path
        The plots written.
    """
    summary, figures = {}, []
    if case.analysis is None:
        return summary, figures
    directory = Path(results.path).parent
    for name, wanted, step in (("fk", case.analysis.fk, _fk), ("kxky", case.analysis.kxky, _kxky)):
        if wanted is None:
            continue
        try:
            entries, paths = step(case, body, results, directory, plots)
        except InputError as exc:
            message = f"analysis.{name} skipped: {exc}"
            print(f"peridyn: warning: {message}", file=sys.stderr)
            summary.setdefault("analysis_warnings", []).append(message)
            continue
        summary.update(entries)
        figures += paths
    return summary, figures


def _fk(case: Case, body: Body, results: Results, directory, plots: bool) -> tuple[dict, list]:
    fk = case.analysis.fk
    f0 = centre_frequency(case)
    E, nu, rho, thickness = plate_theory(case)
    theory = {m.mode: m.wavenumber_rad_m for m in lamb_modes(E, nu, rho, thickness, [f0])}
    line = case.output.lines[fk.line]
    spacing = float(np.linalg.norm(np.subtract(line.end, line.start))) / (line.points - 1)
    peaks = {}
    maps = {}
    for mode, component in fk.components.items():
        if mode not in theory:
            raise CaseFileError(
                case.name,
                f"analysis.fk.components.{mode}",
                component,
                f"a mode that exists at {f0:g} Hz: {sorted(theory)}",
            )
        freq, k, mag = line_fk(
            results,
            f"line_{fk.line}",
            spacing,
            component,
            window=None if fk.window == "none" else fk.window,
            pad_time=fk.pad,
            pad_space=fk.pad,
            f_max=3 * f0,
        )
        maps[component] = (freq, k, mag)
        found = pick_wavenumbers(freq, k, mag, f0, {mode: theory[mode]}, tolerance=fk.tolerance)
        peaks[mode] = None if np.isnan(found[mode]) else float(found[mode])
    out = {
        "fk_frequency_hz": f0,
        "fk_peaks_rad_m": peaks,
        "fk_theory_rad_m": {m: theory[m] for m in peaks},
        "fk_error": {m: (None if peaks[m] is None else peaks[m] / theory[m] - 1) for m in peaks},
    }
    figures = []
    if plots:
        from peridyn.plotting.lamb_wavefield import plot_fk_map

        curves = dispersion_curves(E, nu, rho, thickness, f_max=2 * f0, n=FK_THEORY_POINTS, max_order=1)
        for component, (freq, k, mag) in maps.items():
            marks = {
                m: (f0, peaks[m]) for m, c in fk.components.items() if c == component and peaks[m] is not None
            }
            path = Path(directory) / f"fk_{fk.line}_u{component}.png"
            figures.append(plot_fk_map(freq, k, mag, path, theory=curves, peaks=marks, f_max=2 * f0))
    return out, figures


def _kxky(case: Case, body: Body, results: Results, directory, plots: bool) -> tuple[dict, list]:
    spec = case.analysis.kxky
    E, nu, rho, thickness = plate_theory(case)
    set_name = case.output.planes[spec.plane]
    grid = point_grid(body.points[body.node_set(set_name)])
    kx, ky, maps = kxky_from_hdf5(results, f"plane_{spec.plane}", grid, spec.frequencies, spec.component)
    modes = lamb_modes(E, nu, rho, thickness, spec.frequencies, max_order=0)
    rings = {}
    for f, kmap in zip(spec.frequencies, maps, strict=True):
        guess = {
            m.mode: m.wavenumber_rad_m for m in modes if m.frequency_hz == f and m.mode in FUNDAMENTAL_MODES
        }
        found = ring_radius(kx, ky, kmap, guess)
        rings[f"{f:g}"] = {m: (None if np.isnan(v) else float(v)) for m, v in found.items()}
    out = {"kxky_rings_rad_m": rings, "kxky_theory_rad_m": {f"{m.frequency_hz:g}": {} for m in modes}}
    for m in modes:
        if m.mode in FUNDAMENTAL_MODES:
            out["kxky_theory_rad_m"][f"{m.frequency_hz:g}"][m.mode] = m.wavenumber_rad_m
    figures = []
    if plots:
        from peridyn.plotting.lamb_wavefield import plot_kxky_maps

        path = Path(directory) / f"kxky_{spec.plane}.png"
        figures.append(plot_kxky_maps(kx, ky, maps, spec.frequencies, path, theory=modes))
    return out, figures
