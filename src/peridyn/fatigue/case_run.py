"""A fatigue case: build, optional modal analysis, fatigue loop, modal analysis of the damaged body.

Outputs in the run folder: ``crack_length.csv`` (cycles, crack length, bonds broken),
``crack_length.png``, ``damage.vtu`` (final damage and first-break cycle), ``modal.json``
(frequency tables before/after, MAC matrix, matched types) when ``modal_after`` is set,
and ``fatigue.json`` (the summary).
"""

from __future__ import annotations

import csv
import json
import resource
import time
from pathlib import Path

import numpy as np

from peridyn.errors import CaseFileError, did_you_mean
from peridyn.fatigue.calibration import growth_rates, paris_fit, stress_intensity
from peridyn.fatigue.mapping import CycleMapping
from peridyn.fatigue.model import FatigueParameters, scale_A_II
from peridyn.fatigue.run import FatigueResult, run_fatigue
from peridyn.io.case import Case
from peridyn.io.vtk import write_vtu
from peridyn.modal_run import match_modes, modal_table
from peridyn.simulation import build, output_directory


def check_fatigue_case(case: Case) -> None:
    """Case-level checks of a fatigue case (the ``fatigue`` block's own values are checked on load)."""
    if case.fatigue is None:
        raise CaseFileError(case.name, "fatigue", None, "a fatigue block (parameters, mapping)")
    if not case.boundary_conditions:
        raise CaseFileError(case.name, "boundary_conditions", [],
                            "a cyclic load: boundary conditions giving the maximum load")
    known = set(case.node_sets) | {"all"}
    for name in case.fatigue.no_damage_sets:
        if name not in known:
            raise CaseFileError(case.name, "fatigue.no_damage_sets", name,
                                f"a defined node set{did_you_mean(name, known)}: {sorted(known)}")


def fatigue_parameters(case: Case, horizon: float) -> FatigueParameters:
    """The case's parameters with A_II moved to ``horizon`` (m) by eq. 7.15 when its own is given."""
    f = case.fatigue
    a2 = f.A_II if f.A_II_horizon is None else scale_A_II(f.A_II, f.A_II_horizon, horizon, f.m_II)
    return FatigueParameters(A_I=f.A_I, m_I=f.m_I, eps_inf=f.eps_inf, A_II=a2, m_II=f.m_II,
                             phi_c=f.phi_c)


def paris_slope(case: Case, result: FatigueResult) -> float | None:
    """Slope of log(da/dN) against log(dK) of the run (eqs. 7.12-7.14), or None without ``paris``."""
    p = case.fatigue.paris
    if p is None:
        return None
    a_mid, rate = growth_rates(result.cycles, result.crack_length)
    if rate.size < 2:
        return None
    dk = (1.0 - case.fatigue.load_ratio) * stress_intensity(p.stress, a_mid, p.width)
    return paris_fit(dk, rate)[0]


def run_fatigue_case(case: Case, output_dir=None, base_dir=".", modal: bool | None = None,
                     progress=None) -> dict:
    """Run a fatigue case; returns the summary (JSON keys of ``peridyn fatigue --json``)."""
    start = time.perf_counter()
    check_fatigue_case(case)
    f = case.fatigue
    setup = build(case, base_dir)
    out = output_directory(case, output_dir)
    out.mkdir(parents=True, exist_ok=True)
    n_modes = f.modal_after.modes if f.modal_after is not None else 12
    do_modal = f.modal_after is not None if modal is None else modal
    before = setup_rows = None
    if do_modal:
        before, _, setup_rows = modal_table(setup.model, n_modes)
    mapping = CycleMapping(tuple((b.steps, b.tau) for b in f.mapping), f.adaptive)
    if progress is not None:
        progress = progress(mapping.n_steps)
    result = run_fatigue(setup.model, setup.loading, fatigue_parameters(case, setup.bonds.horizon),
                         mapping, f.load_ratio, f.max_load_time, f.no_damage_sets, f.tip.axis,
                         f.tip.depth_axis, f.tip.damage, f.solver, progress)
    if progress is not None:
        progress.close()
    summary = {"cycles": float(result.cycles[-1]), "crack_length_m": float(result.crack_length[-1]),
               "paris_slope": paris_slope(case, result), "bonds_broken": int(result.broken[-1]),
               "points": setup.body.n_points, "bonds": setup.bonds.n_bonds // 2,
               "output_dir": str(out)}
    if do_modal:
        after, _, after_rows = modal_table(setup.model, n_modes)
        masses = setup.model.density * setup.body.volumes
        mac, pairs = match_modes(before, after, masses)
        summary["modal"] = {"before": setup_rows, "after": after_rows, "mac": mac.tolist(),
                            "matches": pairs}
        (out / "modal.json").write_text(json.dumps(summary["modal"], indent=1))
    _write_history(out / "crack_length.csv", result)
    body = setup.body
    write_vtu(out / "damage.vtu", body.points[:, : body.dim],
              {"damage": result.damage, "first_break_cycle": np.where(
                  np.isfinite(result.first_break), result.first_break, -1.0),
               "u_max": result.u_max[:, : body.dim]})
    if case.output.plots:
        from peridyn.plotting.fatigue import plot_crack_length

        summary["plots"] = [str(plot_crack_length(result.cycles, result.crack_length,
                                                  out / "crack_length.png"))]
    summary["seconds"] = time.perf_counter() - start
    summary["peak_memory_bytes"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    (out / "fatigue.json").write_text(json.dumps(summary, indent=1))
    return summary


def _write_history(path: Path, result: FatigueResult) -> None:
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["cycles", "crack_length_m", "bonds_broken"])
        for n, a, k in zip(result.cycles, result.crack_length, result.broken, strict=True):
            w.writerow([f"{n:.6g}", f"{a:.6g}", int(k)])
