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

Under MPI (``relax(..., domain=...)``) each rank relaxes its own points with the same
arithmetic, exchanging u's ghost rows after each update (bonds break and forces are computed
from them as in an explicit MPI run), and the two sums of c and the residual norms are taken on
rank 0 over the gathered values in global point order: the serial iterates bit for bit.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from peridyn import interrupts
from peridyn.errors import InputError, Interrupted
from peridyn.parallel.domain import Domain, failed_alone
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
    domain: Domain | None = None,
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
    domain : Domain or None
        The rank's part of the body under MPI (``peridyn.parallel``; collective): the model,
        loading, damage and contact are the rank's, each iteration updates the owned rows and
        exchanges u's ghost rows, and the damping's Rayleigh quotient and the residual are
        reduced over the whole body in global point order (``Domain.reduce``), so that u, the
        bonds broken and the iterations are the serial run's bit for bit. None: one process.

    Returns a RelaxationResult; under MPI ``u`` is (n_local, 3) with its ghost rows filled, and
    ``broken_bonds`` counts the whole body's.
    """
    if not tolerance > 0:
        raise InputError(f"relaxation tolerance must be positive, got {tolerance!r}")
    d = domain if domain is not None else Domain.serial(model.body.n_points)
    with _one_rank_errors(d):
        u, free, lam, b = _start(model, loading, time, u0, contact, d)
        return _iterate(model, u, free, lam, b, tolerance, max_iterations, damage, check_every, contact, d)


def _start(model: Model, loading: Loading, time: float, u0, contact: Contact | None, d: Domain):
    """The relaxation's start at load time ``time`` (s): u (n_local, 3) m with the initial and
    prescribed displacements and its ghost rows exchanged, and of the owned rows the free DOFs
    (n_owned, 3) bool, the fictitious density lambda (n_owned, 3) and the body force b
    (n_owned, 3) N/m^3."""
    n = model.body.n_points
    u = np.zeros((n, 3)) if u0 is None else np.array(u0, dtype=float)
    v = np.zeros((n, 3))
    loading.apply_initial(u, v)
    v[:] = 0.0
    loading.apply_kinematics(time, 1.0, u, v)
    d.exchange(u)
    own = d.owned  # every per-point update is of the owned rows; the ghosts' come by exchange
    free = ~loading.constrained[own]
    free[:, model.body.dim :] = False
    bound = model.stiffness_bound()
    if contact is not None:
        bound = bound + contact.stiffness_bound()
    lam = np.repeat((0.25 * bound[own])[:, None], 3, axis=1)
    b = loading.body_force_density(time, np.zeros((n, 3)))[own]
    return u, free, lam, b


def _iterate(model, u, free, lam, b, tolerance, max_iterations, damage, check_every, contact, d: Domain):
    """The iterations of ``relax`` from ``_start``'s arrays (module docstring); u updated in place."""
    own = d.owned
    agree = d.max if d.size > 1 else None

    def internal_force(u):
        f = np.asarray(model.force(u), dtype=float)
        return (contact.add_force(u, f) if contact is not None else f)[own]

    intact_before = _owned_intact(model, d)
    f = internal_force(u)
    v = np.zeros_like(u[own])  # m per iteration (of the fictitious unit step)
    c = 0.0
    for it in range(1, max_iterations + 1):
        interrupts.check(where="relaxing to equilibrium", agree=agree)
        a = (f + b) * free / lam
        v = 0.5 * a if it == 1 else ((2.0 - c) * v + 2.0 * a) / (2.0 + c)
        v *= free
        u[own] += v
        d.exchange(u)
        if damage is not None:
            damage.update(u)
        f_prev, f = f, internal_force(u)
        c = _damping(u[own], v, f, f_prev, lam, d)
        if it % check_every == 0:
            residual = d.reduce(_relative_residual, f, b, free)
            if not np.isfinite(residual):
                error = InputError("relaxation diverged (non-finite forces)")
                error.every_rank = True  # the residual is every rank's
                raise error
            if residual < tolerance:
                return RelaxationResult(u, residual, it, True, _broken(model, d, intact_before))
    residual = d.reduce(_relative_residual, f, b, free)
    return RelaxationResult(u, residual, max_iterations, False, _broken(model, d, intact_before))


@contextmanager
def _one_rank_errors(d: Domain):
    """Under MPI, mark an error raised on this rank alone with ``failed_rank``
    (``parallel.domain.failed_alone``), for the CLI to end every rank: the others wait in a
    collective it will never join. An interruption is every rank's (``interrupts.check`` agrees)."""
    try:
        yield
    except Interrupted:
        raise
    except Exception as exc:
        if d.size > 1:
            failed_alone(exc, d.comm)
        raise


def _damping(u, v, f, f_prev, lam, domain: Domain) -> float:
    """The damping c = 2 sqrt(u^T K_loc u / u^T u) of the next iteration, at most 1.9, with
    K_loc,ii = -(f_i - f_prev_i) / (lam_i v_i) on the moving DOFs (module docstring); all
    arrays (n_owned, 3): u m, v m per (unit) step, f and f_prev N/m^3, lam the fictitious
    density (a quarter of the stiffness bound, N/m^4, for the unit step). The two
    sums are over the whole body in global order (``Domain.reduce``: the serial rounding)."""
    moving = np.abs(v) > 0
    k_loc = np.zeros_like(u)
    k_loc[moving] = -(f[moving] - f_prev[moving]) / (lam[moving] * v[moving])
    num, den = domain.reduce(lambda uku, uu: (np.sum(uku), np.sum(uu)), u * k_loc * u, u * u)
    c = 2.0 * np.sqrt(num / den) if num > 0 and den > 0 else 0.0
    return min(c, 1.9)


def _owned_intact(model: Model, domain: Domain) -> int:
    """Intact directed bonds of the owned points' families (they come first in a rank's bonds)."""
    return int(np.count_nonzero(model.bonds.intact[: model.bonds.offsets[domain.n_owned]]))


def _broken(model: Model, domain: Domain, intact_before: int) -> int:
    """Directed bonds of the whole body broken since ``intact_before`` (``_owned_intact``
    then; collective)."""
    return domain.count(intact_before - _owned_intact(model, domain))


def _relative_residual(f: np.ndarray, b: np.ndarray, free: np.ndarray) -> float:
    out_of_balance = np.linalg.norm((f + b)[free])
    reactions = np.linalg.norm(f[~free])
    scale = max(np.linalg.norm(b), reactions)
    return float(out_of_balance / scale) if scale > 0 else float(out_of_balance)
