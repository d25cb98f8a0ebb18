"""A rank's part of a grid body on lattice storage (``peridyn.parallel.lattice_domain``), built on
simulated ranks in one process (``ThreadComm``: MPI's semantics, threads taking turns): each
rank holds the points of its slab of grid planes across x and of 2 r ghost planes either side
(r the stencil's reach across x), its owned forces are the serial lattice forces bit for bit,
and the broken words go to the whole grid's layout and back unchanged (checkpoints). The runs
under ``mpiexec`` are ``tests/mpi/test_mpi_lattice.py``.
"""

import threading
from pathlib import Path

import numpy as np
import pytest
from test_distributed_relax import on_ranks

from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import load_case
from peridyn.parallel.lattice_domain import slab_bounds
from peridyn.setup import build as build_module
from peridyn.setup import slab_body
from peridyn.setup.build import build
from peridyn.setup.grid_points import grid_points
from peridyn.setup.solver_choice import time_stepper

ROOT = Path(__file__).resolve().parents[2]

#: PMB in 2D with a pre-crack and a no-damage set; LPS in 3D (the bar cut to 30 x 6 x 6 mm)
CASES = {
    "plate2d_stretch": ["discretization.storage=lattice"],
    "bar_pulse": [
        "discretization.storage=lattice",
        "geometry.size=[0.03, 0.006, 0.006]",
        "output.sensors={}",
        "output.lines={}",
    ],
}


def test_slabs_split_the_planes_evenly_and_need_a_plane_per_rank():
    """Rank r owns planes bounds[r] .. bounds[r + 1] - 1: every plane once, counts within one."""
    bounds = slab_bounds(81, 3)
    assert bounds.tolist() == [0, 27, 54, 81]
    counts = np.diff(slab_bounds(10, 4))
    assert counts.sum() == 10 and counts.max() - counts.min() <= 1
    with pytest.raises(InputError, match="at most 2 ranks"):
        slab_bounds(2, 3)


@pytest.mark.bitwise
@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("name", sorted(CASES))
def test_a_rank_holds_its_slab_and_ghost_planes_and_computes_the_serial_forces(name, ranks):
    """Each rank's points are those of its planes (owned) and of the 2 r planes either side within
    the grid (ghosts); the ranks own every point once; the force of its owned points at a random
    displacement (ghost rows the owners' values) equals the serial lattice force bit for bit
    (the pre-crack's bits are the serial ones and every owned point's family is whole)."""
    path = ROOT / "cases" / f"{name}.yaml"
    case = load_case(path, CASES[name])
    whole = build(case, path.parent)
    lattice = whole.bonds
    nx = int(lattice.shape[0])
    plane = lattice.grid_index % nx  # of each body point
    u = 1e-6 * np.random.default_rng(5).standard_normal((whole.body.n_points, 3))
    want = whole.model.force(u).copy()
    reach = int(np.abs(lattice.stencil.offsets[:, 0]).max())

    def part(comm):
        setup = build(case, path.parent, comm)
        d = setup.domain
        f = setup.model.force(u[d.global_ids])
        return d.global_ids, d.n_owned, f[: d.n_owned], setup.bonds.n_broken(d.owned)

    bounds = slab_bounds(nx, ranks)
    parts = on_ranks(ranks, part)
    owned_every = np.concatenate([ids[:n] for ids, n, _, _ in parts])
    assert np.array_equal(np.sort(owned_every), np.arange(whole.body.n_points))
    for r, (ids, n, f, _) in enumerate(parts):
        lo, hi = bounds[r], bounds[r + 1]
        first, stop = max(0, lo - 2 * reach), min(nx, hi + 2 * reach)
        assert np.array_equal(ids[:n], np.flatnonzero((plane >= lo) & (plane < hi)))
        ghost = (plane >= first) & (plane < stop) & ~((plane >= lo) & (plane < hi))
        assert np.array_equal(np.sort(ids[n:]), np.flatnonzero(ghost))
        assert np.array_equal(f, want[ids[:n]])
    assert sum(b for *_, b in parts) == lattice.n_broken()  # the pre-crack's bits, once each


