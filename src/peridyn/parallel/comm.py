"""The communicator of a run: MPI's COMM_WORLD under ``mpiexec -n N`` (N > 1), a serial stand-in
otherwise.

Both expose the same small set of methods (rank, size, barrier, bcast, gather, allgather, a
typed gather of arrays (gatherv), alltoall, allreduce of numbers and arrays, and the
non-blocking point-to-point messages of the halo exchange), so that code written for ranks
runs unchanged in one process; a serial run never imports mpi4py. Each keeps a ``Traffic``
count of what it did (messages, bytes, seconds waiting), which a run reports per rank.
``world()`` picks one: MPI only when mpi4py imports and the environment shows an MPI launch
(``PMI_SIZE``, ``OMPI_COMM_WORLD_SIZE``, ``MPI_LOCALNRANKS`` ...).
"""

from __future__ import annotations

import functools
import os
import time
from dataclasses import dataclass, fields, replace

import numpy as np

#: Environment variables holding the number of ranks that MPI launchers set (MPICH/Hydra and
#: Intel MPI, Open MPI, MPICH's local count, Slurm).
LAUNCH_VARIABLES = ("PMI_SIZE", "OMPI_COMM_WORLD_SIZE", "MPI_LOCALNRANKS", "SLURM_NTASKS")


@dataclass
class Traffic:
    """What one rank's communicator has done so far.

    Attributes
    ----------
    messages : int
        Point-to-point messages sent (halo exchanges of the bonds and of contact).
    bytes : int
        Their payload, bytes.
    halo_seconds : float
        Wall time, s, in the halo exchanges' ``start`` (packing and posting) and ``finish``.
    wait_seconds : float
        The part of ``halo_seconds`` spent in ``finish``, waiting for the messages, s.
    collective_seconds : float
        Wall time, s, in collectives (barrier, bcast, gather, gatherv, allgather, alltoall,
        allreduce):
        their transfer and the wait for the slowest rank.
    """

    messages: int = 0
    bytes: int = 0
    halo_seconds: float = 0.0
    wait_seconds: float = 0.0
    collective_seconds: float = 0.0

    def since(self, earlier: Traffic) -> Traffic:
        """The traffic between ``earlier`` (a copy taken before) and now."""
        return Traffic(*(getattr(self, f.name) - getattr(earlier, f.name) for f in fields(self)))

    def copy(self) -> Traffic:
        return replace(self)


class SerialComm:
    """One process: every collective returns its own contribution."""

    rank = 0
    size = 1

    def __init__(self):
        #: nothing is ever sent: stays zero
        self.traffic = Traffic()

    def barrier(self) -> None:
        """Nothing to wait for."""

    def bcast(self, obj, root: int = 0):
        return obj

    def gather(self, obj, root: int = 0) -> list:
        return [obj]

    def allgather(self, obj) -> list:
        return [obj]

    def gatherv(self, send: np.ndarray, recv: np.ndarray | None, counts, root: int = 0) -> None:
        """``recv`` gets ``send``'s values (any layout of ``recv``; ``counts`` is one rank's)."""
        recv[...] = send.reshape(recv.shape)

    def alltoall(self, objs: list) -> list:
        return list(objs)

    def allreduce(self, value, op: str = "sum"):
        """``value`` itself (``op`` "sum", "max" or "min")."""
        return value

    def isend(self, buf: np.ndarray, dest: int, tag: int):
        raise RuntimeError("a serial run has no other rank to send to")

    def irecv(self, buf: np.ndarray, source: int, tag: int):
        raise RuntimeError("a serial run has no other rank to receive from")

    def waitall(self, requests: list) -> None:
        """No request can be pending."""

    def abort(self, code: int = 1) -> None:
        raise SystemExit(code)


class MPIComm:
    """A thin wrapper of an mpi4py communicator (``mpi4py.MPI.Comm``)."""

    def __init__(self, comm):
        from mpi4py import MPI

        self._mpi = MPI
        self._comm = comm
        self.rank = comm.Get_rank()
        self.size = comm.Get_size()
        self._ops = {"sum": MPI.SUM, "max": MPI.MAX, "min": MPI.MIN}
        #: messages, bytes and seconds of this rank (``Traffic``)
        self.traffic = Traffic()

    def _timed(self, call, *args, **kwargs):
        """``call(*args, **kwargs)``, its wall time added to ``traffic.collective_seconds``."""
        start = time.perf_counter()
        try:
            return call(*args, **kwargs)
        finally:
            self.traffic.collective_seconds += time.perf_counter() - start

    def barrier(self) -> None:
        self._timed(self._comm.Barrier)

    def bcast(self, obj, root: int = 0):
        return self._timed(self._comm.bcast, obj, root=root)

    def gather(self, obj, root: int = 0):
        """A list of every rank's ``obj`` on ``root``, None elsewhere."""
        return self._timed(self._comm.gather, obj, root=root)

    def allgather(self, obj) -> list:
        return self._timed(self._comm.allgather, obj)

    def gatherv(self, send: np.ndarray, recv: np.ndarray | None, counts, root: int = 0) -> None:
        """Every rank's contiguous array ``send`` into ``recv`` on ``root``, in rank order:
        ``counts`` (one per rank) values each, on ``root``; ``recv`` and ``counts`` are ignored
        elsewhere. No pickling: on 2 ranks a 21 000 x 3 float64 part took 0.32 ms against 0.84
        ms for ``gather`` (``benchmarks/HISTORY.md``, "Chunks of 32, ..., a cheaper recorder")."""
        spec = [recv, list(counts)] if self.rank == root else None
        self._timed(self._comm.Gatherv, send, spec, root=root)

    def alltoall(self, objs: list) -> list:
        return self._timed(self._comm.alltoall, objs)

    def allreduce(self, value, op: str = "sum"):
        """The reduction of a number or of a numpy array (element by element) over all ranks.

        Max and min are exact; a sum of floats depends on the order of the ranks, so results
        that must equal a serial run's are gathered and summed in point order instead."""
        if isinstance(value, np.ndarray):
            out = np.empty_like(value)
            self._timed(self._comm.Allreduce, np.ascontiguousarray(value), out, op=self._ops[op])
            return out
        return self._timed(self._comm.allreduce, value, op=self._ops[op])

    def isend(self, buf: np.ndarray, dest: int, tag: int):
        """Post the send of ``buf``, counted in ``traffic`` (messages, bytes)."""
        self.traffic.messages += 1
        self.traffic.bytes += buf.nbytes
        return self._comm.Isend(buf, dest=dest, tag=tag)

    def irecv(self, buf: np.ndarray, source: int, tag: int):
        return self._comm.Irecv(buf, source=source, tag=tag)

    def waitall(self, requests: list) -> None:
        self._mpi.Request.Waitall(requests)

    def abort(self, code: int = 1) -> None:
        self._comm.Abort(code)


def launched_by_mpi(environ=None) -> bool:
    """True when the environment shows an MPI launch with more than one rank."""
    env = os.environ if environ is None else environ
    for name in LAUNCH_VARIABLES:
        value = env.get(name, "")
        if value.isdigit() and int(value) > 1:
            return True
    return False


@functools.cache
def world():
    """COMM_WORLD wrapped (``MPIComm``) under an MPI launch of more than one rank when mpi4py
    imports, else a ``SerialComm`` (the same object at every call)."""
    if not launched_by_mpi():
        return SerialComm()
    try:
        from mpi4py import MPI
    except ImportError:
        return SerialComm()
    comm = MPIComm(MPI.COMM_WORLD)
    return comm if comm.size > 1 else SerialComm()
