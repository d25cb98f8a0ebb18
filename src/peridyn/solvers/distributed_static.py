"""Static equilibrium over MPI ranks: modified Newton steps, each solved by preconditioned CG.

A serial static run relaxes dynamically (``solvers.relaxation``). Under MPI the same equilibrium,
to the same criterion (the out-of-balance force on the free dofs below ``tolerance`` times the
larger of the applied load and the reactions, ``static._relative_residual``), is found by

    u <- u + du,    K0 du = V (f(u) + b)    on the free dofs,

with K0 the linearised stiffness of the reference configuration applied matrix-free on each
rank's own rows (``linalg.distributed.RankStiffness``), solved by conjugate gradients
preconditioned by each rank's AMG V-cycle (block Jacobi, ``rank_preconditioner``) with global
dot products by allreduce. f is the model's own (nonlinear) force, so the fixed point is the
serial equilibrium; the steps converge linearly at the rate of the geometric nonlinearity
(of the order of the strain), a few steps for elastic strains. Each CG solve stops when its
residual is below a third of what the criterion allows, so the last step is checked with the
true force.
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError
from peridyn.linalg.distributed import RankDofs, RankStiffness
from peridyn.linalg.krylov import pcg
from peridyn.physics.loads import Loading
from peridyn.solvers.relaxation import RelaxationResult

#: Share of the allowed out-of-balance force that each CG solve leaves.
INNER_SHARE = 1.0 / 3.0


def distributed_equilibrium(
    dofs: RankDofs,
    precond,
    loading: Loading,
    time: float = 0.0,
    u0: np.ndarray | None = None,
    tolerance: float = 1e-6,
    max_iterations: int = 200_000,
) -> RelaxationResult:
    """The static equilibrium of the rank's part under the loads at ``time`` (s) (collective).

    Parameters
    ----------
    dofs : RankDofs
        The rank's free dofs (held: ``loading.constrained``).
    precond : operator (n_free,) -> (n_free,), the rank's preconditioner.
    u0 : (n_local, 3) float64 or None, m
        Start (the previous load step's solution).
    tolerance : float
        Relative out-of-balance force to reach.
    max_iterations : int
        CG iterations allowed over all Newton steps.

    Returns a RelaxationResult with ``u`` (n_local, 3), m, ghost rows filled, and
    ``iterations`` the CG iterations.
    """
    if not tolerance > 0:
        raise InputError(f"relaxation tolerance must be positive, got {tolerance!r}")
    model, domain = dofs.model, dofs.domain
    n = model.body.n_points
    u = np.zeros((n, 3)) if u0 is None else np.array(u0, dtype=float)
    v = np.zeros((n, 3))
    loading.apply_initial(u, v)
    loading.apply_kinematics(time, 1.0, u, v)
    b = loading.body_force_density(time, np.zeros((n, 3)))
    K = RankStiffness(dofs)
    volume = model.body.volumes[dofs.dofs // 3]
    iterations = 0
    while True:
        f = _force(model, domain, u)
        out_of_balance, scale = _balance(dofs, f, b)
        if not np.isfinite(out_of_balance):
            raise InputError("static solve diverged (non-finite forces)")
        allowed = tolerance * scale
        if out_of_balance < allowed or iterations >= max_iterations:
            return RelaxationResult(u, out_of_balance / scale, iterations, out_of_balance < allowed)
        rhs = volume * (f + b).reshape(-1)[dofs.dofs]
        du, used = conjugate_gradients(
            K, precond, dofs, rhs, INNER_SHARE * allowed, volume, max_iterations - iterations
        )
        iterations += used
        u.reshape(-1)[dofs.dofs] += du


def conjugate_gradients(K, precond, dofs: RankDofs, rhs, target: float, volume, max_iterations: int):
    """x with ||(rhs - K x) / volume|| <= ``target`` by preconditioned CG from zero
    (``linalg.krylov.pcg``, inner products over every rank's dofs), or the last iterate after
    ``max_iterations``; returns (x, iterations) (collective).

    ``rhs`` (n_free,) N, ``volume`` (n_free,) m^3 (the residual is compared as a force density,
    N/m^3, as the equilibrium criterion is)."""
    result = pcg(
        lambda p: K @ p,
        lambda r: precond @ r,
        rhs,
        target,
        max_iterations,
        dot=lambda a, b: float(dofs.domain.allsum(a @ b)),
        residual_norm=lambda r: float(dofs.column_norms((r / volume)[:, None])[0]),
        agree=dofs.domain.max,
    )
    return result.x, result.iterations


def _force(model, domain, u: np.ndarray) -> np.ndarray:
    """The model's force density (n_local, 3), N/m^3, owned rows exact, at ``u`` (its ghost
    rows filled here; collective)."""
    domain.exchange(u)
    return np.asarray(model.force(u), dtype=float)


def _norms(dofs: RankDofs, f: np.ndarray, b: np.ndarray):
    """Global norms of the out-of-balance force on the free dofs, of the reactions (force on the
    other dofs) and of the load, over the owned rows (collective)."""
    n = dofs.domain.n_owned
    free = np.zeros(3 * n, dtype=bool)
    free[dofs.dofs] = True
    total = (f[:n] + b[:n]).reshape(-1)
    held = f[:n].reshape(-1)
    sums = np.array([total[free] @ total[free], held[~free] @ held[~free], np.sum(b[:n] * b[:n])])
    return np.sqrt(dofs.domain.allsum(sums))


def _balance(dofs: RankDofs, f, b) -> tuple[float, float]:
    """The out-of-balance force and the scale it is relative to (the larger of the load and the
    reactions; 1 when both vanish, as in serial), N/m^3 (collective)."""
    out_of_balance, reactions, load = _norms(dofs, f, b)
    scale = max(load, reactions)
    return float(out_of_balance), float(scale) if scale > 0 else 1.0
