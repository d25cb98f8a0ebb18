"""The Krylov solvers (``linalg/krylov.py``): deflated preconditioned CG (Saad, Yeung, Erhel and
Guyomarc'h 2000) and scipy's CG with a Jacobi or AMG preconditioner.

Closed form: in exact arithmetic CG ends in as many iterations as the preconditioned operator
has distinct eigenvalues (on the right-hand side's support); deflating the eigenvectors of all
but one eigenvalue leaves one, so a single iteration solves the system.
"""

import numpy as np
import pytest
import scipy.sparse as sp

from peridyn.errors import InputError
from peridyn.linalg.krylov import RecycledDirections, pcg, solve_spd


def _deflated(matvec, b, x0, maxiter, deflation=None):
    """Unpreconditioned CG to 1e-10 of ||b||, keeping its search directions."""
    target = 1e-10 * np.linalg.norm(b)
    return pcg(matvec, lambda r: r, b, target, maxiter, x0=x0, deflation=deflation, keep_directions=True)


def _spectrum_matrix(seed=0):
    """SPD (200, 200): eigenvalue 1 (x 190) and 10 outliers 3..30, random eigenvectors."""
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.standard_normal((200, 200)))
    lam = np.ones(200)
    lam[:10] = np.linspace(3.0, 30.0, 10)
    return (Q * lam) @ Q.T, Q[:, :10], rng.standard_normal(200)


def test_cg_needs_one_iteration_per_distinct_eigenvalue():
    """11 distinct eigenvalues: plain CG converges in 11 iterations, not fewer than 10."""
    A, _, b = _spectrum_matrix()
    result = _deflated(lambda v: A @ v, b, None, 50)
    assert result.converged and 10 <= result.iterations <= 11
    assert np.linalg.norm(A @ result.x - b) <= 1e-10 * np.linalg.norm(b) * 1.0001


def test_deflating_the_outliers_leaves_one_eigenvalue_and_one_iteration():
    """W = the 10 outlier eigenvectors: the deflated operator has the single eigenvalue 1."""
    A, outliers, b = _spectrum_matrix()
    kept = RecycledDirections(limit=10)
    kept.add(list(outliers.T))
    basis = kept.basis(lambda v: A @ v)
    W, AW = basis
    assert np.allclose(W.T @ AW, np.eye(10), atol=1e-12)
    result = _deflated(lambda v: A @ v, b, None, 50, deflation=basis)
    assert result.converged and result.iterations == 1
    assert np.linalg.norm(A @ result.x - b) <= 1e-10 * np.linalg.norm(b)


def test_recycled_directions_of_a_first_solve_speed_up_a_perturbed_second():
    """A second system differing by a small symmetric perturbation of the same outlier space: the
    first solve's search directions deflate it, so it needs fewer iterations, to the same residual."""
    A, outliers, b = _spectrum_matrix()
    first = _deflated(lambda v: A @ v, b, None, 50)
    A2 = A + 0.1 * outliers[:, :3] @ outliers[:, :3].T
    plain = _deflated(lambda v: A2 @ v, b, first.x, 50)
    kept = RecycledDirections(limit=40)
    kept.add(first.directions)
    recycled = _deflated(lambda v: A2 @ v, b, first.x, 50, deflation=kept.basis(lambda v: A2 @ v))
    assert plain.converged and recycled.converged and recycled.iterations < plain.iterations
    assert np.linalg.norm(A2 @ recycled.x - b) <= 1e-10 * np.linalg.norm(b) * 1.0001


def test_kept_directions_are_capped_newest_last():
    kept = RecycledDirections(limit=3)
    kept.add([np.full(2, k) for k in range(5)])
    assert [v[0] for v in kept.vectors] == [2, 3, 4]
    kept.clear()
    assert kept.basis(lambda v: v) is None


def test_inner_products_split_over_parts_give_the_whole_solve():
    """The dot products and the norm of the stop given by the caller, as an MPI run gives them
    (each a sum of per-rank parts): split into two halves summed in order, they are the whole
    vectors' to rounding, so the solve ends in the same iterations at the same solution."""
    A, _, b = _spectrum_matrix()
    half = len(b) // 2

    def split_dot(u, v):
        return float(u[:half] @ v[:half] + u[half:] @ v[half:])

    whole = _deflated(lambda v: A @ v, b, None, 50)
    split = pcg(
        lambda v: A @ v,
        lambda r: r,
        b,
        1e-10 * np.linalg.norm(b),
        50,
        dot=split_dot,
        residual_norm=lambda r: np.sqrt(split_dot(r, r)),
    )
    assert split.converged and split.iterations == whole.iterations
    np.testing.assert_allclose(split.x, whole.x, rtol=1e-9)  # the solve's own tolerance


@pytest.mark.parametrize("preconditioner", ["jacobi", "amg"])
def test_scipy_cg_solves_a_poisson_system_to_its_tolerance(preconditioner):
    """A 3D Laplacian (7-point, 12^3 unknowns, SPD): scipy's CG with either preconditioner
    reaches ||b - A x|| <= 1e-10 ||b||, as its stop promises."""
    n = 12
    lap = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    A = sp.kronsum(sp.kronsum(lap, lap), lap).tocsr()
    b = np.random.default_rng(1).standard_normal(n**3)
    x = solve_spd(A, b, 1e-10, preconditioner)
    assert np.linalg.norm(b - A @ x) <= 1e-10 * np.linalg.norm(b) * 1.0001


def test_scipy_cg_that_cannot_converge_is_an_error_and_an_unknown_preconditioner_is_named():
    """The stiffness of a free chain is singular (rigid translation); a load with a net force
    has no solution, so CG cannot reach its tolerance: one line naming the cure. A misspelt
    preconditioner is named."""
    n = 40
    free_chain = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n)).tolil()
    free_chain[0, 0] = free_chain[-1, -1] = 1.0
    with pytest.raises(InputError, match="use linear_solver 'lu'"):
        solve_spd(free_chain.tocsr(), np.ones(n), 1e-12)
    with pytest.raises(InputError, match="unknown preconditioner 'ilu'"):
        solve_spd(sp.identity(3).tocsr(), np.ones(3), 1e-12, "ilu")
