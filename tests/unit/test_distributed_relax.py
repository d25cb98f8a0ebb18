"""Dynamic relaxation over simulated MPI ranks in one process (``solvers.relaxation.relax`` with a
``Domain``, issue 20 item 5): the ranks are threads that take turns, joined by a communicator
with MPI's semantics (``ThreadComm``: collectives and point-to-point messages, objects copied),
so the whole distributed path (the rank's part as ``setup.build`` makes it, the halo exchange,
the damage of the part, contact with its own ghosts, the ordered reductions) runs without
mpiexec. The runs under mpiexec are in tests/mpi/test_mpi_static.py.

Fact tested: every rank's owned rows of u, the intact flags of its owned families, the bonds
broken, the iterations and the residual equal the serial relaxation's bit for bit (each rank does
the serial per-point arithmetic on exact ghost values, and the two sums are taken in global
point order on rank 0).
"""

import pickle
import queue
import threading
from collections import defaultdict
from pathlib import Path

import numba
import numpy as np
import pytest

from peridyn.io.case import load_case
from peridyn.parallel.comm import Traffic
from peridyn.setup.build import build
from peridyn.solvers.relaxation import relax

CASES = Path(__file__).resolve().parents[2] / "cases"

#: seconds a simulated rank waits for the others before the test fails (instead of hanging)
TIMEOUT = 60.0


class _Group:
    """What the simulated ranks share: the turn (one rank computes at a time, so numba's thread
    pool is never entered by two ranks at once), a barrier, the collectives' slots and the
    point-to-point mailboxes."""

    def __init__(self, size: int):
        self.size = size
        self.turn = threading.Lock()
        self.barrier = threading.Barrier(size, timeout=TIMEOUT)
        self.slots = [None] * size
        self.boxes = defaultdict(queue.Queue)  # (source, dest, tag) -> queue of arrays
        self.boxes_lock = threading.Lock()

    def box(self, key) -> queue.Queue:
        with self.boxes_lock:
            return self.boxes[key]


class ThreadComm:
    """The ``MPIComm`` interface for a thread of ``_Group``: every object sent is copied (by
    pickling, as mpi4py's lower-case calls do), sums over the ranks in rank order."""

    def __init__(self, group: _Group, rank: int):
        self.group = group
        self.rank = rank
        self.size = group.size
        self.traffic = Traffic()

    def _waiting(self, wait):
        """``wait()`` with the turn given to the other ranks meanwhile."""
        self.group.turn.release()
        try:
            return wait()
        finally:
            self.group.turn.acquire()

    def _everyone(self, obj) -> list:
        """Every rank's ``obj`` (copied), in rank order, on every rank."""
        g = self.group
        g.slots[self.rank] = pickle.dumps(obj)
        self._waiting(g.barrier.wait)
        out = [pickle.loads(s) for s in g.slots]
        self._waiting(g.barrier.wait)
        return out

    def barrier(self) -> None:
        self._everyone(None)

    def bcast(self, obj, root: int = 0):
        return self._everyone(obj)[root]

    def gather(self, obj, root: int = 0):
        out = self._everyone(obj)
        return out if self.rank == root else None

    def allgather(self, obj) -> list:
        return self._everyone(obj)

    def gatherv(self, send: np.ndarray, recv, counts, root: int = 0) -> None:
        parts = self._everyone(np.ascontiguousarray(send))
        if self.rank == root:
            recv.reshape(-1)[...] = np.concatenate([part.reshape(-1) for part in parts])

    def alltoall(self, objs: list) -> list:
        return [sent[self.rank] for sent in self._everyone(objs)]

    def allreduce(self, value, op: str = "sum"):
        values = self._everyone(value)
        fn = {"sum": np.add, "max": np.maximum, "min": np.minimum}[op]
        out = values[0]
        for v in values[1:]:
            out = fn(out, v)
        return out if isinstance(value, np.ndarray) else type(value)(out)

    def isend(self, buf: np.ndarray, dest: int, tag: int):
        self.group.box((self.rank, dest, tag)).put(np.array(buf))
        return None

    def irecv(self, buf: np.ndarray, source: int, tag: int):
        return (buf, self.group.box((source, self.rank, tag)))

    def waitall(self, requests: list) -> None:
        for request in requests:
            if request is not None:
                buf, box = request
                buf[...] = self._waiting(lambda box=box: box.get(timeout=TIMEOUT))

    def abort(self, code: int = 1) -> None:
        self.group.barrier.abort()
        raise SystemExit(code)


