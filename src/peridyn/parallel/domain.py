"""A rank's part of a body (``Domain``): which points it owns, its ghosts and their exchange, and
the collective operations a run needs, written so that results equal a serial run's bit for bit.

Local arrays hold the owned points first (``owned`` rows: the farthest from the ghosts first,
``clear_rows``), then the ghosts (``peridyn.parallel.halo``); ``global_ids`` maps them to the
serial numbering. Reductions that round (sums, dot products) are never summed per rank:
the owned values are gathered on rank 0 in global point order and reduced there with the same
numpy call as in serial, then broadcast. Max and min are exact and reduced across ranks.

Errors: a step that only some ranks may fail (a check, a file on rank 0) runs through
``agree`` or ``on_root``; every rank then raises the same error at the same point, so no rank
waits for a message that never comes (such an error is marked ``every_rank``). Any other error
raised inside a time step is one rank's alone (``failed_alone`` marks it with ``failed_rank``):
the other ranks may then be blocked in a halo wait or a collective that it will never join,
which only ``MPI_Abort`` ends (``peridyn.cli`` reports the error on that rank, then aborts).
``Domain.serial(n)`` is the one-process stand-in: every method reduces to the plain numpy call.
"""

from __future__ import annotations

import pickle

import numpy as np

from peridyn.discretization.state import State, check_state, first_unsound, runaway_limit_of_extent
from peridyn.errors import InstabilityError, PeridynError
from peridyn.parallel.comm import SerialComm, Traffic
from peridyn.parallel.halo import Halo


class RankError(PeridynError):
    """An error raised on another rank, whose exception could not be sent as it was."""