def test_broken_words_go_to_the_whole_grid_and_back():
    """Each rank's broken words (local planes) are the whole grid's at those planes after
    ``scatter_bonds``, and ``gather_bonds`` of the owned planes gives the whole grid's words back
    on rank 0 (the checkpoint's layout is the serial one)."""
    path = ROOT / "cases" / "plate2d_stretch.yaml"
    case = load_case(path, CASES["plate2d_stretch"])
    whole = build(case, path.parent).bonds
    words = np.random.default_rng(7).integers(0, 2**63, size=whole.broken.size, dtype=np.uint64)
    nx = int(whole.shape[0])

    def part(comm):
        setup = build(case, path.parent, comm)
        d = setup.domain
        flat = setup.bonds.broken.reshape(-1)
        every = d.bond_offsets(None)
        flat[:] = d.scatter_bonds(words, setup.bonds, every)
        return d.slab, setup.bonds.broken.copy(), d.gather_bonds(flat, None, every)

    for slab, local, back in on_ranks(3, part):
        grid = words.reshape(whole.broken.shape[0], -1, nx)
        assert np.array_equal(
            local.reshape(grid.shape[0], -1, slab.stop - slab.first), grid[..., slab.first : slab.stop]
        )
        if back is not None:
            assert np.array_equal(back, words)


def test_a_rank_whose_planes_hold_no_point_is_refused_on_every_rank():
    """A removal across the whole width of the plate (planes 27 to 53 of 81) leaves the middle
    rank of 3 no point: every rank raises the error naming it (``agree``), none waits for the
    others."""
    path = ROOT / "cases" / "plate2d_stretch.yaml"
    gap = "removals=[{type: box, min: [3.4e-3, -1, -1], max: [6.7e-3, 1, 1]}]"
    case = load_case(path, [*CASES["plate2d_stretch"], gap, "precracks=[]"])
    with pytest.raises(InputError, match="rank 1's planes across x .* hold no point"):
        on_ranks(3, lambda comm: build(case, path.parent, comm))


@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("name", sorted(CASES))
def test_a_rank_other_than_the_first_never_makes_the_whole_grid(name, ranks, monkeypatch):
    """The points a rank holds come from its planes alone (``setup.slab_body``): every grid it
    makes is a range of planes across x (its share of the counting pass, its slab with its
    ghost planes, one plane for the stencil), the largest its slab and ghost planes, fewer
    points than the whole body; only rank 0 makes the whole body (the recorder's). What the
    ranks hold is checked above: their slabs and ghosts, the serial forces."""
    path = ROOT / "cases" / f"{name}.yaml"
    case = load_case(path, CASES[name])
    whole = build(case, path.parent)
    nx = int(whole.bonds.shape[0])
    per_plane = whole.body.n_points // nx  # no removal in these cases
    reach = int(np.abs(whole.bonds.stencil.offsets[:, 0]).max())
    made = {}  # thread -> [(planes, points made)]

    def recording(case, planes=None):
        body = grid_points(case, planes)
        made.setdefault(threading.get_ident(), []).append((planes, body.n_points))
        return body

    monkeypatch.setattr(slab_body, "grid_points", recording)
    monkeypatch.setattr(build_module, "grid_points", recording)
    ranks_of = dict(
        on_ranks(ranks, lambda comm: (threading.get_ident(), build(case, path.parent, comm).domain))
    )
    bounds = slab_bounds(nx, ranks)
    for thread, domain in ranks_of.items():
        r = domain.comm.rank
        first, stop = max(0, bounds[r] - 2 * reach), min(nx, bounds[r + 1] + 2 * reach)
        calls = made[thread]
        if r == 0:
            assert (None, whole.body.n_points) in calls
            continue
        assert all(planes is not None for planes, _ in calls)
        assert max(n for _, n in calls) == (stop - first) * per_plane == len(domain.global_ids)
        assert (stop - first) * per_plane < whole.body.n_points


#: removals (the notches), a box set and a face set (placed by the whole body's bounds)
NOTCHED = [
    "discretization.spacing=1e-3",
    "discretization.storage=lattice",
    "node_sets.back={type: face, face: x+}",
    "removals=[{type: box, min: [-0.001, 0.07425, -1], max: [0.050, 0.07575, 1]}, "
    "{type: face, face: y+, depth: 0.006}]",
]