def on_ranks(size: int, fn) -> list:
    """``fn(comm)`` on ``size`` simulated ranks (threads with a ``ThreadComm`` each), in rank
    order; an error on any rank is raised here (the others are released from their waits)."""
    group = _Group(size)
    results, errors = [None] * size, []

    def rank_body(rank):
        numba.set_num_threads(1)  # one numba thread per rank, as NUMBA_NUM_THREADS=1 under mpiexec
        with group.turn:
            try:
                results[rank] = fn(ThreadComm(group, rank))
            except BaseException as exc:  # noqa: BLE001 - re-raised in the test's thread
                errors.append(exc)
                group.barrier.abort()

    threads = [threading.Thread(target=rank_body, args=(r,)) for r in range(size)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if errors:
        raise errors[0]
    return results


def _precrack(height: float) -> str:
    """A pre-crack in the plane x = 20 mm through the bar's depth, from y = -1 mm over ``height`` m."""
    return (
        "precracks=[{type: rectangle, origin: [0.02, -0.001, -0.001], "
        f"edge_u: [0, {height}, 0], edge_v: [0, 0, 0.012]}}]"
    )


#: cases/bar_tension_static.yaml at 2 mm made to break bonds or touch (as tests/mpi/test_mpi_static.py)
BAR = ["discretization.spacing=2e-3"]
RUNS = {
    "lps_breaking": BAR + ["material.model=lps", "material.damage.critical_stretch=2.1e-5"],
    "notched": BAR + [_precrack(0.006), "material.damage.critical_stretch=8.5e-5"],
    "contact": BAR
    + [
        _precrack(0.012),
        "contact={radius: 1.0}",
        "boundary_conditions=[{set: clamp, kind: displacement, components: xyz, value: 0.0}, "
        "{set: loaded, kind: force, components: x, value: -100.0}]",
    ],
}


def _relax(setup, case, domain=None):
    s = case.solver
    return relax(
        setup.model,
        setup.loading,
        1.0,
        tolerance=s.tolerance,
        max_iterations=s.max_iterations,
        damage=setup.damage,
        contact=setup.contact,
        domain=domain,
    )


@pytest.fixture(autouse=True)
def one_numba_thread():
    """One numba thread in the test's own thread as in the ranks' (numba's count is per thread):
    with the serial reference run on more, its idle OpenMP workers slowed the simulated ranks
    tenfold on a loaded 2-core machine (measured: 65 s against 6 s)."""
    before = numba.get_num_threads()
    numba.set_num_threads(1)
    yield
    numba.set_num_threads(before)


@pytest.mark.bitwise
@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("run", list(RUNS))
def test_relaxation_on_simulated_ranks_is_the_serial_one(run, ranks):
    """Dynamic relaxation on 2 and 3 simulated ranks gives the serial iterations, residual, broken
    bonds, displacements and intact flags bit for bit: each rank computes its points with the serial
    operations in the serial order, and the global sums are taken over the whole body in global point
    order on rank 0 (``Domain.reduce``); the kernels are compiled without value-changing fast-math flags
    (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    case = load_case(CASES / "bar_tension_static.yaml", RUNS[run])
    whole = build(case, CASES)
    want = _relax(whole, case)
    assert want.converged
    offsets, intact = whole.bonds.offsets, whole.bonds.intact

    def rank_run(comm):
        setup = build(case, CASES, comm)
        result = _relax(setup, case, setup.domain)
        d = setup.domain
        n = d.n_owned
        return d.global_ids[:n], result, setup.bonds.intact[: setup.bonds.offsets[n]]

    owned_by = np.zeros(whole.body.n_points, dtype=int)
    for ids, got, got_intact in on_ranks(ranks, rank_run):
        assert (got.iterations, got.residual, got.broken_bonds) == (
            want.iterations,
            want.residual,
            want.broken_bonds,
        )
        assert got.converged
        np.testing.assert_array_equal(got.u[: len(ids)], want.u[ids])
        serial_bonds = np.concatenate([np.arange(offsets[i], offsets[i + 1]) for i in ids])
        np.testing.assert_array_equal(got_intact, intact[serial_bonds])
        owned_by[ids] += 1
    assert np.all(owned_by == 1)  # the ranks' parts cover the body once
    if run != "contact":
        assert want.broken_bonds > 0  # bonds did break (beyond any pre-crack)