class Domain:
    """The points one rank computes (see the module docstring).

    Parameters
    ----------
    comm : SerialComm or MPIComm
    global_ids : (n_local,) int64
        Global index of each local point: the owned ones first, then the ghosts.
    n_owned : int
    n_global : int
    halo : Halo or None
        The ghost exchange (None: no ghosts, one rank).
    partition : str
        How the points were split, for the provenance.
    clear_rows : tuple of int
        ``clear_rows[c - 1]``: the number of leading owned rows of clearance c or more
        (``peridyn.parallel.halo.clearance``: no ghost within c - 1 bonds of their families),
        whose forces need no ghost value (c = 1 bond-based, c = 2 state-based). Default: none
        known (every force waits for the ghosts).
    """

    def __init__(
        self,
        comm,
        global_ids,
        n_owned: int,
        n_global: int,
        halo: Halo | None,
        partition: str,
        clear_rows: tuple = (0, 0),
    ):
        self.comm = comm
        self.clear_rows = tuple(int(c) for c in clear_rows)
        self.global_ids = np.asarray(global_ids, dtype=np.int64)
        self.n_owned = int(n_owned)
        self.n_global = int(n_global)
        self.halo = halo
        self.partition = partition
        owned_ids = self.global_ids[: self.n_owned]
        rank_ids = comm.gather(owned_ids) if comm.size > 1 else [owned_ids]
        gathering = comm.size > 1 and rank_ids is not None  # rank 0 of several
        #: on rank 0: every rank's number of owned points (None elsewhere)
        self._rank_counts = None if rank_ids is None else [len(ids) for ids in rank_ids]
        #: on rank 0 of several: the global indices of the owned points of rank 0, then rank 1,
        #: ..., or None where that order is the global one (slabs of a grid: ``gather_many``
        #: then places nothing, and rank 0 keeps no whole-body index)
        self._rank_order = np.concatenate(rank_ids) if gathering else None
        del rank_ids
        #: on rank 0 of several: whether the ranks own the global order's consecutive ranges
        self._in_rank_order = gathering and bool(np.array_equal(self._rank_order, np.arange(self.n_global)))
        if self._in_rank_order:
            self._rank_order = None

    @classmethod
    def serial(cls, n_points: int) -> Domain:
        """The whole body in one process."""
        return cls(SerialComm(), np.arange(n_points), n_points, n_points, None, "none", (n_points, n_points))

    @property
    def size(self) -> int:
        """Number of ranks."""
        return self.comm.size

    @property
    def is_root(self) -> bool:
        """True on rank 0, which writes the results."""
        return self.comm.rank == 0

    @property
    def owned(self) -> slice:
        """The owned rows of a local array."""
        return slice(0, self.n_owned)

    def __repr__(self) -> str:
        return (
            f"Domain(rank={self.comm.rank}/{self.size}, owned={self.n_owned}, "
            f"local={len(self.global_ids)}, global={self.n_global})"
        )

    # -- ghosts --------------------------------------------------------------------------

    def exchange(self, a: np.ndarray) -> None:
        """Fill the ghost rows of the local array ``a`` (n_local, ...) from their owners."""
        if self.halo is not None:
            self.halo.exchange(a)

    def start_exchange(self, a: np.ndarray) -> None:
        """Post the exchange of ``exchange``; the ghost rows of ``a`` are filled at
        ``finish_exchange``, and meanwhile neither they nor ``a``'s owned rows may change."""
        if self.halo is not None:
            self.halo.start(a)

    def finish_exchange(self) -> None:
        """Wait for the exchange posted by ``start_exchange``."""
        if self.halo is not None:
            self.halo.finish()

    # -- reductions ----------------------------------------------------------------------

    def max(self, value):
        """The largest of every rank's ``value`` (a number or an array, element by element)."""
        return self.comm.allreduce(value, "max")

    def min(self, value):
        """The smallest of every rank's ``value``."""
        return self.comm.allreduce(value, "min")

    def count(self, value: int) -> int:
        """The sum of every rank's integer ``value``."""
        return int(self.comm.allreduce(int(value), "sum"))

    def gather(self, a: np.ndarray) -> np.ndarray | None:
        """The owned rows of every rank's ``a`` assembled in global point order, on rank 0
        (None elsewhere); in one process ``a`` itself."""
        if self.size == 1:
            return a
        whole = self.gather_many(a)
        return None if whole is None else whole[0]

    def gather_many(self, *arrays: np.ndarray) -> list | None:
        """``gather`` of several per-point arrays, on rank 0 (None elsewhere); in one process the
        arrays themselves. Each array by one typed gather (``comm.gatherv``: no pickled copies,
        faster than a pickled gather of the same bytes), in rank order into a buffer of the whole
        array, then placed in global order; where the ranks own consecutive ranges of points in
        rank order (slabs of a grid: ``parallel.lattice_domain``) straight into the result."""
        if self.size == 1:
            return list(arrays)
        root = self.is_root
        out = []
        for a in arrays:
            row = int(np.prod(a.shape[1:], dtype=np.int64))
            whole = np.empty((self.n_global, *a.shape[1:]), dtype=a.dtype) if root else None
            by_rank = whole if root and self._in_rank_order else np.empty_like(whole) if root else None
            counts = [row * count for count in self._rank_counts] if root else None
            self.comm.gatherv(np.ascontiguousarray(a[: self.n_owned]), by_rank, counts)
            if root and not self._in_rank_order:
                whole[self._rank_order] = by_rank
            out.append(whole)
        return out if root else None

    def reduce(self, fn, *arrays: np.ndarray):
        """``fn(*arrays)`` over the whole body, on every rank: the owned rows of the per-point
        ``arrays`` gathered in global point order (one ``gather_many``), ``fn`` called on rank 0
        and its result broadcast, so that whatever ``fn`` rounds (sums, norms) rounds as in serial.
        In one process ``fn(*arrays)`` itself."""
        whole = self.gather_many(*arrays)
        return self.comm.bcast(fn(*whole) if self.is_root else None)

    def sum(self, a: np.ndarray) -> float:
        """``np.sum`` of the per-point values ``a`` (owned rows) over the whole body, in global
        order (the serial rounding), on every rank."""
        return self.reduce(np.sum, a)

    def dot(self, a: np.ndarray, b: np.ndarray) -> float:
        """The dot product of two per-point (n,) arrays over the whole body, as in serial, on
        every rank: ``np.sum(a * b)``, NumPy's pairwise sum in a fixed order, not ``np.dot``,
        whose BLAS may split the sum over threads as the cores it sees allow."""
        return self.reduce(lambda x, y: np.sum(x * y), a, b)

    def allsum(self, value):
        """The sum of every rank's ``value`` (a number or an array, element by element) by one
        allreduce: rounded in rank order, not as a serial sum over the points. For the global
        dot products of Krylov solvers (``peridyn.linalg.distributed``), whose answers must
        equal a serial run's to the solver tolerance only, at the cost of one message round."""
        return self.comm.allreduce(value, "sum")

    def runaway_limit(self, points: np.ndarray) -> float:
        """``runaway_limit`` of the whole body from the local ``points`` (n_local, 3), m."""
        owned = points[: self.n_owned]
        extent = self.max(owned.max(axis=0)) - self.min(owned.min(axis=0))
        return runaway_limit_of_extent(extent)

    # -- errors --------------------------------------------------------------------------

    def agree(self, fn, *args):
        """``agree`` on this domain's communicator."""
        return agree(self.comm, fn, *args)

    def on_root(self, fn, *args):
        """``fn(*args)`` on rank 0 only (its result there, None elsewhere); an error there is
        raised on every rank."""
        if self.size == 1:
            return fn(*args)
        result, error = None, None
        if self.is_root:
            try:
                result = fn(*args)
            except Exception as exc:  # noqa: BLE001 - shared, then raised
                error = exc
        _raise_any([self.comm.bcast(None if error is None else _portable(error))], error)
        return result

    def from_root(self, fn, *args):
        """``fn(*args)`` on rank 0, its result on every rank (``on_root``, then broadcast): what
        needs the whole body, which only rank 0 may hold (lattice storage's slabs)."""
        result = self.on_root(fn, *args)
        return result if self.size == 1 else self.comm.bcast(result)

    def check_state(self, state: State, max_displacement: float) -> None:
        """``check_state`` of the whole body, each rank checking its owned points, then one
        allgather: every rank raises the error of the serial check (the first field out of
        bounds, u before v, at its smallest global point)."""
        n = self.n_owned
        owned = State(state.u[:n], state.v[:n], state.a[:n], state.time, state.step)
        if self.size == 1:
            check_state(owned, max_displacement)
            return
        found = first_unsound(owned, max_displacement, self.global_ids[:n])
        every = [f for f in self.comm.allgather(found) if f is not None]
        if every:
            _, point, detail = min(every)
            error = InstabilityError(state.step, state.time, point, detail)
            error.every_rank = True
            raise error

    def gather_state(self, state: State) -> State | None:
        """The state of the whole body in global order on rank 0 (None elsewhere); in one
        process ``state`` itself."""
        if self.size == 1:
            return state
        whole = self.gather_many(state.u, state.v, state.a)
        return State(*whole, state.time, state.step) if self.is_root else None

    # -- per-bond arrays (checkpoints) ------------------------------------------------------

    def bond_offsets(self, offsets: np.ndarray) -> np.ndarray:
        """(n_global + 1,) int64: the whole body's family offsets (serial bond numbering), from
        the local CSR ``offsets`` (collective; the owned families are whole)."""
        counts = np.diff(offsets[: self.n_owned + 1])
        if self.size == 1:
            return np.asarray(offsets, dtype=np.int64)
        every = np.zeros(self.n_global, dtype=np.int64)
        for ids, c in self.comm.allgather((self.global_ids[: self.n_owned], counts)):
            every[ids] = c
        return np.concatenate([[0], np.cumsum(every)])

    def _serial_rows(self, offsets: np.ndarray, points: np.ndarray, whole: np.ndarray):
        """Local bond rows of the families of local ``points`` and their serial bond numbers."""
        counts = offsets[points + 1] - offsets[points]
        shift = np.repeat(whole[self.global_ids[points]] - offsets[points], counts)
        rows = np.repeat(offsets[points], counts) + _ranges(counts)
        return rows, rows + shift

    def gather_bonds(self, values: np.ndarray, offsets: np.ndarray, whole: np.ndarray):
        """Per-bond ``values`` of the owned families placed in the serial bond numbering on rank 0
        (None elsewhere); ``whole`` is ``bond_offsets(offsets)``. In one process ``values``."""
        if self.size == 1:
            return values
        rows, serial = self._serial_rows(offsets, np.arange(self.n_owned), whole)
        parts = self.comm.gather((serial, values[rows]))
        if not self.is_root:
            return None
        out = np.empty(int(whole[-1]), dtype=values.dtype)
        for idx, part in parts:
            out[idx] = part
        return out

    def scatter_bonds(self, values: np.ndarray, bonds, whole: np.ndarray) -> np.ndarray:
        """The local part ((n_bonds,) of ``bonds``) of per-bond ``values`` given in the serial
        numbering (``whole`` = ``bond_offsets``), for a bond value shared by both directed copies
        (e.g. ``intact``). The owned points' and their neighbours' families are whole on the rank
        and taken directly; an outer ghost's bond takes its reverse copy's value where that lies in
        such a family (a bond between two outer ghosts keeps its value, it enters no owned force).
        In one process ``values``."""
        if self.size == 1:
            return values
        offsets = bonds.offsets
        whole_family = np.zeros(len(self.global_ids), dtype=bool)
        whole_family[: self.n_owned] = True
        whole_family[bonds.neighbours[: offsets[self.n_owned]]] = True
        rows, serial = self._serial_rows(offsets, np.flatnonzero(whole_family), whole)
        out = bonds.intact.copy() if values.dtype == bool else np.zeros(bonds.n_bonds, dtype=values.dtype)
        out[rows] = values[serial]
        rev = bonds.reverse()
        owners = bonds.owners()
        outer = ~whole_family[owners] & whole_family[owners[rev]]
        out[outer] = out[rev[outer]]
        return out

    #: the keys of ``provenance``
    provenance_keys = ("mpi_ranks", "partition", "points_per_rank", "ghosts_per_rank")

    def provenance(self) -> dict:
        """Ranks, partition, and each rank's owned and ghost points, for the results file's
        provenance (collective)."""
        counts = self.comm.allgather((self.n_owned, len(self.global_ids) - self.n_owned))
        owned, ghosts = (list(c) for c in zip(*counts, strict=True))
        values = (self.size, self.partition, owned, ghosts)
        return dict(zip(self.provenance_keys, values, strict=True))

    def traffic_per_rank(self, earlier: Traffic, steps: int, seconds: float) -> list[dict]:
        """Every rank's communication in ``steps`` time steps (collective), one dict per rank.

        ``earlier`` is a copy of ``comm.traffic`` taken before the steps and ``seconds`` the
        rank's own wall time, s, in them. Keys: ``rank``, ``owned`` and ``ghosts`` (points),
        ``halo_neighbours`` (ranks it sends to), ``step_seconds`` (``seconds``),
        ``messages_per_step`` and ``bytes_per_step`` (sent), ``halo_seconds`` (in the halo
        exchanges), ``halo_wait_seconds`` (its part waiting for messages), ``collective_seconds``
        and ``halo_share`` (``halo_seconds / seconds``). Counts include the contact halo.
        """
        t = self.comm.traffic.since(earlier)
        per_step = 1.0 / max(int(steps), 1)
        mine = {
            "rank": self.comm.rank,
            "owned": self.n_owned,
            "ghosts": len(self.global_ids) - self.n_owned,
            "halo_neighbours": 0 if self.halo is None else len(self.halo.plan.send_ranks),
            "step_seconds": seconds,
            "messages_per_step": t.messages * per_step,
            "bytes_per_step": t.bytes * per_step,
            "halo_seconds": t.halo_seconds,
            "halo_wait_seconds": t.wait_seconds,
            "collective_seconds": t.collective_seconds,
            "halo_share": t.halo_seconds / seconds if seconds > 0 else 0.0,
        }
        return self.comm.allgather(mine)


