"""A modal case: solve, classify, and write frequencies, mode shapes and their figures.

Outputs in the run folder: ``modes.csv`` and ``modes.json`` (index, frequency, type,
order, residual), ``results.h5`` (``/modes/frequencies``, ``/modes/shapes``),
``modes/mode_NN.vtu`` for ParaView and ``modes.png`` (out-of-plane maps of the elastic modes).
"""

from __future__ import annotations

import csv
import json
import resource
from pathlib import Path

from peridyn.analysis.modes import classify_modes
from peridyn.errors import InputError
from peridyn.io.hdf5 import HDF5Writer
from peridyn.io.vtk import write_vtu
from peridyn.materials import LPSModel
from peridyn.recorder import provenance
from peridyn.solvers.modal import modal_analysis
from peridyn.solvers.ordering import estimated_factor_entries

#: Share of the machine's memory the factorisation may take.
MEMORY_SHARE = 0.7


def run_modal(case, setup, out: Path, case_path=None) -> dict:
    """Modal analysis of a built case; returns the summary (VALIDATION.md JSON keys)."""
    check_assembly_fits(setup.model)
    fixed = setup.loading.constrained if setup.loading.has_loads else None
    result = modal_analysis(setup.model, case.solver.modes, fixed=fixed)
    masses = setup.model.density * setup.body.volumes
    types = classify_modes(setup.body.points, result.shapes, masses, result.rigid)
    modes = [{"index": i, "frequency_hz": float(f), "type": t.type, "order": t.order,
              "residual": float(r)}
             for i, (f, t, r) in enumerate(zip(result.frequencies, types, result.residuals,
                                                strict=True))]
    _write_tables(out, modes)
    body = setup.body
    with HDF5Writer(out / "results.h5", body.points[:, : body.dim], body.volumes,
                    provenance(case_path, case=case)) as h5:
        h5.write_array("modes/frequencies", result.frequencies)
        h5.write_array("modes/shapes", result.shapes)
        h5.write_array("modes/rigid", result.rigid)
    (out / "modes").mkdir(exist_ok=True)
    for i, shape in enumerate(result.shapes):
        write_vtu(out / "modes" / f"mode_{i:02d}.vtu", body.points[:, : body.dim],
                  {"mode_shape": shape[:, : body.dim]})
    summary = {"output_dir": str(out), "rigid_modes": result.n_rigid, "modes": modes,
               "points": body.n_points, "bonds": setup.bonds.n_bonds,
               "peak_memory_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024}
    if case.output.plots:
        from peridyn.plotting.modes import plot_mode_shapes

        summary["plots"] = [str(plot_mode_shapes(body, result, types, out / "modes.png"))]
    return summary


def check_assembly_fits(model) -> None:
    """Refuse, with the numbers, a shift-invert factorisation too large for this machine.

    The factor's size is estimated from the nested-dissection separators of the
    points (``solvers.ordering.estimated_factor_entries``): it grows with the
    horizon (wider separators) much faster than the number of bonds does.
    """
    unknowns = 4 if isinstance(model, LPSModel) else 3  # LPS: three dofs and a dilatation
    entries = estimated_factor_entries(model.body.points, model.bonds.horizon, unknowns)
    needed = 12.0 * entries  # 8-byte values and 4-byte indices
    try:
        import os

        available = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return
    if needed > MEMORY_SHARE * available:
        raise InputError(
            f"the sparse factorisation of this model would hold about {entries / 1e9:.2f} billion "
            f"entries (~{needed / 2**30:.0f} GiB; this machine has {available / 2**30:.0f} GiB): "
            "use a smaller horizon (1.4143 spacing: 18 neighbours) or a coarser spacing"
        )


def _write_tables(out: Path, modes: list[dict]) -> None:
    with open(out / "modes.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(modes[0]))
        writer.writeheader()
        writer.writerows(modes)
    (out / "modes.json").write_text(json.dumps(modes, indent=1))
