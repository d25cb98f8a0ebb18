"""Block V-cycle of the LOBPCG preconditioner (linalg.block_amg) and its aggregates.

References: pyamg's own V-cycle (``MultilevelSolver.aspreconditioner``) on the same hierarchy,
applied column by column, is the cycle the block version must reproduce; a V-cycle with
symmetric Gauss-Seidel pre/post-smoothing, R = P^T and an exact coarse solve is symmetric
positive definite for an SPD matrix (Vassilevski 2008, Multilevel Block Factorization
Preconditioners, ch. 5), which LOBPCG needs of its preconditioner (Knyazev 2001).
"""

import numpy as np
import pytest
import scipy.sparse as sp

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.linalg.amg import orthonormal, proxy_aggregates, proxy_stiffness, rigid_fields
from peridyn.linalg.block_amg import BlockVCycle, smoothed_aggregation_hierarchy
from peridyn.linalg.dofs import free_dofs
from peridyn.physics.materials import make_model

#: PMMA plate of VALIDATION.md V4 at 4 mm spacing (600 points), horizon 3.001 spacings.
SIZE, E, NU, RHO = (0.10, 0.05, 0.008), 5.35e9, 0.33, 1200.0


def _system(fixed_face=None, size=SIZE):
    body = geometry.box(size, 4e-3)
    bonds = find_bonds(body, 3.001 * 4e-3, partial_volumes=False)
    model = make_model("lps", body, bonds, E=E, nu=NU, density=RHO)
    fixed = None
    if fixed_face:
        fixed = np.zeros((body.n_points, 3), dtype=bool)
        fixed[geometry.face(body, fixed_face)] = True
    dofs = free_dofs(model, fixed)
    proxy = proxy_stiffness(model, dofs)
    m = np.repeat(RHO * body.volumes, 3)[dofs]
    a = (proxy + sp.diags(1e-6 * np.median(proxy.diagonal() / m) * m)).tocsr()
    near_null = orthonormal(rigid_fields(body.points)[dofs])
    return model, dofs, a, near_null


@pytest.mark.parametrize("aggregation", ["pyamg standard", "two-bond points"])
def test_block_v_cycle_equals_pyamgs_column_by_column(aggregation):
    """Nine columns at once give pyamg's V-cycle of each column to round-off (1e-10 of the
    largest entry: the coarse Cholesky and pyamg's pseudo-inverse differ by round-off times the
    coarse matrix's condition number, ~1e6 with the 1e-6 mass shift), on a three-level
    hierarchy (max_coarse 50) and on the two-level one of the two-bond aggregates."""
    model, dofs, a, near_null = _system()
    aggregates = proxy_aggregates(model, dofs) if aggregation == "two-bond points" else None
    hierarchy = smoothed_aggregation_hierarchy(a, near_null, aggregates, max_coarse=50)
    assert len(hierarchy.levels) >= 2
    v = np.random.default_rng(3).standard_normal((len(dofs), 9))
    pyamg_cycle = hierarchy.aspreconditioner(cycle="V")
    expected = np.column_stack([pyamg_cycle @ col for col in v.T])
    block = BlockVCycle(hierarchy)
    np.testing.assert_allclose(block(v), expected, rtol=0, atol=1e-10 * np.abs(expected).max())
    np.testing.assert_allclose(block(v[:, 4]), expected[:, 4], rtol=0, atol=1e-10 * np.abs(expected).max())


def test_block_v_cycle_is_symmetric_positive_definite_on_a_clamped_plate():
    """B = the cycle as a matrix (applied to the identity's columns) is symmetric to 1e-12 of
    its largest entry and its smallest eigenvalue is positive, on a 0.04 m long piece of the
    plate clamped at its x- face (the aggregates there have fewer free dofs than points)."""
    model, dofs, a, near_null = _system("x-", size=(0.04, 0.02, 0.008))
    hierarchy = smoothed_aggregation_hierarchy(a, near_null, proxy_aggregates(model, dofs), max_coarse=5)
    assert len(hierarchy.levels) >= 2
    block = BlockVCycle(hierarchy)
    matrix = block(np.eye(len(dofs)))
    scale = np.abs(matrix).max()
    assert np.abs(matrix - matrix.T).max() < 1e-12 * scale
    assert np.linalg.eigvalsh(0.5 * (matrix + matrix.T)).min() > 1e-10 * scale


def test_two_bond_aggregates_cover_every_free_dof_once_and_keep_points_whole():
    """Each free dof is in exactly one aggregate, the three dofs of a point share it, and an
    aggregate is local: pyamg's standard aggregation takes a root with the points up to two
    graph steps away, then joins each leftover point to an aggregate two steps from it, so a
    member is at most four short bonds (each at most one spacing along any axis on a grid)
    from its root: the extent along each axis is at most 8 spacings. Every aggregate has at
    least 2 points. Sums of ones and indices: compared exactly."""
    model, dofs, _, _ = _system()
    aggregates = proxy_aggregates(model, dofs)
    assert aggregates.shape[0] == len(dofs)
    np.testing.assert_array_equal(aggregates.sum(axis=1).A1, 1.0)
    owner = aggregates.tocsr().indices
    np.testing.assert_array_equal(owner.reshape(-1, 3), owner.reshape(-1, 3)[:, :1].repeat(3, 1))
    assert np.bincount(owner[::3]).min() >= 2
    x = model.body.points
    for agg in range(aggregates.shape[1]):
        members = x[np.flatnonzero(owner[::3] == agg)]
        assert np.all(np.ptp(members, axis=0) <= 8 * 4e-3 + 1e-12)


def test_two_bond_aggregates_do_not_cross_a_cut():
    """Cutting every bond across the plane x = 0.05 m (a through crack) leaves no aggregate
    with points on both sides."""
    model, dofs, _, _ = _system()
    x = model.body.points
    owners = model.bonds.owners()
    crossing = (x[owners, 0] < 0.05) != (x[model.bonds.neighbours, 0] < 0.05)
    model.bonds.intact[crossing] = False
    owner = proxy_aggregates(model, dofs).tocsr().indices[::3]
    left = x[:, 0] < 0.05
    for agg in np.unique(owner):
        side = left[owner == agg]
        assert side.all() or not side.any()
