"""Quasi-static equilibrium by adaptive dynamic relaxation (Kilic and Madenci 2010).

Fictitious diagonal density lambda_i = (1/4) dt^2 s_i with dt = 1 and s_i the
model's stiffness bound (``Model.stiffness_bound``), which makes the
fictitious explicit integration stable. Each iteration n:

    a = (f(u) + b) / lambda;
    v <- ((2 - c dt) v + 2 dt a) / (2 + c dt)   (first iteration: v = dt a / 2);
    u <- u + dt v;
    c = 2 sqrt(u^T K_loc u / u^T u),  K_loc,ii = -(f_i^n - f_i^(n-1)) / (lambda_i dt v_i),

the damping c tracking the lowest frequency of the current state. Converged
when the out-of-balance force on the free DOFs is below ``tolerance`` times
the larger of the applied load and the reactions. With contact, f includes the
short-range forces and s_i their stiffness bound (``Contact.stiffness_bound``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from peridyn import interrupts
from peridyn.errors import InputError
from peridyn.physics.contact import Contact
from peridyn.physics.damage import BondDamage
from peridyn.physics.loads import Loading
from peridyn.physics.materials.base import Model


@dataclass
class RelaxationResult:
    """Outcome of a relaxation.

    Attributes
    ----------
    u : (n_points, 3) float64, m
    residual : float
        Relative out-of-balance force at the end.
    iterations : int
    converged : bool
    broken_bonds : int
    """

    u: np.ndarray
    residual: float
    iterations: int
    converged: bool
    broken_bonds: int = 0


def relax(
    model: Model,
    loading: Loading,
    time: float = 0.0,
    u0: np.ndarray | None = None,
    tolerance: float = 1e-6,
    max_iterations: int = 200_000,
    damage: BondDamage | None = None,
    check_every: int = 20,
    contact: Contact | None = None,
) -> RelaxationResult:
    """Find the static equilibrium under the loads evaluated at ``time`` (s).

    Parameters
    ----------
    u0 : (n_points, 3) float64 or None
        Starting displacement (m), e.g. the previous load step's solution.
    tolerance : float
        Relative residual force to reach.
    damage : BondDamage or None
        If given, bonds break as the body relaxes.
    contact : Contact or None
        Short-range forces between unbonded points, added to the model's force.
    """
    if not tolerance > 0:
        raise InputError(f"relaxation tolerance must be positive, got {tolerance!r}")
    n = model.body.n_points
    u = np.zeros((n, 3)) if u0 is None else np.array(u0, dtype=float)
    v = np.zeros((n, 3))
    loading.apply_initial(u, v)
    v[:] = 0.0
    loading.apply_kinematics(time, 1.0, u, v)
    v[:] = 0.0
    free = ~loading.constrained
    free[:, model.body.dim :] = False
    bound = model.stiffness_bound()
    if contact is not None:
        bound = bound + contact.stiffness_bound()
    lam = np.repeat((0.25 * bound)[:, None], 3, axis=1)

    def internal_force(u):
        f = np.asarray(model.force(u), dtype=float)
        return contact.add_force(u, f) if contact is not None else f

    b = loading.body_force_density(time, np.zeros((n, 3)))
    f = internal_force(u)
    f_prev = f.copy()
    c = 0.0
    broken = 0
    residual = np.inf
    for it in range(1, max_iterations + 1):
        interrupts.check(where="relaxing to equilibrium")
        r = (f + b) * free
        a = r / lam
        if it == 1:
            v = 0.5 * a
        else:
            v = ((2.0 - c) * v + 2.0 * a) / (2.0 + c)
        v *= free
        u += v
        if damage is not None:
            broken += damage.update(u)
        f_prev, f = f, internal_force(u)
        moving = np.abs(v) > 0
        k_loc = np.zeros_like(u)
        k_loc[moving] = -(f[moving] - f_prev[moving]) / (lam[moving] * v[moving])
        num = np.sum(u * k_loc * u)
        den = np.sum(u * u)
        c = 2.0 * np.sqrt(num / den) if num > 0 and den > 0 else 0.0
        c = min(c, 1.9)
        if it % check_every == 0:
            residual = _relative_residual(f, b, free)
            if not np.isfinite(residual):
                raise InputError("relaxation diverged (non-finite forces)")
            if residual < tolerance:
                return RelaxationResult(u, residual, it, True, broken)
    return RelaxationResult(u, _relative_residual(f, b, free), max_iterations, False, broken)


def _relative_residual(f: np.ndarray, b: np.ndarray, free: np.ndarray) -> float:
    out_of_balance = np.linalg.norm((f + b)[free])
    reactions = np.linalg.norm(f[~free])
    scale = max(np.linalg.norm(b), reactions)
    return float(out_of_balance / scale) if scale > 0 else float(out_of_balance)
