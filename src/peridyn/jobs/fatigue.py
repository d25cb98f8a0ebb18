"""A fatigue case: build, optional modal analysis, fatigue loop, modal analysis of the damaged body.

Outputs in the run folder: ``crack_length.csv`` (cycles, crack length, directed bonds broken by
the cycles),
``crack_length.png``, ``damage.vtu`` (final damage and first-break cycle), ``broken_bonds.csv``
(each bond the cycles broke, once: its two points, indices into ``damage.vtu``'s, and the cycle
at which it broke), ``modal.json``
(frequency tables before/after, MAC matrix, matched types) when ``modal_after`` is set,
and ``fatigue.json`` (the summary), with the files of every job's folder (``status.json``,
``provenance.json``, ``summary.json``: ``peridyn.io.job_files``).

Under ``mpiexec -n N`` (N > 1) each rank builds its part of the body and runs the fatigue loop on
it (``fatigue.loop``: the distributed CG for the equilibrium); the modal analyses before and after
run on the parts too (``jobs.modal.case_modes``: the distributed LOBPCG, after the cycles with the
bonds each rank's loop broke); rank 0 writes the same files as a serial run. The compliance K of
the Paris fit and the serial solvers are not distributed: they are refused by their case keys
(``check_parallel_fatigue``).
"""

from __future__ import annotations

import csv
import json
import logging
import time
from contextlib import nullcontext
from pathlib import Path

import numpy as np

from peridyn import interrupts
from peridyn.errors import CaseFileError, did_you_mean
from peridyn.fatigue.calibration import growth_rates, paris_fit, stress_intensity
from peridyn.fatigue.loop import FatigueResult, run_fatigue
from peridyn.fatigue.mapping import CycleMapping
from peridyn.fatigue.model import FatigueParameters, scale_A_II
from peridyn.fatigue.specimen import compliance_energy, compliance_stress_intensity, straight_crack_cut
from peridyn.fatigue.tip import AXES
from peridyn.io.case import Case, FatigueModal
from peridyn.io.job_files import job_files, write_summary
from peridyn.io.outdir import prepare_output
from peridyn.io.provenance import provenance
from peridyn.io.run_log import run_log
from peridyn.io.vtk import write_vtu
from peridyn.jobs.modal import case_modes, match_modes
from peridyn.jobs.summary import finish_summary
from peridyn.setup.build import build
from peridyn.setup.estimate import check_memory
from peridyn.setup.recording import output_directory

logger = logging.getLogger(__name__)


def check_fatigue_case(case: Case) -> None:
    """Case-level checks of a fatigue case (the ``fatigue`` block's own values are checked on load)."""
    if case.fatigue is None:
        raise CaseFileError(case.name, "fatigue", None, "a fatigue block (parameters, mapping)")
    if not case.boundary_conditions:
        raise CaseFileError(
            case.name, "boundary_conditions", [], "a cyclic load: boundary conditions giving the maximum load"
        )
    known = set(case.node_sets) | {"all"}
    for name in case.fatigue.no_damage_sets:
        if name not in known:
            raise CaseFileError(
                case.name,
                "fatigue.no_damage_sets",
                name,
                f"a defined node set{did_you_mean(name, known)}: {sorted(known)}",
            )


def check_parallel_fatigue(case: Case) -> None:
    """Refuse what an MPI fatigue run (mpiexec -n N, N > 1) cannot do: the compliance K of the
    Paris fit (``fatigue.paris.k: compliance``) and the serial linear solvers (``fatigue.solver``).
    The modal analyses (``fatigue.modal_after``, ``--modal``) run distributed."""
    f = case.fatigue
    if f.paris is not None and f.paris.k == "compliance":
        raise CaseFileError(
            case.name, "fatigue.paris.k", f.paris.k, "eq. 7.12 (not compliance) in an MPI run"
        )
    if f.solver not in ("auto", "amg"):
        raise CaseFileError(
            case.name, "fatigue.solver", f.solver, "auto or amg in an MPI run (distributed CG)"
        )


def fatigue_parameters(case: Case, horizon: float) -> FatigueParameters:
    """The case's parameters with A_II moved to ``horizon`` (m) by eq. 7.15 when its own is given."""
    f = case.fatigue
    a2 = f.A_II if f.A_II_horizon is None else scale_A_II(f.A_II, f.A_II_horizon, horizon, f.m_II)
    return FatigueParameters(A_I=f.A_I, m_I=f.m_I, eps_inf=f.eps_inf, A_II=a2, m_II=f.m_II, phi_c=f.phi_c)


