"""Domain decomposition without mpiexec (``peridyn.parallel``): the partition, the ghost layers and
exchange plans of simulated ranks, the serial stand-in, and each simulated rank's part of a case
against the serial build (the runs under mpiexec are in ``tests/mpi``).

Facts and their sources: RCB splits a part of p ranks at floor(n (p // 2) / p) points
(``parallel/partition.py``), so part sizes differ by at most one point per level of cuts; the
ghosts are by definition the points within the search reach of an owned point (layer 1) or of a
layer-1 point (layer 2) that are not owned; bit-for-bit runs need every owned point's family, in
serial order, with identical per-bond and per-point coefficients and forces (issue 20).
"""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.distance import cdist
from test_distributed_relax import on_ranks

from peridyn.discretization import geometry
from peridyn.discretization.bonds import search_reach
from peridyn.discretization.pairs import index_bandwidth
from peridyn.discretization.state import State, runaway_limit
from peridyn.errors import InputError, InstabilityError
from peridyn.io.case import load_case
from peridyn.parallel.comm import SerialComm, launched_by_mpi
from peridyn.parallel.domain import Domain
from peridyn.parallel.halo import ghost_layers, plan_halo
from peridyn.parallel.partition import rcb
from peridyn.physics.materials.lps import LPSModel
from peridyn.setup.build import _build_part, build

CASES = Path(__file__).resolve().parents[2] / "cases"


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("parts", [1, 2, 3, 4, 7])
def test_rcb_owns_every_point_once_balanced_and_deterministic(dim, parts):
    """Recursive coordinate bisection gives each point one of ``parts`` ranks, balanced to a point per
    level of cuts, and the same parts from a copy of the coordinates: rank numbers, compared exactly."""
    body = (
        geometry.box((0.013, 0.007, 0.005), 1e-3)
        if dim == 3
        else geometry.rectangle(0.021, 0.008, 1e-3, thickness=1e-3)
    )
    part = rcb(body.points, parts)
    assert part.shape == (body.n_points,) and set(np.unique(part)) == set(range(parts))
    counts = np.bincount(part, minlength=parts)
    # one point of rounding per level of cuts (ceil(log2 p) levels)
    assert counts.max() - counts.min() <= max(1, int(np.ceil(np.log2(parts))))
    assert counts.sum() == body.n_points
    # deterministic: a copy of the coordinates (another process's) gives the same parts
    assert np.array_equal(part, rcb(body.points.copy(), parts))


def test_rcb_refuses_more_parts_than_points():
    with pytest.raises(InputError, match="cannot split 4 points into 5 parts"):
        rcb(np.zeros((4, 3)), 5)


def test_rcb_cuts_the_longest_side_first():
    body = geometry.rectangle(0.040, 0.004, 1e-3, thickness=1e-3)
    part = rcb(body.points, 2)
    x = body.points[:, 0]
    assert x[part == 0].max() < x[part == 1].min()


def _brute_ghosts(points, owned, reach, layers):
    taken = np.zeros(len(points), dtype=bool)
    taken[owned] = True
    frontier = owned
    for _ in range(layers):
        near = np.flatnonzero((cdist(points[frontier], points) <= reach).any(axis=0))
        frontier = near[~taken[near]]
        taken[frontier] = True
    taken[owned] = False
    return np.flatnonzero(taken)


@pytest.mark.parametrize("layers", [1, 2])
@pytest.mark.parametrize("horizon", [2.015e-3, None])
def test_ghosts_are_the_points_within_reach_not_owned(layers, horizon):
    """Also at a reach of exactly two spacings (None), where grid points lie at the reach. Point
    indices, compared exactly with a brute-force search: both decide with IEEE distances computed by
    scipy's compiled code, the same on every CPU."""
    body = geometry.rectangle(0.012, 0.009, 1e-3, thickness=1e-3)
    reach = 2e-3 if horizon is None else search_reach(body, horizon)
    part = rcb(body.points, 3)
    for rank in range(3):
        owned = np.flatnonzero(part == rank)
        ghosts = ghost_layers(body.points, owned, reach, layers)
        assert np.array_equal(ghosts, _brute_ghosts(body.points, owned, reach, layers))
        assert not np.isin(ghosts, owned).any()


