"""The Newton and Newmark systems (K(u) + s M) du = r: LU and matrix-free CG agree, the choice
between them follows the estimated factor, and a factor too large is refused with its size."""

import numpy as np
import pytest
from conftest import small_model

import peridyn.linalg.tangent_solve as tangent_solve
from peridyn.errors import InputError
from peridyn.linalg.dofs import free_dofs
from peridyn.linalg.tangent_solve import TangentSolver, choose_linear_solver, factor_bytes


def _system(rng):
    """A 3D LPS cube of 6^3 points (horizon 3 spacings), stretched by 0.1% with 10 nm of noise,
    its x- face held, a random right-hand side (N)."""
    model = small_model("lps", 3, n=6)
    x = model.body.points
    u = 1e-3 * (x - x.mean(axis=0)) + 1e-8 * rng.standard_normal(x.shape)
    held = np.zeros_like(x, dtype=bool)
    held[x[:, 0] == x[:, 0].min()] = True
    free = free_dofs(model, held)
    return model, u, free, rng.standard_normal(len(free))


@pytest.mark.parametrize("mass_dominated", [False, True])
def test_matrix_free_cg_gives_the_lu_increment(rng, mass_dominated):
    """CG on the matrix-free tangent (AMG V-cycle without a mass shift; the mass diagonal with
    Newmark's 4 / dt^2 at 1 ns, far above the stiffness) solves the system the LU solves, to
    1e-9 of the increment (CG stops at 1e-12 of the residual; the condition number of the
    statics, ~1e3 here, bounds the error's growth)."""
    model, u, free, rhs = _system(rng)
    shift = 4.0 / 1e-9**2 if mass_dominated else 0.0
    direct = TangentSolver(model, "lu", shift).solve(u, free, rhs)
    krylov = TangentSolver(model, "cg", shift)
    du = krylov.solve(u, free, rhs)
    assert np.abs(du - direct).max() < 1e-9 * np.abs(direct).max()
    assert krylov.preconditioner_kind == ("mass" if mass_dominated else "amg")


def test_auto_factorises_a_small_body_and_refuses_a_factor_beyond_the_memory(monkeypatch, caplog):
    """``auto`` takes the LU when its estimated factor is under the budget (a 6^3 cube: about
    a megabyte); an explicit ``lu`` whose factor exceeds 70% of the memory is refused in one
    line naming the factor's size and the memory, and ``auto`` then takes CG, saying why in
    the log."""
    model = small_model("lps", 3, n=6)
    needed = factor_bytes(model)
    assert 0 < needed < tangent_solve.DIRECT_BUDGET
    assert choose_linear_solver(model, "auto") == "lu"
    monkeypatch.setattr(tangent_solve, "memory_limit", lambda: needed)
    with pytest.raises(InputError, match=r"sparse LU of this tangent would hold about .* GiB; 0 GiB here"):
        choose_linear_solver(model, "lu")
    with caplog.at_level("INFO", logger="peridyn.linalg.tangent_solve"):
        assert choose_linear_solver(model, "auto") == "cg"
    assert "linear solver: cg (the tangent's LU factor would take" in caplog.text
    with pytest.raises(InputError, match="unknown linear solver 'lsu'"):
        choose_linear_solver(model, "lsu")


def test_a_point_without_bonds_is_held_by_cg_as_by_lu(rng):
    """Statics (no mass shift): the dofs of a point whose bonds all broke have no stiffness;
    both solvers leave them at zero and agree on the rest."""
    model, u, free, rhs = _system(rng)
    lonely = int(np.argmin(np.linalg.norm(model.body.points - model.body.points.mean(axis=0), axis=1)))
    b = model.bonds
    model.bonds.intact[(b.owners() == lonely) | (b.neighbours == lonely)] = False
    direct = TangentSolver(model, "lu").solve(u, free, rhs)
    du = TangentSolver(model, "cg").solve(u, free, rhs)
    at_lonely = free // 3 == lonely
    assert at_lonely.sum() == 3 and not du[at_lonely].any() and not direct[at_lonely].any()
    assert np.abs(du - direct).max() < 1e-9 * np.abs(direct).max()
