"""VTU snapshots of an MPI run as per-rank pieces (ParaView's parallel format).

At a snapshot each rank writes its owned points, with the point data of a serial snapshot
(``peridyn.io.recorder.snapshot_fields``: the same names, types and values), to
``snapshots/step_NNNNNNNN/piece_RRRR.vtu``, and rank 0 writes ``snapshots/step_NNNNNNNN.pvtu``,
which lists the pieces; ``snapshots.pvd`` (the recorder's, on rank 0) lists the ``.pvtu`` files.
Nothing is gathered: the pieces together hold every point of the body once.
"""

from __future__ import annotations

from pathlib import Path

from peridyn.discretization.body import Body
from peridyn.discretization.state import State
from peridyn.io.recorder import snapshot_fields, snapshot_name
from peridyn.io.vtk import write_pvtu, write_vtu
from peridyn.parallel.domain import Domain


class VtuPieces:
    """Writer of the per-rank pieces of the VTU snapshots (collective: every rank calls ``write``).

    Parameters
    ----------
    domain : Domain
    body : Body
        The rank's part (owned points first).
    directory : path
        The run's output folder.
    damage : callable () -> (n_local,) float64, or None
        The rank's damage index (owned rows written).
    tensors : callable (u) -> dict of str to array, or None
        The rank's per-point tensor fields at its local displacement (``Recorder``'s ``tensors``).
    compression : {"none", "zlib"}
        The pieces' data arrays (``peridyn.io.vtk.write_vtu``).
    """

    def __init__(self, domain: Domain, body: Body, directory, damage=None, tensors=None, compression="none"):
        self.domain = domain
        self.body = body
        self.directory = Path(directory)
        self.damage = damage
        self.tensors = tensors
        self.compression = compression

    def write(self, state: State) -> None:
        """Write this rank's piece of the snapshot of ``state`` (the rank's, local rows) and, on
        rank 0, the ``.pvtu``; an error on any rank is raised on all."""
        n, dim = self.domain.n_owned, self.body.dim
        damage = self.damage()[:n] if self.damage is not None else None
        tensors = {k: v[:n] for k, v in self.tensors(state.u).items()} if self.tensors is not None else {}
        data = snapshot_fields(state.u[:n], state.v[:n], dim, damage, tensors, self.body.volumes[:n])
        name = snapshot_name(state.step, "")
        pieces = [f"{Path(name).name}/piece_{rank:04d}.vtu" for rank in range(self.domain.size)]
        folder = self.directory / name
        self.domain.agree(self._write_piece, folder, pieces[self.domain.comm.rank], data, state.time)
        self.domain.on_root(write_pvtu, self.directory / f"{name}.pvtu", pieces, data)

    def _write_piece(self, folder: Path, piece: str, data: dict, time: float) -> None:
        folder.mkdir(parents=True, exist_ok=True)
        n, dim = self.domain.n_owned, self.body.dim
        write_vtu(folder.parent / piece, self.body.points[:n, :dim], data, self.compression, time)
