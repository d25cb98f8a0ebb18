"""Implicit dynamics: Newmark average acceleration (beta = 1/4, gamma = 1/2) with Newton.

One step of size dt from (u, v, a) at t to t + dt, lumped mass M = rho V, mass-proportional
damping c:

    u* = u + dt v + dt^2 a / 4;  a' = 4 (u' - u*) / dt^2;  v' = v + dt (a + a') / 2;
    R(u') = V (f(u') + b(t + dt)) - M (a' + c v') = 0  at the free dofs,

solved by Newton with the consistent tangent ``K`` (``peridyn.linalg.tangent``):
``(K + (4 / dt^2 + 2 c / dt) M) du = R`` (``peridyn.linalg.tangent_solve``: sparse LU, or
AMG-preconditioned CG on the matrix-free tangent for large bodies), until the largest displacement increment
|du| is below ``tolerance`` (m; Martowicz: dt = 20 ns, 0.1 nm) or, given ``residual_tolerance``
(N), |R| is below that. Prescribed displacements
are imposed at t + dt, prescribed velocities integrated by the trapezoidal rule, and
prescribed dofs get a = 0 (as in ``ExplicitSolver``). For a linear undamped system the
scheme conserves the energy (v^T M v + u^T K u) / 2 exactly and is unconditionally stable.

``NewmarkSolver`` has the interface of ``ExplicitSolver`` (``dt``, ``model``,
``initial_state``, ``step``, ``run`` with observers, ``kinetic_energy``), so the
Recorder, checkpoints and HDF5 output work unchanged.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from peridyn.discretization.state import State, check_state
from peridyn.errors import InputError
from peridyn.linalg.dofs import free_dofs
from peridyn.linalg.stiffness import mass_matrix
from peridyn.linalg.tangent_solve import TangentSolver
from peridyn.physics.damage import BondDamage
from peridyn.physics.loads import Loading
from peridyn.physics.materials.base import Model
from peridyn.solvers.stepping import advance


class NewmarkSolver:
    """Average-acceleration Newmark integration with Newton iterations.

    Parameters
    ----------
    model : Model
    loading : Loading or None
    dt : float, s
        Time step (any size: the scheme is unconditionally stable for linear systems).
    tolerance : float, m
        Newton stops when the largest displacement increment is below it.
    residual_tolerance : float or None, N
        Newton also stops when the norm of the residual force (at the free dofs) is below it
        (Peridigm's "Absolute Tolerance").
    initial_acceleration : {"balance", "zero"}
        The acceleration at t = 0: from M a = V (f + b) - c M v (``balance``), or zero, as
        Peridigm's implicit solver starts.
    max_iterations : int
        Newton iterations per step; more raises an InputError naming the step.
    damping : float, 1/s
        Mass-proportional damping coefficient c.
    damage : BondDamage or None
        Over-stretched bonds break after each converged step.
    linear_solver : {"auto", "lu", "cg"}
        Sparse LU, conjugate gradients on the matrix-free tangent preconditioned by AMG (the
        mass term makes the effective tangent well conditioned: a few iterations), or
        ``auto``: LU where its estimated factor is small (``linalg.tangent_solve``).
    """

    def __init__(
        self,
        model: Model,
        loading: Loading | None = None,
        dt: float = 20e-9,
        tolerance: float = 1e-10,
        max_iterations: int = 20,
        damping: float = 0.0,
        damage: BondDamage | None = None,
        linear_solver: str = "auto",
        residual_tolerance: float | None = None,
        initial_acceleration: str = "balance",
    ):
        if not dt > 0:
            raise InputError(f"time step must be positive, got {dt!r}")
        if not tolerance > 0:
            raise InputError(f"Newmark displacement tolerance must be positive, got {tolerance!r}")
        if int(max_iterations) != max_iterations or max_iterations < 1:
            raise InputError(f"Newmark max_iterations must be a positive integer, got {max_iterations!r}")
        if damping < 0:
            raise InputError(f"damping must be non-negative, got {damping!r}")
        if initial_acceleration not in ("balance", "zero"):
            raise InputError(f"initial_acceleration {initial_acceleration!r}: use 'balance' or 'zero'")
        self.initial_acceleration = initial_acceleration
        self.model = model
        self.loading = loading if loading is not None else Loading(model.body)
        self.dt = float(dt)
        self.tolerance = float(tolerance)
        self.residual_tolerance = residual_tolerance
        self.max_iterations = int(max_iterations)
        self.damping = float(damping)
        self.damage = damage
        self.linear = TangentSolver(model, linear_solver, 4.0 / self.dt**2 + 2.0 * self.damping / self.dt)
        self.stable_dt = model.critical_time_step()  # the explicit limit, for comparison
        self.mass = mass_matrix(model).diagonal()
        self.free = free_dofs(model, self.loading.constrained)
        self.iterations: list[int] = []  # Newton iterations of each step taken
        n = model.body.n_points
        self._body_force = np.zeros((n, 3))

    def __repr__(self) -> str:
        return f"NewmarkSolver(model={self.model!r}, dt={self.dt:.4g} s, tol={self.tolerance:g} m)"

    def initial_state(self) -> State:
        """The state at t = 0: initial conditions applied and M a = V (f + b) - c M v solved
        (a = 0 with ``initial_acceleration="zero"``)."""
        state = State.zeros(self.model.body.n_points)
        self.loading.apply_start(self.dt, state.u, state.v)
        if self.initial_acceleration == "zero":
            return state
        state.a[:] = self._out_of_balance(state.u, state.time) / self.mass.reshape(-1, 3)
        state.a -= self.damping * state.v
        state.a[self.loading.constrained] = 0.0
        return state

    def _out_of_balance(self, u: np.ndarray, t: float) -> np.ndarray:
        """V (f(u) + b(t)), N, (n_points, 3)."""
        f = np.asarray(self.model.force(u), dtype=float)
        b = self.loading.body_force_density(t, self._body_force)
        return self.model.body.volumes[:, None] * (f + b)

    def step(self, state: State) -> int:
        """Advance ``state`` by one step in place; returns the number of bonds broken."""
        dt, c, free = self.dt, self.damping, self.free
        t1 = state.time + dt
        u_star = state.u + dt * state.v + 0.25 * dt * dt * state.a
        v_new = state.v.copy()
        self.loading.apply_velocities(t1, v_new)
        u = u_star.copy()
        held = self.loading.constrained
        u[held] = state.u[held] + 0.5 * dt * (state.v[held] + v_new[held])
        self.loading.apply_kinematics(t1, dt, u, v_new)
        mass = self.mass
        uf, u0f, v0f, a0f = u.reshape(-1), u_star.reshape(-1), state.v.reshape(-1), state.a.reshape(-1)
        taken = 0
        for _ in range(self.max_iterations):
            taken += 1
            a1 = 4.0 * (uf[free] - u0f[free]) / dt**2
            v1 = v0f[free] + 0.5 * dt * (a0f[free] + a1)
            r = self._out_of_balance(u, t1).reshape(-1)[free] - mass[free] * (a1 + c * v1)
            if self.residual_tolerance is not None and np.linalg.norm(r) < self.residual_tolerance:
                break
            du = self.linear.solve(u, free, r)
            uf[free] += du
            if np.max(np.abs(du), initial=0.0) < self.tolerance:
                break
        else:
            raise InputError(
                f"Newmark step {state.step + 1} (t = {t1:.6g} s) did not converge in "
                f"{self.max_iterations} Newton iterations (last increment "
                f"{np.max(np.abs(du)):.3g} m > tolerance {self.tolerance:g} m): reduce dt"
            )
        self.iterations.append(taken)
        a_new = np.zeros_like(state.a)
        a_new.reshape(-1)[free] = 4.0 * (uf[free] - u0f[free]) / dt**2
        v_new.reshape(-1)[free] = v0f[free] + 0.5 * dt * (a0f[free] + a_new.reshape(-1)[free])
        state.u[:] = u
        state.v[:] = v_new
        state.a[:] = a_new
        state.time = t1
        state.step += 1
        # bonds broken here act from the next step on: the stored acceleration is the
        # converged one of this step (a lag of one step; the explicit solver breaks first)
        broken = self.damage.update(state.u, state.time) if self.damage is not None else 0
        check_state(state)
        return broken

    def run(self, state: State, n_steps: int, observers: Sequence = (), progress=None) -> State:
        """Advance ``state`` by ``n_steps`` steps, calling ``observe(state, self)`` after each."""
        return advance(self, state, n_steps, observers, progress)

    def kinetic_energy(self, state: State) -> float:
        """Total kinetic energy, J."""
        return float(0.5 * np.sum(self.mass * state.v.reshape(-1) ** 2))
