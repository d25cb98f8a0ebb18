"""Deflated preconditioned CG (``fatigue/pcg.py``; Saad, Yeung, Erhel and Guyomarc'h 2000).

Closed form: in exact arithmetic CG ends in as many iterations as the preconditioned operator
has distinct eigenvalues (on the right-hand side's support); deflating the eigenvectors of all
but one eigenvalue leaves one, so a single iteration solves the system.
"""

import numpy as np

from peridyn.fatigue.pcg import RecycledDirections, deflated_pcg


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
    result = deflated_pcg(lambda v: A @ v, lambda r: r, b, None, 1e-10, 50)
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
    result = deflated_pcg(lambda v: A @ v, lambda r: r, b, None, 1e-10, 50, basis)
    assert result.converged and result.iterations == 1
    assert np.linalg.norm(A @ result.x - b) <= 1e-10 * np.linalg.norm(b)


def test_recycled_directions_of_a_first_solve_speed_up_a_perturbed_second():
    """A second system differing by a small symmetric perturbation of the same outlier space: the
    first solve's search directions deflate it, so it needs fewer iterations, to the same residual."""
    A, outliers, b = _spectrum_matrix()
    first = deflated_pcg(lambda v: A @ v, lambda r: r, b, None, 1e-10, 50)
    A2 = A + 0.1 * outliers[:, :3] @ outliers[:, :3].T
    plain = deflated_pcg(lambda v: A2 @ v, lambda r: r, b, first.x, 1e-10, 50)
    kept = RecycledDirections(limit=40)
    kept.add(first.directions)
    recycled = deflated_pcg(
        lambda v: A2 @ v, lambda r: r, b, first.x, 1e-10, 50, kept.basis(lambda v: A2 @ v)
    )
    assert plain.converged and recycled.converged and recycled.iterations < plain.iterations
    assert np.linalg.norm(A2 @ recycled.x - b) <= 1e-10 * np.linalg.norm(b) * 1.0001


def test_kept_directions_are_capped_newest_last():
    kept = RecycledDirections(limit=3)
    kept.add([np.full(2, k) for k in range(5)])
    assert [v[0] for v in kept.vectors] == [2, 3, 4]
    kept.clear()
    assert kept.basis(lambda v: v) is None
