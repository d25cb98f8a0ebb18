"""Ghost points and their exchange between ranks.

A rank owns some points and keeps copies (ghosts) of the points it needs from other ranks:

- layer 1: the points within the bond search reach of an owned point (the neighbours of its
  families);
- layer 2: the points within that reach of a layer-1 point. Then every layer-1 point has its
  whole family on the rank, so whatever a material computes per point from its family (the LPS
  dilatation and weighted volume, surface-correction factors, the deviatoric stiffness of a
  bond, which needs the far end's coefficients) comes out on the rank as in a serial run, with
  a single exchange of u per step.

Local numbering: owned points first, then the ghosts grouped by the rank that owns them (ranks
ascending), so that each rank's ghosts are one block of rows that a message fills in place; in
a block, the layer-1 ghosts (those an owned point's family holds) come first, each layer in
global order. The owned points are ordered by their ``clearance`` from the ghosts,
the farthest first (global order within a clearance), so that the rows a force needs no ghost
for are leading blocks, computed while the ghosts' values are on their way.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

#: Message tag of the halo exchange.
HALO_TAG = 17


def ghost_layers(points: np.ndarray, owned: np.ndarray, reach: float, layers: int = 2) -> np.ndarray:
    """Global indices (sorted, int64) of the points within ``layers`` hops of ``reach`` (m) of the
    ``owned`` points (global indices) and not owned.

    One hop: the points within ``reach`` of a point of the previous layer (layer 0: the owned).
    Each hop asks, of the points not yet taken inside the previous layer's box grown by
    ``reach``, how many points of that layer lie within ``reach`` (a tree of the layer's
    points): the work grows with the points near the part, not with its bonds.
    """
    points = np.asarray(points, dtype=np.float64)
    taken = np.zeros(len(points), dtype=bool)
    taken[owned] = True
    frontier = np.asarray(owned, dtype=np.int64)
    for _ in range(layers):
        if frontier.size == 0:
            break
        at = points[frontier]
        pad = reach * (1.0 + 1e-9)  # a point at exactly ``reach`` stays a candidate
        inside = np.all((points >= at.min(axis=0) - pad) & (points <= at.max(axis=0) + pad), axis=1)
        candidates = np.flatnonzero(inside & ~taken)
        hits = cKDTree(at).query_ball_point(points[candidates], reach, return_length=True)
        frontier = candidates[np.asarray(hits) > 0]
        taken[frontier] = True
    taken[owned] = False
    return np.flatnonzero(taken).astype(np.int64)


def clearance(offsets: np.ndarray, neighbours: np.ndarray, owned: np.ndarray, hops: int = 2) -> np.ndarray:
    """(k,) int64: for each of the ``owned`` rows (k,) of a part's bonds (CSR ``offsets`` and
    ``neighbours`` over all its rows, the others its ghosts), the bond hops between it and the
    nearest ghost less one, at most ``hops``: 0 if its family holds a ghost, 1 if not but a
    neighbour's does, ...

    A row of clearance c has a force computable without ghost values when the force reads the
    families of points up to c - 1 bonds away: 1 for a bond-based force, 2 for a state-based one
    (the dilatation of each neighbour).
    """
    n_rows = len(offsets) - 1
    owners = np.repeat(np.arange(n_rows), np.diff(offsets))
    near_ghost = np.ones(n_rows, dtype=bool)
    near_ghost[owned] = False  # rows within the current distance of a ghost
    level = np.full(len(owned), hops, dtype=np.int64)
    for c in range(hops):
        touching = np.bincount(owners, weights=near_ghost[neighbours], minlength=n_rows) > 0
        reached = touching[owned] & (level == hops)
        level[reached] = c
        near_ghost |= touching
    return level


@dataclass(frozen=True)
class HaloPlan:
    """Who sends which owned points to whom, on one rank.

    Attributes
    ----------
    n_owned : int
    recv_ranks : (k,) int64
        Ranks this rank receives ghosts from, ascending.
    recv_slices : list of (start, stop)
        Rows of the local arrays that each of ``recv_ranks`` fills (the ghosts it owns).
    send_ranks : (m,) int64
        Ranks this rank sends owned points to, ascending.
    send_rows : list of (n_r,) int64
        The local rows (owned points) sent to each of ``send_ranks``, in the order that the
        receiver keeps them (global order).
    """

    n_owned: int
    recv_ranks: np.ndarray
    recv_slices: list
    send_ranks: np.ndarray
    send_rows: list

    @property
    def n_ghosts(self) -> int:
        """Number of ghost rows."""
        return sum(stop - start for start, stop in self.recv_slices)

    def messages(self) -> int:
        """Messages this rank sends per exchange."""
        return len(self.send_ranks)


def plan_halo(comm, owned_ids: np.ndarray, ghost_ids: np.ndarray, ghost_owner: np.ndarray) -> HaloPlan:
    """The exchange plan of one rank (collective: every rank calls it).

    ``owned_ids`` (global) are this rank's points in local order, ``ghost_ids`` its ghosts in local
    order (grouped by owner rank ascending) and ``ghost_owner`` their ranks.
    """
    n_owned = len(owned_ids)
    recv_ranks = np.unique(ghost_owner)
    bounds = (
        np.searchsorted(ghost_owner, recv_ranks, side="left"),
        np.searchsorted(ghost_owner, recv_ranks, side="right"),
    )
    recv_slices = [(n_owned + int(a), n_owned + int(b)) for a, b in zip(*bounds, strict=True)]
    requests = [np.zeros(0, dtype=np.int64) for _ in range(comm.size)]
    for r, (a, b) in zip(recv_ranks, zip(*bounds, strict=True), strict=True):
        requests[int(r)] = ghost_ids[a:b]
    wanted = comm.alltoall(requests)
    send_ranks = np.array([r for r in range(comm.size) if len(wanted[r])], dtype=np.int64)
    order = np.argsort(owned_ids, kind="stable")
    send_rows = [order[np.searchsorted(owned_ids, wanted[r], sorter=order)] for r in send_ranks]
    return HaloPlan(n_owned, recv_ranks.astype(np.int64), recv_slices, send_ranks, send_rows)


class Halo:
    """Exchange of the ghost rows of per-point arrays by non-blocking messages.

    ``start(a)`` posts the receives straight into the ghost rows of ``a`` (each sender fills one
    contiguous block) and the sends of the owned rows the others need; ``finish()`` waits for
    them. Work on the owned rows may go between the two; ``exchange(a)`` does both. The
    communicator's ``traffic`` counts the messages, bytes and the seconds spent in both.
    """

    def __init__(self, comm, plan: HaloPlan):
        self.comm = comm
        self.plan = plan
        self._pending: list = []
        self._buffers: list = []

    def start(self, a: np.ndarray) -> None:
        """Post the exchange of ``a`` (n_local, ...) C-contiguous; ghost rows are OUT."""
        began = time.perf_counter()
        p = self.plan
        for r, (lo, hi) in zip(p.recv_ranks, p.recv_slices, strict=True):
            self._pending.append(self.comm.irecv(a[lo:hi], int(r), HALO_TAG))
        for r, rows in zip(p.send_ranks, p.send_rows, strict=True):
            buf = np.ascontiguousarray(a[rows])
            self._buffers.append(buf)
            self._pending.append(self.comm.isend(buf, int(r), HALO_TAG))
        self.comm.traffic.halo_seconds += time.perf_counter() - began

    def finish(self) -> None:
        """Wait for the messages of ``start``."""
        began = time.perf_counter()
        self.comm.waitall(self._pending)
        self._pending, self._buffers = [], []
        waited = time.perf_counter() - began
        self.comm.traffic.halo_seconds += waited
        self.comm.traffic.wait_seconds += waited

    def exchange(self, a: np.ndarray) -> None:
        """Fill the ghost rows of ``a`` with their owners' values."""
        if self.plan.recv_slices or len(self.plan.send_ranks):
            self.start(a)
            self.finish()
