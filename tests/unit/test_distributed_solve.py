"""The distributed stiffness and LOBPCG (linalg.distributed, solvers.distributed_eigen) in one
process, where the Domain is the serial stand-in (the same code runs on each MPI rank; the
multi-rank runs are in tests/mpi/test_mpi_solve.py).

References: K applied as the serial block operator (linalg.block_operator, itself checked
against the assembled stiffness); the modes of the serial shift-invert Lanczos (solvers.modal,
VALIDATION.md V4); issue 20 item 5 asks the same frequencies to 1e-6 relative.
"""

from pathlib import Path

import numpy as np
import pytest

from peridyn.analysis.modes import mac_matrix
from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.linalg.amg import rigid_body_modes
from peridyn.linalg.block_operator import block_stiffness_operator
from peridyn.linalg.distributed import RankDofs, RankStiffness
from peridyn.linalg.dofs import free_dofs
from peridyn.parallel.domain import Domain
from peridyn.physics.materials import make_model
from peridyn.solvers.distributed_eigen import distributed_modes
from peridyn.solvers.modal import modal_analysis

#: the 4 mm grid rounds the 50 mm side to 48 mm (12 cells), as in test_modal_iterative
pytestmark = pytest.mark.filterwarnings("ignore:the spacing does not divide the body")

#: PMMA plate of VALIDATION.md V4 (m, Pa, -, kg/m^3) at 4 mm (600 points).
SIZE, E, NU, RHO = (0.10, 0.05, 0.008), 5.35e9, 0.33, 1200.0


def _plate(spacing=4e-3, horizon=3.001):
    body = geometry.box(SIZE, spacing)
    bonds = find_bonds(body, horizon * spacing, partial_volumes=False)
    return make_model("lps", body, bonds, E=E, nu=NU, density=RHO)


def _clamped(model):
    """The x- face held (every dof of the points at the smallest x)."""
    fixed = np.zeros((model.body.n_points, 3), dtype=bool)
    fixed[model.body.points[:, 0] == model.body.points[:, 0].min()] = True
    return fixed


@pytest.fixture(scope="module")
def plate():
    return _plate()


def test_rank_stiffness_is_the_serial_block_operator(plate):
    """On the serial domain the rank's rows are all rows: K v equal to the block operator's to
    round-off (the same kernel and order: exactly)."""
    fixed = _clamped(plate)
    dofs = RankDofs(plate, Domain.serial(plate.body.n_points), fixed)
    np.testing.assert_array_equal(dofs.dofs, free_dofs(plate, fixed))
    v = np.random.default_rng(1).standard_normal((len(dofs.dofs), 4))
    want = block_stiffness_operator(plate, dofs.dofs) @ v
    np.testing.assert_allclose(RankStiffness(dofs) @ v, want, rtol=0, atol=1e-12 * np.abs(want).max())


@pytest.mark.parametrize("clamped", [False, True])
def test_rigid_body_modes_span_the_serial_ones(plate, clamped):
    """Free: six rigid motions; clamped face: none (linalg.amg.rigid_body_modes)."""
    fixed = _clamped(plate) if clamped else None
    dofs = RankDofs(plate, Domain.serial(plate.body.n_points), fixed)
    got = dofs.rigid_body_modes()
    want = rigid_body_modes(plate.body.points, dofs.dofs)
    assert got.shape == want.shape == (len(dofs.dofs), 0 if clamped else 6)
    np.testing.assert_allclose(got.T @ got, np.eye(got.shape[1]), atol=1e-12)
    if got.shape[1]:  # the same subspace: the projection of one on the other is the identity
        np.testing.assert_allclose(np.linalg.svd(got.T @ want, compute_uv=False), 1.0, atol=1e-10)


@pytest.mark.parametrize("clamped", [False, True])
def test_distributed_lobpcg_gives_the_serial_modes(plate, clamped):
    """Elastic frequencies equal to the shift-invert ones to 1e-6 relative, mode shapes with MAC
    above 0.999, every residual below 1e-6 (issues 9 and 20)."""
    fixed = _clamped(plate) if clamped else None
    result, stats = distributed_modes(RankDofs(plate, Domain.serial(plate.body.n_points), fixed), 10)
    ref = modal_analysis(plate, 10, fixed=fixed)
    assert result.n_rigid == ref.n_rigid == (0 if clamped else 6)
    assert stats["iterations"] > 0
    e = ~ref.rigid
    np.testing.assert_allclose(result.frequencies[e], ref.frequencies[e], rtol=1e-6)
    mac = mac_matrix(ref.elastic().shapes, result.elastic().shapes, RHO * plate.body.volumes)
    assert np.diag(mac).min() > 0.999
    assert np.all(result.residuals < 1e-6)