def specimen_k(case: Case, setup) -> tuple[np.ndarray, np.ndarray] | None:
    """K_I (Pa m^0.5) of the modelled specimen at the maximum load on a grid of crack lengths (m),
    by compliance (``fatigue.specimen``), when ``paris.k`` is ``compliance``; else None."""
    p = case.fatigue.paris
    if p is None or p.k != "compliance":
        return None
    if not case.precracks:
        raise CaseFileError(case.name, "fatigue.paris.k", p.k, "a pre-crack to lengthen (compliance K)")
    body, axis = setup.body, AXES[case.fatigue.tip.axis]
    h = body.spacing
    span = np.ptp(body.points[:, axis]) + h
    crack = case.precracks[0]
    tips = (
        [np.add(crack.origin, crack.edge_u), crack.origin]
        if crack.type == "rectangle"
        else [crack.start, crack.end]
    )
    start = max(np.asarray(t, float)[axis] for t in tips) - (body.points[:, axis].min() - 0.5 * h)
    end = min(span - 2.0 * h, p.stop_length or span, p.fit_range[1] if p.fit_range else span)
    lengths = np.arange(start, end + 1.5 * h, h)
    cut = straight_crack_cut(body.points, h, setup.bonds, crack, axis)
    energy = compliance_energy(setup.model, setup.loading, lengths, cut, case.fatigue.max_load_time)
    depth = (
        case.geometry.thickness
        if body.dim == 2
        else np.ptp(body.points[:, AXES[case.fatigue.tip.depth_axis]]) + h
    )
    return lengths, compliance_stress_intensity(lengths, energy, depth, case.material.E)


def paris_rates(case: Case, result: FatigueResult, k_curve=None) -> tuple[np.ndarray, np.ndarray]:
    """(dK, da/dN) of the run's crack-length jumps (eq. 7.14), Pa m^0.5 and m/cycle, restricted to
    ``paris.fit_range`` (phase II) when it is set. K from eq. 7.12, or from ``k_curve``
    (lengths, K) of ``specimen_k`` interpolated in log-log."""
    p = case.fatigue.paris
    a_mid, rate = growth_rates(result.cycles, result.crack_length)
    if p.fit_range is not None:
        keep = (a_mid >= p.fit_range[0]) & (a_mid <= p.fit_range[1])
        a_mid, rate = a_mid[keep], rate[keep]
    if k_curve is None:
        k = stress_intensity(p.stress, a_mid, p.width)
    else:
        k = np.exp(np.interp(np.log(a_mid), np.log(k_curve[0]), np.log(k_curve[1])))
    return (1.0 - case.fatigue.load_ratio) * k, rate


def paris_slope(case: Case, result: FatigueResult, k_curve=None) -> float | None:
    """Slope of log(da/dN) against log(dK) of the run (eqs. 7.10-7.14), or None without ``paris``
    or with fewer than two rates in the fit range."""
    if case.fatigue.paris is None:
        return None
    dk, rate = paris_rates(case, result, k_curve)
    if rate.size < 2:
        return None
    return paris_fit(dk, rate)[0]


def _stop_length(f) -> float:
    """Crack length (m) that ends the run: ``paris.stop_length``, else none (inf)."""
    return f.paris.stop_length if f.paris is not None and f.paris.stop_length is not None else np.inf


@interrupts.deferred()
def run_fatigue_case(
    case: Case,
    output_dir=None,
    base_dir=".",
    modal: bool | None = None,
    progress=None,
    overwrite: bool = False,
    comm=None,
    max_memory: float | None = None,
    case_path=None,
) -> dict:
    """Run a fatigue case; returns the summary (JSON keys of ``peridyn fatigue --json``, also in
    ``fatigue.json``; docs/user-guide.md, "Summaries and results files"). A folder holding an
    earlier ``fatigue.json`` is refused unless ``overwrite``; the job's status, provenance and
    summary go to ``status.json``, ``provenance.json`` and ``summary.json``
    (``peridyn.io.job_files``). ``comm``: ``peridyn.parallel.comm.world()`` under
    ``mpiexec -n N`` (N > 1; see the module docstring), every rank returning the summary; None:
    one process. ``max_memory``: bytes the job may hold (default: the machine's); a case whose
    estimated peak exceeds it is refused before it is built (``setup.estimate.check_memory``).
    ``case_path``: the case file, recorded in the provenance (None: a case made in Python)."""
    start = time.perf_counter()
    check_fatigue_case(case)
    if comm is not None and comm.size > 1:
        check_parallel_fatigue(case)
    check_memory(case, max_memory, base_dir, job="fatigue")
    setup = build(case, base_dir, comm)
    d = setup.domain
    out = d.on_root(prepare_output, output_directory(case, output_dir), "fatigue.json", overwrite)
    files = job_files(out, provenance(case_path, case=case)) if d.is_root else nullcontext()
    with files, run_log(out, d.is_root):
        logger.info(f"fatigue case {case.name!r} ({setup.whole_body.n_points} points) into {out}")
        summary = d.comm.bcast(_run_fatigue(case, setup, out, modal, progress, start))
        logger.info(f"fatigue case {case.name!r} complete in {time.perf_counter() - start:.1f} s")
        return summary