class _Simulated:
    """A rank's communicator in a one-process simulation of ``size`` ranks: ``alltoall`` answers
    from the messages the other simulated ranks posted in a first pass."""

    def __init__(self, rank, size, posted):
        self.rank, self.size, self.posted = rank, size, posted

    def alltoall(self, objs):
        self.posted[self.rank] = objs
        return [self.posted[s][self.rank] if s in self.posted else [] for s in range(self.size)]


def test_halo_plans_send_each_ghost_from_its_owner_in_the_receiver_order():
    """Each rank's halo plan receives each ghost from its owner, into the rows of the receiver's ghost
    order: point indices, compared exactly."""
    body = geometry.box((0.010, 0.006, 0.004), 1e-3)
    size = 3
    part = rcb(body.points, size)
    reach = search_reach(body, 1.5e-3, partial_volumes=False)
    owned = [np.flatnonzero(part == r) for r in range(size)]
    ghosts = []
    for r in range(size):
        g = ghost_layers(body.points, owned[r], reach, 2)
        ghosts.append(g[np.lexsort((g, part[g]))])
    posted = {}
    for r in range(size):  # first pass posts every rank's requests
        plan_halo(_Simulated(r, size, posted), owned[r], ghosts[r], part[ghosts[r]])
    plans = [
        plan_halo(_Simulated(r, size, posted), owned[r], ghosts[r], part[ghosts[r]]) for r in range(size)
    ]
    for r, plan in enumerate(plans):
        local = np.concatenate([owned[r], ghosts[r]])
        assert plan.n_ghosts == len(ghosts[r])
        for source, (lo, hi) in zip(plan.recv_ranks, plan.recv_slices, strict=True):
            sender = plans[source]
            k = list(sender.send_ranks).index(r)
            sent = owned[source][sender.send_rows[k]]
            assert np.array_equal(sent, local[lo:hi])  # what arrives fills exactly these rows
        assert set(plan.recv_ranks) == set(np.unique(part[ghosts[r]]))


def test_serial_domain_reduces_like_numpy():
    """The serial domain's reductions are NumPy's own, so they round as a serial run does; the
    dot product is ``np.sum(a * b)`` (a pairwise sum in a fixed order, not a BLAS ``np.dot``,
    which may split the sum over threads), equal to ``np.dot`` to rounding."""
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=1001), rng.normal(size=1001)
    d = Domain.serial(1001)
    assert d.gather(a) is a
    assert d.sum(a) == np.sum(a) and d.dot(a, b) == np.sum(a * b)
    assert abs(d.dot(a, b) - np.dot(a, b)) <= 1e-12 * np.dot(np.abs(a), np.abs(b))
    assert d.reduce(lambda x, y: (np.sum(x), np.linalg.norm(y)), a, b) == (np.sum(a), np.linalg.norm(b))
    assert d.max(2.5) == 2.5 and d.count(7) == 7
    points = rng.normal(size=(1001, 3))
    assert d.runaway_limit(points) == runaway_limit(points)
    state = State(np.zeros((1001, 3)), np.zeros((1001, 3)), np.zeros((1001, 3)), 1e-6, 4)
    state.v[17, 1] = np.nan
    with pytest.raises(InstabilityError, match="point 17"):
        d.check_state(state, 1.0)
    with pytest.raises(ValueError, match="boom"):
        d.agree(_raise_value_error)


def _raise_value_error():
    raise ValueError("boom")


