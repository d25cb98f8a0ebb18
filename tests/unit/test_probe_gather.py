"""The series records of an MPI run gather only the probe points (issue 20): ``PointGather`` on
simulated ranks in one process, the recorder's ``Probes`` and ``ProbeState`` path against its
whole-state path, and the whole-body check from the ranks' parts (``Domain.check_state``).

Facts and their sources: a gather copies values, so the values placed on rank 0 are the owners'
bit for bit, in the order asked (``parallel/points.py``); a rank's owned rows are in clearance
order, not global order, and its ghost rows are copies that must never be read (``Domain``);
``record_series`` writes the same records from the whole state and from the values at its
probe points (``io/recorder.py``: one code path, two row maps); the serial ``check_state``
names the first field out of bounds (u before v) at its first point in global order.
"""

import h5py
import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.discretization.state import ProbeState, State, check_state
from peridyn.errors import InstabilityError
from peridyn.io.recorder import LineProbe, Probes, Recorder, RecorderSpec
from peridyn.parallel.domain import Domain
from peridyn.parallel.partition import rcb
from peridyn.parallel.points import PointGather


class _Gathering:
    """A rank's communicator in a one-process simulation of ``size`` ranks: rank 0's ``gather``,
    ``gatherv`` and ``allgather`` answer from what the other ranks posted before it (call rank 0
    last); the others' ``allgather`` answers from the previous round."""

    def __init__(self, rank, size, posted):
        self.rank, self.size, self.posted = rank, size, posted

    def gather(self, obj, root=0):
        self.posted[self.rank] = obj
        return [self.posted[r] for r in range(self.size)] if self.rank == root else None

    def gatherv(self, send, recv, counts, root=0):
        self.posted.setdefault(("gatherv", self.rank), []).append(send.copy())
        if self.rank == root:
            sent = [self.posted[("gatherv", r)].pop(0) for r in range(self.size)]
            assert [a.size for a in sent] == counts  # MPI's Gatherv needs the counts right
            recv.reshape(-1)[:] = np.concatenate([a.reshape(-1) for a in sent])

    def allgather(self, obj):
        self.posted[self.rank] = obj
        return [self.posted.get(r) for r in range(self.size)]

    def bcast(self, obj, root=0):
        return obj


def _simulated_domains(body, size, rng):
    """One ``Domain`` per simulated rank, rank 0 last: owned rows in a shuffled order (as the
    clearance order is not the global one), then a few ghosts (other ranks' points)."""
    part = rcb(body.points, size)
    posted, domains = {}, {}
    for rank in [*range(1, size), 0]:
        owned = rng.permutation(np.flatnonzero(part == rank))
        ghosts = np.flatnonzero(part != rank)[:7]
        ids = np.concatenate([owned, ghosts])
        domains[rank] = Domain(_Gathering(rank, size, posted), ids, len(owned), body.n_points, None, "rcb")
    return domains


def _ranks_last_root(domains):
    return [domains[r] for r in [*range(1, len(domains)), 0]]


@pytest.mark.parametrize("size", [2, 3])
def test_point_gather_places_the_owners_values_in_the_order_asked(size):
    """A ``PointGather`` on simulated ranks places the owners' values of the asked points (repeats and
    any order included) on rank 0: copied values, compared exactly."""
    body = geometry.box((0.010, 0.006, 0.004), 1e-3)
    n = body.n_points
    rng = np.random.default_rng(11)
    u, v = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    ids_u = np.concatenate([rng.choice(n, 40), np.arange(3, n, 5), [0, 0, n - 1]])  # repeats, any order
    ids_v = rng.choice(n, 4)
    domains = _simulated_domains(body, size, rng)
    gathers = {d.comm.rank: PointGather(d, ids_u, ids_v) for d in _ranks_last_root(domains)}
    for d in _ranks_last_root(domains):
        local_u, local_v = u[d.global_ids], v[d.global_ids]
        local_u[d.n_owned :] = np.nan  # ghost rows: never read
        local_v[d.n_owned :] = np.nan
        got = gathers[d.comm.rank](local_u, local_v)
        assert (got is None) == (d.comm.rank != 0)
    got_u, got_v = got
    assert np.array_equal(got_u, u[ids_u]) and np.array_equal(got_v, v[ids_v])


