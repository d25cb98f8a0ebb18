"""Static equilibrium of the fatigue loop (``fatigue/statics.py``) after bonds break.

Physical check: the displacement must satisfy K u = F on the free dofs of the *damaged* body, with
K the stiffness assembled independently from the current bonds (``stiffness.assemble_stiffness``)
and F the applied loads; a direct sparse solve of that system is the reference. The tolerance is
the one the fatigue model needs (module docstring of ``fatigue.statics``): equilibrium residual
1e-8 relative, bond strains to 1e-6 of the largest strain.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.errors import InputError
from peridyn.fatigue.model import bond_strain
from peridyn.fatigue.statics import SHIFT, LinearStatics
from peridyn.linalg.stiffness import assemble_stiffness
from peridyn.physics.loads import BoundaryCondition, Loading
from peridyn.physics.materials import make_model
from peridyn.physics.timefunctions import Constant

SPACING = 1e-3
LENGTH, WIDTH, DEPTH = 0.016, 0.006, 0.003  # m: a small steel bar, 16 x 6 x 3 points


def _notched_bar(load: str):
    """LPS steel bar (V5 material), left end clamped; the right end pulled by 10 um
    (``load="displacement"``, its y and z held) or by a 2 kN axial force (``load="force"``)."""
    body = geometry.box((LENGTH, WIDTH, DEPTH), SPACING)
    x = body.points
    body = body.with_node_set("left", x[:, 0] < 1.1 * SPACING)
    body = body.with_node_set("right", x[:, 0] > LENGTH - 1.1 * SPACING)
    bonds = find_bonds(body, 1.5001 * SPACING)
    model = make_model("lps", body, bonds, E=189.9e9, nu=0.3, density=7850.0)
    bcs = [BoundaryCondition("left", "displacement", "xyz", Constant(0.0))]
    if load == "displacement":
        bcs += [
            BoundaryCondition("right", "displacement", "x", Constant(1e-5)),
            BoundaryCondition("right", "displacement", "yz", Constant(0.0)),
        ]
    else:
        bcs += [BoundaryCondition("right", "force", "x", Constant(2e3))]
    return model, Loading(body, bcs)


def _cut(model, depth_points: int):
    """Break every bond crossing the plane x = LENGTH / 2 below y = depth_points spacings
    (an edge crack; both halves of each bond)."""
    x = model.body.points
    b = model.bonds
    xi, xj = x[b.owners()], x[b.neighbours]
    mid = 0.5 * LENGTH
    crossing = (np.minimum(xi[:, 0], xj[:, 0]) < mid) & (np.maximum(xi[:, 0], xj[:, 0]) > mid)
    low = np.maximum(xi[:, 1], xj[:, 1]) < depth_points * SPACING
    b.intact[crossing & low] = False


def _direct_solution(model, loading, statics):
    """Reference: spsolve of the assembled (K + shift I) u = F on the free dofs, the bonds as now;
    also returns the equilibrium residual function of the assembled K."""
    K = assemble_stiffness(model)
    free = statics.free
    u = statics.u_prescribed.ravel().copy()
    rhs = (statics.force - K @ u)[free]
    k_ff = K[free][:, free] + sp.identity(len(free)) * statics.shift
    u[free] = spsolve(k_ff.tocsc(), rhs)

    def residual(v):
        return np.linalg.norm(rhs - k_ff @ v.ravel()[free]) / np.linalg.norm(rhs)

    return u.reshape(-1, 3), residual


def _check_equal_to_direct(model, loading, statics, u):
    """The damaged body's equilibrium residual (assembled K) is below rtol and the bond strains
    match the direct solve's to 1e-6 of the largest strain."""
    u_ref, residual = _direct_solution(model, loading, statics)
    assert residual(u) < 1e-8
    strain, strain_ref = bond_strain(model, u), bond_strain(model, u_ref)
    intact = model.bonds.intact
    assert np.abs(strain - strain_ref)[intact].max() < 1e-6 * np.abs(strain_ref[intact]).max()


@pytest.mark.parametrize("load", ["displacement", "force"])
def test_old_factorisation_preconditions_the_damaged_body_to_the_direct_solution(load):
    """One factorisation of the intact bar; after an edge crack of 3 spacings (a low-rank change
    of K) the next solve reuses it as CG preconditioner: a few iterations, no refactorisation,
    and the displacement satisfies the damaged body's equilibrium (direct solve as reference)."""
    model, loading = _notched_bar(load)
    statics = LinearStatics(model, loading)
    u0 = statics.solve()
    _check_equal_to_direct(model, loading, statics, u0)
    assert statics.records[0].factorised and statics.records[0].iterations <= 2
    _cut(model, 3)
    assert (~model.bonds.intact).sum() > 0
    u1 = statics.solve()
    _check_equal_to_direct(model, loading, statics, u1)
    second = statics.records[1]
    assert not second.factorised and 2 <= second.iterations < 30 and second.residual < 1e-8
    # the crack softens the bar: the crack mouth opens (the right end moves more under the force)
    assert np.abs(u1 - u0).max() > 1e-3 * np.abs(u0).max()