def test_launch_detection_reads_the_rank_count():
    assert launched_by_mpi({"PMI_SIZE": "3"}) and launched_by_mpi({"OMPI_COMM_WORLD_SIZE": "2"})
    assert not launched_by_mpi({"PMI_SIZE": "1"}) and not launched_by_mpi({})
    assert SerialComm().allreduce(3.0, "max") == 3.0


def test_serial_gatherv_fills_recv_whatever_its_layout():
    """One process: the gather is a copy into ``recv``, also a non-contiguous view (a copy made
    by a reshape would drop the values). A copy: compared exactly."""
    send = np.arange(6.0).reshape(3, 2)
    recv = np.zeros((2, 3)).T  # (3, 2), Fortran order
    SerialComm().gatherv(send, recv, [6])
    np.testing.assert_array_equal(recv, send)


@pytest.mark.parametrize(
    "owned", [[[4, 0, 2], [5, 1, 3]], [[0, 1, 2], [3, 4, 5]]], ids=["interleaved", "consecutive"]
)
def test_gather_many_puts_every_rank_s_rows_at_their_global_points(owned):
    """``Domain.gather_many`` on 2 simulated ranks: each rank's owned rows (ghost rows after them
    ignored) land at their global indices on rank 0, for (n, 3) float64 and (n,) bool arrays,
    whether the ranks own interleaved points or consecutive ranges (gathered straight into the
    result); copies, so compared exactly."""
    values = np.arange(18.0).reshape(6, 3) * 1.5
    flags = np.array([True, False, False, True, True, False])

    def gather(comm):
        ids = np.array(owned[comm.rank] + [9])  # one ghost row, global index 9: never gathered
        local = np.vstack([values, [[-1.0, -1.0, -1.0]] * 4])[ids]
        domain = Domain(comm, ids, 3, 6, None, "test")
        return domain.gather_many(local, np.append(flags, [False] * 4)[ids])

    whole, elsewhere = on_ranks(2, gather)
    assert elsewhere is None
    np.testing.assert_array_equal(whole[0], values)
    np.testing.assert_array_equal(whole[1], flags)


PARTS = [
    ("bar_pulse.yaml", ["geometry.size=[0.03, 0.008, 0.006]", "output.sensors={}", "output.lines={}"]),
    (
        "bar_pulse.yaml",
        [
            "geometry.size=[0.03, 0.008, 0.006]",
            "output.sensors={}",
            "output.lines={}",
            "material.surface_correction=energy",
        ],
    ),
    ("plate2d_stretch.yaml", []),
    ("plate2d_stretch.yaml", ["material.surface_correction=energy"]),
    (
        "bar_pulse.yaml",
        [
            "geometry.size=[0.03, 0.008, 0.006]",
            "output.sensors={}",
            "output.lines={}",
            "solver.dtype=float32",
        ],
    ),
    ("plate2d_stretch.yaml", ["solver.dtype=float32"]),
]


