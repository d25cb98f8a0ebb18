"""A modal case: solve, classify, and write frequencies, mode shapes and their figures.

Outputs in the run folder: ``modes.csv`` and ``modes.json`` (index, frequency, type,
order, residual), ``results.h5`` (``/modes/frequencies``, ``/modes/shapes``),
``modes/mode_NN.vtu`` for ParaView and ``modes.png`` (out-of-plane maps of the elastic modes).
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from peridyn.analysis.modes import classify_modes, mac_matrix
from peridyn.errors import InputError
from peridyn.io.hdf5 import HDF5Writer
from peridyn.io.provenance import provenance
from peridyn.io.vtk import write_vtu
from peridyn.setup.eigensolver import check_mode_count, choose_eigensolver
from peridyn.solvers.modal import ModalResult, modal_analysis


@dataclass(frozen=True)
class ModeTable:
    """Modes of a built case's whole body, classified (``case_modes``).

    Attributes
    ----------
    result : ModalResult
        Frequencies (n_modes,) Hz and mode shapes (n_modes, n_points, 3) of the whole body.
    types : list of ``analysis.modes.ModeType``, one per mode
    rows : list of dict
        The JSON/CSV rows of ``mode_rows`` (index, frequency_hz, type, order, label, residual).
    masses : (n_points,) float64, kg
        Lumped mass rho V of each point of the whole body (the MAC's weights).
    stats : dict
        The distributed solver's ``iterations`` (LOBPCG) under MPI; empty in one process.
    """

    result: ModalResult
    types: list
    rows: list[dict]
    masses: np.ndarray
    stats: dict


def case_modes(setup, n_modes: int, fixed=None, eigensolver: str = "auto") -> ModeTable | None:
    """The ``n_modes`` lowest modes of a built case's model with the bonds intact now
    (collective under MPI).

    In one process ``modal_table`` (eigensolver by ``choose_eigensolver``). Over several ranks
    (``setup.domain``) the distributed LOBPCG on each rank's part (``solvers.distributed_eigen``:
    its owned free rows of K, ghosts by the halo exchange; ``eigensolver`` is then not used),
    the modes classified on rank 0 over the whole body. ``fixed``: (n_local, 3) bool, dofs held
    at zero, or None (free). Returns the table on rank 0, None on the other ranks.
    """
    d = setup.domain
    masses = d.gather(setup.model.density * setup.model.body.volumes)
    if d.size == 1:
        result, types, rows = modal_table(setup.model, n_modes, fixed=fixed, eigensolver=eigensolver)
        return ModeTable(result, types, rows, masses, {})
    from peridyn.linalg.distributed import RankDofs
    from peridyn.solvers.distributed_eigen import distributed_modes

    result, stats = distributed_modes(RankDofs(setup.model, d, fixed), n_modes)
    classified = d.on_root(mode_rows, setup.whole_body, masses, result)
    if not d.is_root:
        return None
    return ModeTable(result, *classified, masses, {"iterations": stats["iterations"]})


def run_modal(case, setup, out: Path, case_path=None) -> tuple[dict, list[Path]]:
    """Modal analysis of a built case; returns the summary's own keys (docs/user-guide.md,
    "Summaries and results files") and the figures drawn. Under MPI (``setup.domain`` of
    several ranks) the modes are found by the distributed LOBPCG (``case_modes``) and rank 0
    writes the same files as a serial run, the summary adding the LOBPCG's ``iterations``
    (collective)."""
    fixed = setup.loading.constrained if setup.loading.has_loads else None
    d = setup.domain
    held = fixed is not None and d.max(int(np.any(fixed[: d.n_owned]))) > 0  # on any rank
    check_mode_count(case, setup.whole_body.dim, held)
    table = case_modes(setup, case.solver.modes, fixed, case.solver.eigensolver)
    n_bonds = d.count(setup.bonds.offsets[d.n_owned])  # the owned points' families come first
    written = d.on_root(_write_modal, case, setup.whole_body, n_bonds, table, out, case_path)
    summary, plots = written if d.is_root else (None, [])
    return d.comm.bcast({**summary, **table.stats} if d.is_root else None), plots


def _write_modal(case, body, n_bonds, table: ModeTable, out, case_path) -> tuple[dict, list[Path]]:
    """Write the tables, results.h5, the mode-shape VTUs and figure of the modes ``table`` of
    ``body``; the summary's own keys and the figures."""
    result, types, modes = table.result, table.types, table.rows
    _write_tables(out, modes)
    with HDF5Writer(
        out / "results.h5", body.points[:, : body.dim], body.volumes, provenance(case_path, case=case)
    ) as h5:
        h5.set_status("running")
        h5.write_array(
            "modes/frequencies", result.frequencies, {"units": "Hz", "long_name": "frequency"}, ["mode"]
        )
        about = {"units": "1", "long_name": "mode shape, mass-normalised (x^T M x = 1)"}
        h5.write_array("modes/shapes", result.shapes, about, ["mode", "point", "component"])
        h5.write_array("modes/rigid", result.rigid, {"units": "1", "long_name": "rigid-body mode"}, ["mode"])
    (out / "modes").mkdir(exist_ok=True)
    for i, shape in enumerate(result.shapes):
        write_vtu(
            out / "modes" / f"mode_{i:02d}.vtu",
            body.points[:, : body.dim],
            {"mode_shape": shape[:, : body.dim]},
            case.output.vtu_compression,
        )
    summary = {
        "rigid_modes": result.n_rigid,
        "modes": modes,
        "points": body.n_points,
        "bonds": n_bonds,
    }
    plots = []
    if case.output.plots:
        from peridyn.plotting.modes import plot_mode_shapes

        plots.append(plot_mode_shapes(body, result, types, out / "modes.png"))
    return summary, plots