def agree(comm, fn, *args):
    """``fn(*args)`` on every rank of ``comm``; if it raised on any rank, every rank raises (its
    own error, or the lowest failing rank's)."""
    try:
        result, error = fn(*args), None
    except Exception as exc:  # noqa: BLE001 - every error is shared, then raised
        result, error = None, exc
    if comm.size == 1:
        if error is not None:
            raise error
        return result
    _raise_any(comm.allgather(None if error is None else _portable(error)), error)
    return result


def _raise_any(errors: list, own: BaseException | None) -> None:
    """Raise ``own``, else the first error of ``errors`` (pickled), if any, marked ``every_rank``."""
    if own is not None:
        own.every_rank = True
        raise own
    for err in errors:
        if err is not None:
            error = pickle.loads(err)
            error.every_rank = True
            raise error


def failed_alone(error: BaseException, comm) -> None:
    """Mark ``error``, raised inside a time step on this rank of ``comm`` (several ranks), with
    ``failed_rank`` (this rank) unless every rank raised it (``every_rank``): no other rank
    knows of it."""
    if not getattr(error, "every_rank", False):
        error.failed_rank = comm.rank


def _portable(error: BaseException) -> bytes:
    """``error`` pickled, or a ``RankError`` with its message when it does not survive pickling."""
    try:
        data = pickle.dumps(error)
        pickle.loads(data)
        return data
    except Exception:  # noqa: BLE001 - exceptions with custom constructors
        return pickle.dumps(RankError(str(error)))


def _ranges(counts: np.ndarray) -> np.ndarray:
    """0, 1, ..., c_0 - 1, 0, 1, ..., c_1 - 1, ... for the ``counts`` c_k."""
    total = int(counts.sum())
    starts = np.repeat(np.cumsum(counts) - counts, counts)
    return np.arange(total) - starts