@pytest.mark.bitwise
@pytest.mark.parametrize(("name", "overrides"), PARTS)
@pytest.mark.parametrize("size", [2, 3])
def test_each_rank_part_matches_the_serial_build(name, overrides, size):
    """Owned families in serial order with identical coefficients, and the same force on the owned
    points from the same displacement (the kernels are unchanged: per-point arithmetic), also
    when the force of the rows clear of the ghosts is computed before the ghosts' u arrives. Bit for
    bit: a rank computes its points' coefficients and forces with the serial operations in the serial
    order, and the kernels are compiled without value-changing fast-math flags
    (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    case = load_case(CASES / name, overrides)
    whole = build(case, CASES)
    m, b = whole.model, whole.bonds
    u = np.random.default_rng(5).normal(scale=1e-6, size=(whole.body.n_points, 3))
    if whole.body.dim == 2:
        u[:, 2] = 0.0
    force = m.force(u)
    owned_by = np.full(whole.body.n_points, -1)
    # the parts are built one after the other here: the ranks' largest index bandwidth (the only
    # reduction of the build) is the whole body's
    bandwidth = index_bandwidth(b.offsets, b.neighbours)
    for rank in range(size):
        comm = SimpleNamespace(rank=rank, size=size, allreduce=lambda value, op: max(value, bandwidth))
        setup, owned, ghosts, ghost_owner, clear_rows = _build_part(case, comm, CASES)
        assert not (owned_by[owned] >= 0).any()
        owned_by[owned] = rank
        ids = np.concatenate([owned, ghosts])
        n, pb = len(owned), setup.bonds
        nb = pb.offsets[n]
        serial_bonds = np.concatenate([np.arange(b.offsets[i], b.offsets[i + 1]) for i in owned])
        assert np.array_equal(ids[pb.neighbours[:nb]], b.neighbours[serial_bonds])
        assert np.array_equal(pb.intact[:nb], b.intact[serial_bonds])
        for attr in ("bond_volume", "bond_stiffness", "w", "dev"):
            if hasattr(m, attr):
                assert np.array_equal(getattr(setup.model, attr)[:nb], getattr(m, attr)[serial_bonds]), attr
        assert np.array_equal(setup.model.stiffness_bound()[:n], m.stiffness_bound()[owned])
        local_force = setup.model.force(np.ascontiguousarray(u[ids]))
        assert np.array_equal(local_force[:n], force[owned])
        _assert_clear_rows(pb, n, clear_rows)
        # in each owner's block of ghosts, the ones an owned family holds (layer 1) come first
        held = np.zeros(len(ids), dtype=bool)
        held[pb.neighbours[:nb]] = True
        for r in np.unique(ghost_owner):
            block = held[n:][ghost_owner == r]
            assert not np.any(block[1:] & ~block[:-1]), "a layer-1 ghost after a layer-2 one"
        if isinstance(setup.model, LPSModel):  # the dilatation of the layer-2 ghosts is skipped
            assert setup.model._rows_read(n) == np.flatnonzero(held).max() + 1 < len(ids)
        if isinstance(setup.model, LPSModel) and setup.model.dtype == np.float64:
            assert setup.model._fused(clear_rows[1]) is not None  # the fused force before the halo
        assert np.array_equal(_overlapped_force(setup.model, u[ids], n, clear_rows)[:n], force[owned])
        assert np.array_equal(setup.loading.constrained, whole.loading.constrained[ids])
    assert (owned_by >= 0).all()


def _assert_clear_rows(bonds, n_owned: int, clear_rows: tuple) -> None:
    """The leading owned rows of ``clear_rows`` are what their name says: no ghost (row >= n_owned)
    in the families of the first ``clear_rows[0]`` rows, and only such rows in the families of the
    first ``clear_rows[1]``; and the prefixes are as long as can be (every later owned row's family
    breaks the rule)."""
    n1, n2 = clear_rows
    assert 0 < n2 <= n1 <= n_owned  # these parts are large enough to have an interior
    families = [bonds.neighbours[bonds.offsets[i] : bonds.offsets[i + 1]] for i in range(n_owned)]
    assert all(f.max() < n_owned for f in families[:n1])
    assert all(f.max() >= n_owned for f in families[n1:])
    assert all(f.max() < n1 for f in families[:n2])
    assert all(f.max() >= n1 for f in families[n2:n1])


def _overlapped_force(model, u: np.ndarray, n_owned: int, clear_rows: tuple) -> np.ndarray:
    """``model.force_overlapped`` with the ghost rows of u NaN until ``finish`` fills them: a row
    computed before would read a NaN and differ from the serial force."""
    pending = np.array(u, dtype=np.float64)
    pending[n_owned:] = np.nan
    arrived = []

    def finish():
        pending[n_owned:] = u[n_owned:]
        arrived.append(True)

    out = np.full((len(u), 3), np.nan, dtype=model.dtype)
    model.force_overlapped(pending, out, clear_rows, n_owned, finish)
    assert arrived == [True]
    return out