@pytest.mark.parametrize("material", ["pmb", "lps"])
def test_distributed_equilibrium_meets_the_serial_criterion(material):
    """Modified Newton with CG (solvers.distributed_static) on the clamped bar of
    cases/bar_tension_static.yaml at 2 mm: the serial model's out-of-balance force at its
    displacement, relative to the larger of load and reactions (solvers.relaxation), is below the
    case's tolerance, as dynamic relaxation's; and the end displacements agree to 100 times that
    tolerance (1e-7): both solves are within the tolerance of the same equilibrium (measured:
    2.6e-7 PMB, 2.0e-7 LPS apart, and the CG one within 1.2e-9 of a relaxation to 1e-9)."""
    from peridyn.io.case import load_case
    from peridyn.linalg.distributed import rank_preconditioner
    from peridyn.setup.build import build
    from peridyn.solvers.distributed_static import distributed_equilibrium
    from peridyn.solvers.relaxation import _relative_residual, relax

    root = Path(__file__).resolve().parents[2] / "cases"
    case = load_case(
        root / "bar_tension_static.yaml", ["discretization.spacing=2e-3", f"material.model={material}"]
    )
    setup = build(case, root)
    model, loading = setup.model, setup.loading
    dofs = RankDofs(model, Domain.serial(model.body.n_points), loading.constrained)
    tol = case.solver.tolerance
    got = distributed_equilibrium(dofs, rank_preconditioner(dofs), loading, 1.0, tolerance=tol)
    want = relax(model, loading, 1.0, tolerance=tol)
    assert got.converged and want.converged
    b = loading.body_force_density(1.0, np.zeros((model.body.n_points, 3)))
    free = ~loading.constrained
    assert _relative_residual(np.asarray(model.force(got.u), dtype=float), b, free) < tol
    end = model.body.points[:, 0] == model.body.points[:, 0].max()
    np.testing.assert_allclose(got.u[end, 0].mean(), want.u[end, 0].mean(), rtol=100 * tol)


@pytest.mark.parametrize(
    ("case_file", "overrides", "refused"),
    [
        ("bar_tension_static.yaml", ["solver.type=newton"], "newton run"),
        ("pmma_plate.yaml", ["solver.eigensolver=shift-invert"], "solver.eigensolver"),
    ],
)
def test_what_an_mpi_run_cannot_do_is_refused_before_the_build(case_file, overrides, refused):
    """Newton runs and shift-invert (a factor of the whole body) are refused under MPI with one
    clear error (setup.solver_choice.check_parallel), before anything is built or written."""
    from peridyn.errors import PeridynError
    from peridyn.io.case import load_case
    from peridyn.setup.solver_choice import check_parallel

    case = load_case(Path(__file__).resolve().parents[2] / "cases" / case_file, overrides)
    with pytest.raises(PeridynError, match=refused):
        check_parallel(case)


@pytest.mark.parametrize(
    ("case_file", "overrides"),
    [
        ("plate2d_stretch.yaml", ["solver.type=static"]),
        ("plate2d_cyclic.yaml", ["solver.type=static"]),
    ],
)
def test_static_mpi_runs_with_damage_or_contact_are_accepted(case_file, overrides):
    """Static runs with bond breaking (plate2d_stretch) and with contact as well
    (plate2d_cyclic) run under MPI by dynamic relaxation on each rank's part: not refused."""
    from peridyn.io.case import load_case
    from peridyn.setup.solver_choice import check_parallel

    case = load_case(Path(__file__).resolve().parents[2] / "cases" / case_file, overrides)
    assert case.material.damage is not None
    check_parallel(case)


def test_relax_with_damage_leaves_every_intact_bond_within_its_critical_stretch():
    """Dynamic relaxation with bond breaking (solvers.relaxation.relax, the code every MPI rank runs)
    on the clamped bar of cases/bar_tension_static.yaml at 2 mm with a pre-crack to mid-height at
    mid-length and a critical stretch of 8.5e-5 (below the elastic solution's 9.1e-5 at the crack
    tip): it converges with bonds broken beyond the pre-crack's, every intact bond's deformed
    length at the end within its critical length |xi| (1 + s_c) (bonds are tested at every
    iterate), both copies of every broken bond broken, and ``broken_bonds`` the bonds it broke. Intact
    flags (booleans): compared exactly."""
    from peridyn.io.case import load_case
    from peridyn.setup.build import build
    from peridyn.solvers.relaxation import relax

    root = Path(__file__).resolve().parents[2] / "cases"
    precrack = (
        "precracks=[{type: rectangle, origin: [0.02, -0.001, -0.001], edge_u: [0, 0.006, 0], "
        "edge_v: [0, 0, 0.012]}]"
    )
    overrides = ["discretization.spacing=2e-3", precrack, "material.damage.critical_stretch=8.5e-5"]
    setup = build(load_case(root / "bar_tension_static.yaml", overrides), root)
    bonds = setup.bonds
    cut = int((~bonds.intact).sum())
    model, loading, damage = setup.model, setup.loading, setup.damage
    result = relax(model, loading, 1.0, tolerance=1e-7, max_iterations=20_000, damage=damage)
    assert result.converged
    assert result.broken_bonds == int((~bonds.intact).sum()) - cut > 0
    assert np.array_equal(bonds.intact, bonds.intact[bonds.reverse()])
    x, u, i, j = setup.body.points, result.u, bonds.owners(), bonds.neighbours
    length = np.linalg.norm(x[j] - x[i], axis=1)
    deformed = np.linalg.norm(x[j] + u[j] - x[i] - u[i], axis=1)
    assert np.all(deformed[bonds.intact] <= length[bonds.intact] * (1 + 8.5e-5) * (1 + 1e-12))