def test_recycled_directions_cut_the_iterations_of_a_growing_crack():
    """An edge crack grown 1, 2, 3, 4 spacings deep with one factorisation of the intact bar: with
    the earlier solves' directions recycled (deflated CG) every solve still reaches the damaged
    body's equilibrium, and the later ones need fewer iterations than without (measured: 7, 7, 8
    against 9, 12, 14)."""
    iterations = {}
    for recycle in (0, 80):
        model, loading = _notched_bar("displacement")
        statics = LinearStatics(model, loading, recycle=recycle)
        statics.solve()
        for depth in (1, 2, 3, 4):
            _cut(model, depth)
            _check_equal_to_direct(model, loading, statics, statics.solve())
        assert sum(r.factorised for r in statics.records) == 1
        iterations[recycle] = [r.iterations for r in statics.records[2:]]
    assert all(a < b for a, b in zip(iterations[80], iterations[0], strict=True))


def test_iterations_past_the_threshold_refactorise_and_still_reach_equilibrium():
    """With refactor_iterations = 2, a deeper crack (4 of 6 spacings) cannot be resolved by the old
    factorisation in two iterations: K is factorised again and the solve still equals the direct one."""
    model, loading = _notched_bar("displacement")
    statics = LinearStatics(model, loading, refactor_iterations=2)
    statics.solve()
    _cut(model, 4)
    u = statics.solve()
    assert statics.records[1].factorised
    _check_equal_to_direct(model, loading, statics, u)


def test_jacobi_cg_reaches_the_same_equilibrium():
    """The factorisation-free route (method "cg") gives the damaged body's equilibrium too."""
    model, loading = _notched_bar("displacement")
    _cut(model, 3)
    statics = LinearStatics(model, loading, method="cg")
    u = statics.solve()
    assert not statics.records[0].factorised and statics.records[0].iterations > 10
    _check_equal_to_direct(model, loading, statics, u)


@pytest.mark.parametrize("load", ["displacement", "force"])
def test_amg_preconditioner_of_the_intact_bar_solves_the_damaged_one(load):
    """AMG route: one V-cycle on the intact bar's pair proxy preconditions every solve; after an
    edge crack of 3 spacings (half the section at once) it is kept (rebuild threshold raised)
    and the displacement still satisfies the damaged body's equilibrium to rtol, bond strains as
    the direct solve's to 1e-6. Measured: 12 then 26 iterations (displacement), 16 then 33 (force)."""
    model, loading = _notched_bar(load)
    statics = LinearStatics(model, loading, method="amg", refactor_iterations=100)
    _check_equal_to_direct(model, loading, statics, statics.solve())
    _cut(model, 3)
    _check_equal_to_direct(model, loading, statics, statics.solve())
    first, second = statics.records
    assert first.factorised and not second.factorised
    assert second.iterations < 40 and second.residual < 1e-8


def test_stale_amg_preconditioner_is_rebuilt_and_the_solve_still_reaches_equilibrium():
    """Default threshold (30): the force-loaded bar cut through half its section needs more with
    the intact bar's proxy (33 measured), so the V-cycle is rebuilt on the cut bonds mid-solve and
    the solve still equals the direct one."""
    model, loading = _notched_bar("force")
    statics = LinearStatics(model, loading, method="amg")
    statics.solve()
    _cut(model, 3)
    u = statics.solve()
    assert statics.records[1].factorised
    _check_equal_to_direct(model, loading, statics, u)


def test_auto_factorises_small_systems_and_uses_amg_above_the_threshold(monkeypatch):
    """``auto``: direct up to DIRECT_DOFS free dofs (the bar: 16 x 6 x 3 points, both end columns
    held, 252 x 3 = 756 free dofs), AMG above (threshold lowered below the bar's dofs)."""
    from peridyn.fatigue import statics as module

    model, loading = _notched_bar("displacement")
    statics = LinearStatics(model, loading)
    assert len(statics.free) == 756 and statics.method == "direct"
    monkeypatch.setattr(module, "DIRECT_DOFS", 100)
    assert LinearStatics(model, loading).method == "amg"


def test_shift_is_a_tiny_fraction_of_the_stiffness():
    """The regularising shift is SHIFT (1e-9) of the mean diagonal stiffness of the intact body."""
    model, loading = _notched_bar("force")
    statics = LinearStatics(model, loading)
    diagonal = assemble_stiffness(model).diagonal()[statics.free]
    assert statics.shift == pytest.approx(SHIFT * diagonal.mean(), rel=1e-12)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"method": "lu"}, "linear solver must be auto, amg, direct or cg, got 'lu'"),
        ({"rtol": 0.0}, "rtol must be in (0, 1), got 0.0"),
        ({"refactor_iterations": 0}, "refactor_iterations must be at least 1, got 0"),
        ({"recycle": -1}, "recycle (directions kept between solves) must be >= 0, got -1"),
    ],
)
def test_bad_solver_settings_are_refused(kwargs, message):
    model, loading = _notched_bar("displacement")
    with pytest.raises(InputError, match=message.replace("(", r"\(").replace(")", r"\)")):
        LinearStatics(model, loading, **kwargs)