def redraw_mode_shapes(body, results) -> Path:
    """``modes.png`` of a finished modal run of ``body`` again, from its ``results``
    (``peridyn.io.results.Results``: the frequencies, shapes and rigid modes, and the types and
    residuals of its summary's rows)."""
    from peridyn.analysis.modes import ModeType
    from peridyn.plotting.modes import plot_mode_shapes

    rows = results.summary()["modes"]
    result = ModalResult(
        results.array("modes/frequencies"),
        results.array("modes/shapes"),
        np.array([row["residual"] for row in rows]),
        results.array("modes/rigid").astype(bool),
    )
    types = [ModeType(row["type"], row["order"]) for row in rows]
    return plot_mode_shapes(body, result, types, Path(results.path).parent / "modes.png")


def modal_table(model, n_modes: int, fixed=None, eigensolver: str = "auto"):
    """Modes of ``model`` (eigensolver chosen by ``choose_eigensolver``), classified:
    (ModalResult, types, rows), the rows being the JSON/CSV dicts index, frequency_hz, type,
    order, label ("1st bending", ``mode_label``), residual."""
    method = choose_eigensolver(model, eigensolver)
    result = modal_analysis(model, n_modes, fixed=fixed, method=method)
    types, rows = mode_rows(model.body, model.density * model.body.volumes, result)
    return result, types, rows


def mode_rows(body, masses, result):
    """Types (``analysis.modes.classify_modes``) and JSON/CSV rows of the modes ``result`` of
    ``body`` whose points weigh ``masses`` (n_points,) kg. A rigid mode's frequency is 0 Hz
    (the solver's value, round-off of order 1e-3 Hz of either sign, stays in results.h5)."""
    types = classify_modes(body.points, result.shapes, masses, result.rigid)
    rows = [
        {
            "index": i,
            "frequency_hz": 0.0 if rigid else float(f),
            "type": t.type,
            "order": t.order,
            "label": str(t),
            "residual": float(r),
        }
        for i, (f, t, r, rigid) in enumerate(
            zip(result.frequencies, types, result.residuals, result.rigid, strict=True)
        )
    ]
    return types, rows