def _run_fatigue(case, setup, out, modal, progress, start) -> dict:
    """The fatigue run of ``run_fatigue_case`` in its checked output folder (collective)."""
    f = case.fatigue
    modes = _modal_modes(case, modal)
    before = case_modes(setup, modes) if modes else None  # the healthy body
    k_curve = specimen_k(case, setup)
    mapping = CycleMapping(tuple((b.steps, b.tau) for b in f.mapping), f.adaptive)
    d = setup.domain
    if progress is not None and d.is_root:
        progress = progress(mapping.n_steps)
    else:
        progress = None
    result = run_fatigue(
        setup.model,
        setup.loading,
        fatigue_parameters(case, setup.bonds.horizon),
        mapping,
        load_ratio=f.load_ratio,
        max_load_time=f.max_load_time,
        no_damage_sets=f.no_damage_sets,
        crack_plane=f.crack_plane,
        tip=f.tip,
        solver=f.solver,
        stop_length=_stop_length(f),
        progress=progress,
        domain=d,
    )
    if progress is not None:
        progress.close()
    owned = slice(0, setup.bonds.offsets[d.n_owned])  # the owned points' families: every bond once
    summary = {
        "cycles": float(result.cycles[-1]),
        "crack_length_m": float(result.crack_length[-1]),
        "paris_slope": paris_slope(case, result, k_curve),
        "paris_rates": int(paris_rates(case, result)[1].size) if f.paris is not None else 0,
        "points": setup.whole_body.n_points,
        "bonds": d.count(owned.stop),
        "broken_bonds": d.count(int((~setup.bonds.intact[owned]).sum())),
        "fatigue_broken_bonds": int(result.broken[-1]),
    }
    after = case_modes(setup, modes) if modes else None  # the damaged body: bonds broken now
    return d.on_root(_write_fatigue, case, setup, out, summary, result, before, after, start)


def _modal_modes(case: Case, modal: bool | None) -> int:
    """Number of modes of the analyses before and after the cycles: ``fatigue.modal_after.modes``
    (its default, 12, with ``--modal`` alone), 0 for none (``modal`` False, or None without
    ``modal_after``)."""
    f = case.fatigue
    wanted = f.modal_after is not None if modal is None else modal
    if not wanted:
        return 0
    return (f.modal_after or FatigueModal()).modes


def _write_fatigue(case, setup, out, summary, result, before, after, start) -> dict:
    """The files of the run and its summary (rank 0), with ``modal.json`` from the ModeTables
    ``before`` and ``after`` the cycles when they are given."""
    if before is not None:
        mac, pairs = match_modes(before.result, after.result, before.masses)
        summary["modal"] = {"before": before.rows, "after": after.rows, "mac": mac.tolist(), "matches": pairs}
        (out / "modal.json").write_text(json.dumps(summary["modal"], indent=1))
    _write_history(out / "crack_length.csv", result)
    _write_broken_bonds(out / BROKEN_BONDS, result)
    body = setup.whole_body
    write_vtu(
        out / "damage.vtu",
        body.points[:, : body.dim],
        {
            "damage": result.damage,
            "first_break_cycle": np.where(np.isfinite(result.first_break), result.first_break, -1.0),
            "u_max": result.u_max[:, : body.dim],
        },
        case.output.vtu_compression,
    )
    plots = []
    if case.output.plots:
        from peridyn.plotting.fatigue import plot_crack_length

        plots.append(plot_crack_length(result.cycles, result.crack_length, out / "crack_length.png"))
    finish_summary(summary, "fatigue", out, start, plots)
    (out / "fatigue.json").write_text(json.dumps(summary, indent=1))
    write_summary(out, summary)
    return summary


#: The file of the bonds a fatigue run broke (``_write_broken_bonds``).
BROKEN_BONDS = "broken_bonds.csv"


def _write_broken_bonds(path: Path, result: FatigueResult) -> None:
    """``point_a, point_b, cycles``: each bond the cycles broke (its points, indices into
    ``damage.vtu``'s) and the cycle at which it broke, written as ``crack_length.csv``'s cycles
    (a bond broken at a step has that step's cycles there)."""
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["point_a", "point_b", "cycles"])
        for (a, b), n in zip(result.broken_pairs, result.break_cycle, strict=True):
            w.writerow([int(a), int(b), f"{n:.6g}"])


def _write_history(path: Path, result: FatigueResult) -> None:
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["cycles", "crack_length_m", "fatigue_broken_bonds"])
        for n, a, k in zip(result.cycles, result.crack_length, result.broken, strict=True):
            w.writerow([f"{n:.6g}", f"{a:.6g}", int(k)])