@pytest.mark.parametrize("ranks", [2, 3])
def test_planes_made_apart_are_the_whole_bodys_points_and_sets(ranks):
    """A slab made from its planes alone (``setup.slab_body``) has the whole body's points,
    volumes and numbers, and the node sets' points, bit for bit, with removals and faces (a
    face removal placed by the grid before removals, a face set by the body after them, as
    ``build_body`` places them on the whole body)."""
    path = ROOT / "cases" / "kalthoff_winkler.yaml"
    case = load_case(path, NOTCHED)
    whole = build_module.build_body(case, path.parent)

    def planes(comm):
        plan = slab_body.grid_plan(case, comm)
        bounds = slab_bounds(int(plan.shape[0]), comm.size)
        lo, hi = int(bounds[comm.rank]), int(bounds[comm.rank + 1])
        part, ids = slab_body.slab_points(case, plan, lo, hi)
        part = build_module._slab_node_sets(case, part, plan, comm, part.n_points)
        return plan, part, ids

    parts = on_ranks(ranks, planes)
    assert np.array_equal(np.concatenate([ids for _, _, ids in parts]), np.arange(whole.n_points))
    plan = parts[0][0]
    assert plan.n_points == whole.n_points
    assert np.array_equal(plan.origin, whole.points.min(axis=0))
    for _, part, ids in parts:
        assert np.array_equal(part.points, whole.points[ids])
        assert np.array_equal(part.volumes, whole.volumes[ids])
        for name in ("back", "impact", "all"):
            assert np.array_equal(ids[part.node_sets[name]], np.intersect1d(whole.node_sets[name], ids))
    assert sum(len(p.node_sets["back"]) for _, p, _ in parts) == len(whole.node_sets["back"]) > 0


def test_a_set_that_no_rank_holds_a_point_of_is_refused_as_in_one_process():
    """The emptiness of a node set is decided over the ranks, with the serial error."""
    path = ROOT / "cases" / "plate2d_stretch.yaml"
    case = load_case(
        path, [*CASES["plate2d_stretch"], "node_sets.away={type: box, min: [9, 9, -1], max: [10, 10, 1]}"]
    )
    with pytest.raises(CaseFileError) as serial:
        build(case, path.parent)
    with pytest.raises(CaseFileError) as ranked:
        on_ranks(2, lambda comm: build(case, path.parent, comm))
    assert str(ranked.value) == str(serial.value)


def test_a_region_of_listed_points_makes_the_whole_body_first():
    """Point numbers name the whole body's points (``slab_refusals``): such a case is made whole
    on every rank, then cut; each rank holds the set's points of its slab and ghosts."""
    path = ROOT / "cases" / "plate2d_stretch.yaml"
    case = load_case(
        path, [*CASES["plate2d_stretch"], "node_sets.listed={type: points, indices: [0, 7, 100]}"]
    )
    assert slab_body.slab_refusals(case) == ["a region of listed point numbers"]
    domains = on_ranks(2, lambda comm: (lambda s: (s.domain, s.body))(build(case, path.parent, comm)))
    owned = [
        d.global_ids[body.node_sets["listed"][body.node_sets["listed"] < d.n_owned]] for d, body in domains
    ]
    assert sorted(np.concatenate(owned).tolist()) == [0, 7, 100]


@pytest.mark.parametrize("name", sorted(CASES))
def test_a_ranks_float64_lattice_force_is_written_into_its_acceleration(name):
    """As in one process, a rank's float64 lattice force needs no array of its own (24 B a
    point, ``ExplicitSolver``): the lattice force overwrites every row of the part, ghosts
    included (with and without the overlap of the ghost exchange: bar_pulse, no damage, and
    plate2d_stretch, bonds breaking). The runs stay bit for bit (tests/mpi/test_mpi_lattice.py)."""
    path = ROOT / "cases" / f"{name}.yaml"
    case = load_case(path, CASES[name])
    solvers = on_ranks(2, lambda comm: time_stepper(case, build(case, path.parent, comm)))
    assert [s._force is None for s in solvers] == [True, True]
    assert [s.overlap for s in solvers] == [name == "bar_pulse"] * 2
