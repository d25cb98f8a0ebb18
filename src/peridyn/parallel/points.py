"""Gathering the values of a few named points on rank 0 (``PointGather``): each rank sends the
values of those it owns, one typed message per array, and rank 0 places them in the order asked.

Used at a recorder's series records (``peridyn.parallel.observers.RootObservers``): the probe
points (sensors, lines, planes, PZT sensors) are a small part of the body, and gathering them
alone costs a fraction of gathering the whole state. The values are copied, never computed, so
they equal the serial run's bit for bit. A rank's owned rows are ordered by their clearance from
the ghosts (``peridyn.parallel.domain.Domain.clear_rows``), not by global index: the rows are
looked up through ``Domain.global_ids``.
"""

from __future__ import annotations

import numpy as np

from peridyn.parallel.domain import Domain


def owned_slots(owned_ids: np.ndarray, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Which of the points ``ids`` (k,) a rank owns.

    Parameters
    ----------
    owned_ids : (n_owned,) int
        Global index of each owned row (any order; each index once).
    ids : (k,) int
        Global indices asked for (may repeat).

    Returns
    -------
    rows : (m,) int64
        The owned rows holding them, in the order of ``slots``.
    slots : (m,) int64
        Their positions in ``ids``, increasing.
    """
    owned_ids = np.asarray(owned_ids, dtype=np.int64)
    ids = np.asarray(ids, dtype=np.int64)
    if len(owned_ids) == 0 or len(ids) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    order = np.argsort(owned_ids, kind="stable")
    pos = np.minimum(np.searchsorted(owned_ids[order], ids), len(order) - 1)
    hit = owned_ids[order[pos]] == ids
    return order[pos[hit]].astype(np.int64), np.flatnonzero(hit).astype(np.int64)


class PointGather:
    """The values of per-point arrays at fixed global points, gathered on rank 0 (collective).

    Parameters
    ----------
    domain : Domain
    *ids : (k_j,) int
        One set of global point indices per array that ``__call__`` will be given (may repeat,
        any order), the same on every rank.

    Raises
    ------
    ValueError
        On every rank, when the ranks together do not own each asked point exactly once (an
        index outside the body).
    """

    def __init__(self, domain: Domain, *ids: np.ndarray):
        self.domain = domain
        owned = domain.global_ids[: domain.n_owned]
        found = [owned_slots(owned, i) for i in ids]
        self.rows = [rows for rows, _ in found]
        self.sizes = [len(i) for i in ids]
        slots = [s for _, s in found]
        #: on rank 0: every rank's slots, per set of ids
        self._slots = domain.comm.gather(slots) if domain.size > 1 else [slots]
        domain.on_root(self._check_cover)
        if domain.is_root:
            #: per set of ids: the positions of the values as they arrive (rank after rank), and
            #: how many each rank sends
            by_set = [[rank_slots[j] for rank_slots in self._slots] for j in range(len(ids))]
            self._order = [np.concatenate(slots) for slots in by_set]
            self._counts = [[len(s) for s in slots] for slots in by_set]

    def _check_cover(self) -> None:
        for j, k in enumerate(self.sizes):
            taken = np.zeros(k, dtype=np.int64)
            for rank_slots in self._slots:
                np.add.at(taken, rank_slots[j], 1)
            if not np.all(taken == 1):
                bad = int(np.flatnonzero(taken != 1)[0])
                raise ValueError(
                    f"point set {j}: position {bad} is owned by {int(taken[bad])} ranks, not one"
                )

    def __call__(self, *arrays: np.ndarray) -> list | None:
        """``[arrays[j][ids[j]] ...]`` of the whole body, on rank 0 (None elsewhere): each
        ``arrays[j]`` is a local per-point array (n_local, ...) of the rank. One path for one
        process and for ranks (``SerialComm.gatherv`` copies)."""
        root = self.domain.is_root
        out = []
        for j, (a, rows) in enumerate(zip(arrays, self.rows, strict=True)):
            row = int(np.prod(a.shape[1:], dtype=np.int64))
            by_rank = np.empty((self.sizes[j], *a.shape[1:]), dtype=a.dtype) if root else None
            counts = [row * c for c in self._counts[j]] if root else None
            self.domain.comm.gatherv(np.ascontiguousarray(a[rows]), by_rank, counts)
            if root:
                whole = np.empty_like(by_rank)
                whole[self._order[j]] = by_rank
                out.append(whole)
        return out if root else None