def match_modes(before, after, masses) -> tuple[np.ndarray, list[dict]]:
    """MAC matrix of the elastic modes (before x after) and, for each mode before, the mode after
    with the largest MAC (types can swap order when frequencies shift, thesis table 7.2).

    ``before``, ``after``: ModalResult of the same points; ``masses`` (n_points,) kg.
    """
    b, a = before.elastic(), after.elastic()
    mac = mac_matrix(b.shapes, a.shapes, masses)
    pairs = []
    for i in range(mac.shape[0]):
        j = int(np.argmax(mac[i]))
        pairs.append(
            {
                "before": i,
                "after": j,
                "mac": float(mac[i, j]),
                "frequency_change": float(a.frequencies[j] / b.frequencies[i] - 1.0),
            }
        )
    return mac, pairs


def compare_with_run(run_dir: Path, reference_dir: Path) -> list[dict]:
    """Frequency-shift table of the modal run in ``run_dir`` against ``reference_dir``.

    Each elastic mode of the reference is paired with this run's elastic mode of largest
    MAC (so types are compared like with like when damage changes the order); written to
    ``run_dir / "frequency_shift.csv"``. Both runs must have the same points.
    """
    from peridyn.io.results import Results

    runs = []
    for d in (reference_dir, run_dir):
        h5 = d / "results.h5"
        if not h5.is_file():
            raise InputError(f"--compare: {h5} not found (give the folder of a modal run)")
        results = Results(h5)
        runs.append(
            {
                "points": results.array("geometry/points"),
                "volumes": results.array("geometry/volumes"),
                "frequencies": results.array("modes/frequencies"),
                "shapes": results.array("modes/shapes"),
                "rigid": results.array("modes/rigid").astype(bool),
                "types": json.loads((d / "modes.json").read_text()),
            }
        )
    ref, new = runs
    if ref["points"].shape != new["points"].shape or not np.allclose(ref["points"], new["points"]):
        raise InputError(
            f"--compare: {reference_dir} has other points than this run "
            f"({len(ref['points'])} against {len(new['points'])}): MAC needs the "
            "same grid"
        )
    keep_r, keep_n = ~ref["rigid"], ~new["rigid"]
    # uniform density: the volumes weigh the MAC as the masses would
    mac = mac_matrix(ref["shapes"][keep_r], new["shapes"][keep_n], new["volumes"])
    ref_rows = [m for m, r in zip(ref["types"], ref["rigid"], strict=True) if not r]
    new_rows = [m for m, r in zip(new["types"], new["rigid"], strict=True) if not r]
    rows = []
    for i, ref_row in enumerate(ref_rows):
        j = int(np.argmax(mac[i]))
        rows.append(
            {
                "reference_index": ref_row["index"],
                "reference_label": mode_label(ref_row),
                "reference_frequency_hz": ref_row["frequency_hz"],
                "index": new_rows[j]["index"],
                "label": mode_label(new_rows[j]),
                "frequency_hz": new_rows[j]["frequency_hz"],
                "mac": float(mac[i, j]),
                "frequency_change": new_rows[j]["frequency_hz"] / ref_row["frequency_hz"] - 1,
            }
        )
    with open(run_dir / "frequency_shift.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return rows


def mode_label(row: dict) -> str:
    """'1st bending' from a mode row's type and order (the type alone for order 0): the one
    form of a mode's label in every summary, table and report."""
    from peridyn.analysis.modes import ModeType

    return str(ModeType(row["type"], row["order"]))


def _write_tables(out: Path, modes: list[dict]) -> None:
    with open(out / "modes.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(modes[0]))
        writer.writeheader()
        writer.writerows(modes)
    (out / "modes.json").write_text(json.dumps(modes, indent=1))
