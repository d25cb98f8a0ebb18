"""Quasi-static equilibrium by Newton-Raphson with load stepping and bond breaking.

At the free dofs (not prescribed, and not the z dofs of a 2D body) the
out-of-balance force (N) is

    r(u) = V f(u) + V b,

and each iteration solves ``K(u) du = r(u)`` with the consistent tangent
``K = -d(V f)/du`` (``peridyn.linalg.tangent``) by a sparse LU factorisation where its
estimated size fits, or by AMG-preconditioned conjugate gradients on the matrix-free tangent
to 1e-12 (``peridyn.linalg.tangent_solve``), the prescribed dofs held at their values
(elimination). Near the solution the
residual falls quadratically, r_(k+1) ~ C r_k^2. Converged when
``|r| / max(|V b|, |reactions|) < tolerance`` (the reactions are the internal
forces on the prescribed dofs), the criterion of ``relax`` with integrated forces.

Load stepping: step k of n evaluates the loads at ``time * k / n`` and starts
from step k-1's solution. With a ``BondDamage``, each converged step breaks the
over-stretched bonds and re-equilibrates, repeatedly, until no bond breaks.
Dofs whose tangent has no diagonal entry (points left without any bond) are held.
A body with no prescribed motion at all gets a statically determinate support
(``rigid_support``: 3-2-1 dofs in 3D, 2-1 in 2D) that removes its rigid-body modes
and carries no reaction when the loads balance; partly supported bodies must be
held against rigid motion by their own conditions.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from peridyn import interrupts
from peridyn.errors import InputError
from peridyn.linalg.dofs import free_dofs
from peridyn.linalg.tangent_solve import TangentSolver
from peridyn.physics.damage import BondDamage
from peridyn.physics.loads import Loading
from peridyn.physics.materials.base import Model


@dataclass
class NewtonStep:
    """One load step.

    Attributes
    ----------
    time : float, s
        Time at which the loads were evaluated.
    residuals : list of list of float
        Relative residual before each Newton iteration and at the end, one list per
        equilibrium solve (the first, then one per round of bond breaking).
    broken_bonds : int
    converged : bool
    """

    time: float
    residuals: list = field(default_factory=list)
    broken_bonds: int = 0
    converged: bool = False


@dataclass
class NewtonResult:
    """Outcome of a Newton-Raphson solve (compare ``RelaxationResult``).

    Attributes
    ----------
    u : (n_points, 3) float64, m
    residual : float
        Relative residual at the end of the last step.
    iterations : int
        Newton iterations (linear solves) over all steps.
    converged : bool
        Every step converged and stopped breaking bonds.
    broken_bonds : int
    steps : list of NewtonStep
    """

    u: np.ndarray
    residual: float
    iterations: int
    converged: bool
    broken_bonds: int
    steps: list


def newton(
    model: Model,
    loading: Loading,
    load_steps: int = 1,
    time: float = 1.0,
    u0: np.ndarray | None = None,
    tolerance: float = 1e-8,
    max_iterations: int = 30,
    damage: BondDamage | None = None,
    max_breaking_rounds: int = 100,
    linear_solver: str = "auto",
    absolute_tolerance: float | None = None,
    on_step=None,
) -> NewtonResult:
    """Equilibrium under the loads ramped in ``load_steps`` steps up to ``time`` (s).

    Parameters
    ----------
    u0 : (n_points, 3) float64 or None
        Starting displacement, m.
    tolerance : float
        Relative residual to reach (see the module docstring).
    max_iterations : int
        Newton iterations per equilibrium solve.
    damage : BondDamage or None
        Break over-stretched bonds after each converged step and re-equilibrate.
    max_breaking_rounds : int
        Re-equilibrations allowed per load step.
    linear_solver : {"auto", "lu", "cg"}
        Sparse LU, AMG-preconditioned conjugate gradients on the matrix-free tangent, or
        ``auto``: LU where its estimated factor is small (``linalg.tangent_solve``).
    absolute_tolerance : float or None, N
        Converged when the norm of the out-of-balance force at the free dofs is below it
        (Peridigm's "Absolute Tolerance"), instead of the relative ``tolerance``.
    on_step : callable (NewtonStep, u) or None
        Called after each converged load step with its displacement (n_points, 3), m.
    """
    if absolute_tolerance is not None and not absolute_tolerance > 0:
        raise InputError(f"Newton absolute tolerance must be positive, got {absolute_tolerance!r}")
    if not tolerance > 0:
        raise InputError(f"Newton tolerance must be positive, got {tolerance!r}")
    for name, value in (
        ("load_steps", load_steps),
        ("max_iterations", max_iterations),
        ("max_breaking_rounds", max_breaking_rounds),
    ):
        if int(value) != value or value < 1:
            raise InputError(f"Newton {name} must be a positive integer, got {value!r}")
    if not time > 0:
        raise InputError(f"Newton end time must be positive, got {time!r}")
    n = model.body.n_points
    u = np.zeros((n, 3)) if u0 is None else np.array(u0, dtype=float)
    if u.shape != (n, 3):
        raise InputError(f"u0 must have shape ({n}, 3), got {u.shape}")
    solver = TangentSolver(model, linear_solver)
    v = np.zeros((n, 3))
    loading.apply_initial(u, v)
    steps, iterations, broken_total, residual = [], 0, 0, np.inf
    for k in range(1, load_steps + 1):
        t = time * k / load_steps
        loading.apply_kinematics(t, 1.0, u, v)
        b = loading.body_force_density(t, np.zeros((n, 3)))
        step = NewtonStep(t)
        for _ in range(max_breaking_rounds + 1):
            u, history, converged = equilibrate(
                model, u, b, loading.constrained, tolerance, max_iterations, solver, absolute_tolerance
            )
            step.residuals.append(history)
            iterations += len(history) - 1
            residual = history[-1]
            if not converged:
                break
            broken = damage.update(u) if damage is not None else 0
            step.broken_bonds += broken
            if broken == 0:
                step.converged = True
                break
        broken_total += step.broken_bonds
        steps.append(step)
        if not step.converged:
            break
        if on_step is not None:
            on_step(step, u)
    converged = len(steps) == load_steps and steps[-1].converged
    return NewtonResult(u, float(residual), iterations, converged, broken_total, steps)


def equilibrate(
    model: Model,
    u: np.ndarray,
    b: np.ndarray,
    constrained: np.ndarray,
    tolerance: float,
    max_iterations: int,
    linear_solver: str | TangentSolver = "auto",
    absolute_tolerance: float | None = None,
) -> tuple[np.ndarray, list, bool]:
    """Newton iterations at fixed loads from ``u`` (n, 3), m; ``b`` body force density N/m^3;
    ``linear_solver`` a name of ``linalg.tangent_solve.LINEAR_SOLVERS`` or a ``TangentSolver``
    (kept between calls: its preconditioner is set up once).

    Returns the displacement, the relative residual before each iteration and at the
    end, and whether it converged (the relative residual below ``tolerance`` or, when
    ``absolute_tolerance`` (N) is given, the residual force's norm below it).
    """
    if isinstance(linear_solver, str):
        linear_solver = TangentSolver(model, linear_solver)
    u = u.copy()
    vol = np.repeat(model.body.volumes, 3)
    support = constrained if constrained.any() else rigid_support(model)
    free = free_dofs(model, support)
    held = np.flatnonzero(constrained.ravel())
    load = np.linalg.norm(vol * b.ravel())
    history = []
    for it in range(max_iterations + 1):
        interrupts.check(where="solving for equilibrium")
        force = vol * (np.asarray(model.force(u), dtype=float) + b).ravel()
        scale = max(load, np.linalg.norm(force[held]))
        r = force[free]
        residual = float(np.linalg.norm(r) / scale) if scale > 0 else float(np.linalg.norm(r))
        history.append(residual)
        if not np.isfinite(residual):
            return u, history, False
        if absolute_tolerance is None and residual < tolerance:
            return u, history, True
        if absolute_tolerance is not None and np.linalg.norm(r) < absolute_tolerance:
            return u, history, True
        if it == max_iterations:
            break
        du = linear_solver.solve(u, free, r)
        u.ravel()[free] += du
    return u, history, False


def rigid_support(model: Model) -> np.ndarray:
    """(n_points, 3) bool: dofs of a statically determinate support (3-2-1 rule).

    Point A (nearest the centroid) is held in every in-plane direction; point B (farthest
    from A) across the line AB; in 3D, point C (farthest from that line) across the plane ABC.
    Each direction is the coordinate axis closest to it.
    """
    x = model.body.points
    dim = model.body.dim
    held = np.zeros((len(x), 3), dtype=bool)
    a = int(np.argmin(np.linalg.norm(x - x.mean(axis=0), axis=1)))
    held[a, :dim] = True
    along = x - x[a]
    b = int(np.argmax(np.linalg.norm(along, axis=1)))
    ab = along[b] / np.linalg.norm(along[b])
    across = np.argsort(np.abs(ab[:dim]))[: dim - 1]  # the axes least along AB
    held[b, across] = True
    if dim == 3:
        off_line = along - np.outer(along @ ab, ab)
        c = int(np.argmax(np.linalg.norm(off_line, axis=1)))
        normal = np.cross(ab, along[c])
        held[c, int(np.argmax(np.abs(normal)))] = True
    return held