def test_point_gather_refuses_a_point_no_rank_owns():
    body = geometry.box((0.006, 0.004, 0.003), 1e-3)
    domains = _simulated_domains(body, 2, np.random.default_rng(2))
    PointGather(domains[1], np.array([1, body.n_points]))
    with pytest.raises(ValueError, match="position 1 is owned by 0 ranks"):
        PointGather(domains[0], np.array([1, body.n_points]))


def test_serial_point_gather_reads_the_points():
    """In one process the gather reads the asked rows: copied values, compared exactly."""
    d = Domain.serial(20)
    a = np.arange(60.0).reshape(20, 3)
    (got,) = PointGather(d, np.array([4, 2, 4]))(a)
    assert np.array_equal(got, a[[4, 2, 4]])


def _spec(body):
    top = np.flatnonzero(body.points[:, 2] == body.points[:, 2].max())
    pzt = top[:6]
    weights = np.random.default_rng(4).normal(size=(len(pzt), 2))
    return RecorderSpec(
        every=1,
        sensors={"a": (0.002, 0.002, 0.004), "b": (0.0055, 0.0, 0.0)},
        lines={"axis": LineProbe((0.0, 0.002, 0.004), (0.009, 0.002, 0.004), 13)},
        planes={"top": top},
        pzt_sensors={"p": (pzt, weights)},
        series_dtype="float32",
        vtu=False,
    )


def test_probe_state_records_equal_the_whole_state_records(tmp_path):
    """The series recorded from a ``ProbeState`` (the probes' rows only) are those recorded from the
    whole state: the same rows copied and stored, compared exactly."""
    body = geometry.box((0.010, 0.006, 0.005), 1e-3)
    spec = _spec(body)
    probes = Probes.of(body, spec)
    assert list(probes.index) == ["sensor_u", "line_axis", "plane_top", "pzt_p"]
    for key, rows in probes.slices.items():
        assert np.array_equal(probes.u_points[rows], probes.index[key])
    rng = np.random.default_rng(8)
    whole = Recorder(body, tmp_path / "whole", spec, {})
    probed = Recorder(body, tmp_path / "probes", spec, {}, probes=probes)
    for step in range(3):
        state = State(*(rng.normal(scale=1e-6, size=(body.n_points, 3)) for _ in range(3)), 1e-7 * step, step)
        whole.record_series(state)
        probe = ProbeState(state.u[probes.u_points], state.v[probes.v_points], state.time, state.step)
        probed.record_series(probe)
    for recorder in (whole, probed):
        recorder.close()
    with (
        h5py.File(tmp_path / "whole" / "results.h5") as a,
        h5py.File(tmp_path / "probes" / "results.h5") as b,
    ):
        names = [n for n in a["series"] if n != "field_u"]
        assert names == ["line_axis", "plane_top", "pzt_signal", "sensor_u", "sensor_v"]
        for name in names:
            for part in ("data", "step", "time"):
                want, got = a[f"series/{name}/{part}"][()], b[f"series/{name}/{part}"][()]
                assert want.dtype == got.dtype and np.array_equal(want, got), (name, part)
        assert len(a["series/sensor_u/step"]) == 3


@pytest.mark.parametrize("size", [2, 3])
def test_rank_checks_raise_the_serial_error_on_every_rank(size):
    body = geometry.box((0.010, 0.006, 0.004), 1e-3)
    n = body.n_points
    state = State(np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3)), 2e-6, 9)
    state.v[5, 0] = np.inf  # v is checked after u: the runaway u below is the one named
    state.u[[n - 3, 17, n // 2], 1] = [2e3, np.nan, 3e3]
    with pytest.raises(InstabilityError) as serial:
        check_state(state, 1.0)
    domains = _simulated_domains(body, size, np.random.default_rng(1))
    domains[0].comm.posted.clear()  # the domains' own gathers are no findings
    raised = []
    for round_ in range(2):  # in the second, every rank has seen every rank's finding
        for d in _ranks_last_root(domains):
            local = State(state.u[d.global_ids], state.v[d.global_ids], state.a[d.global_ids], 2e-6, 9)
            local.u[d.n_owned :] = np.nan  # ghost rows: not the ranks' to check
            try:
                d.check_state(local, 1.0)
            except InstabilityError as exc:
                raised.append((round_, str(exc)))
    assert [text for r, text in raised if r == 1] == [str(serial.value)] * size
    assert "point 17" in str(serial.value)
