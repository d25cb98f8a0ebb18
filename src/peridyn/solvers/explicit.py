"""Explicit dynamics by velocity Verlet.

One step of size dt (rho a = f(u) + b - rho c v, c the mass-proportional damping):

    v <- v + dt/2 a;  u <- u + dt v;  t <- t + dt;  impose prescribed u (and its v);
    break over-stretched bonds;  a <- (f(u) + f_c(u) + b(t)) / rho - c v;  a <- 0 on prescribed DOFs;
    v <- v + dt/2 a;  impose prescribed v.

The step defaults to ``safety`` times the model's stable step (``Model.critical_time_step``);
a larger step given by the user is refused. With contact (``f_c``, the short-range
forces of ``peridyn.physics.contact``) the stable step comes from the sum of the model's and the
contact's stiffness bounds, 2 / sqrt(max((s_model + s_contact) / rho)) (Gershgorin).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np

from peridyn.discretization.state import State
from peridyn.errors import InputError
from peridyn.kernels.verlet import acceleration, kick_drift
from peridyn.parallel.domain import Domain
from peridyn.physics.contact import Contact
from peridyn.physics.damage import BondDamage
from peridyn.physics.loads import Loading
from peridyn.physics.materials.base import Model
from peridyn.solvers.stepping import advance


class ExplicitSolver:
    """Velocity-Verlet time integration of a model under a loading.

    Parameters
    ----------
    model : Model
    loading : Loading or None
    dt : float or None, s
        Time step; ``None`` takes ``safety`` times the stable step.
    safety : float
        Fraction of the stable step used when ``dt`` is None (0 < safety <= 1).
    damping : float or (n_points,) float, 1/s
        Mass-proportional damping coefficient c, one for all points or one per point (e.g.
        absorbing layers, ``peridyn.physics.absorbing``); 0: undamped. It lowers the stable step.
    damage : BondDamage or None
    check_every : int
        Steps between checks for a non-finite or runaway state (``check_state``; the
        recorder also checks before every record).
    contact : Contact or None
        Short-range forces added to the model's force; their stiffness lowers the stable step.
    domain : Domain or None
        The rank's part of the body under MPI (``peridyn.parallel``): the model, loading and
        damping are the rank's, u's ghost rows are exchanged after every update of u, and the
        stable step, checks and energies are taken over the whole body. None: one process.
    prescribed_velocity : {"rate", "difference"}
        The velocity of a DOF with a prescribed displacement: ``rate``, the central difference
        of its time function (peridyn's); ``difference``, Peridigm's (u(n+1) - u(n)) / dt +
        dt/2 a(n+1), a the acceleration of the forces on the point (zero at t = 0, where it
        keeps its initial velocity). Either way the motion of every point is the same.
    arithmetic : {"peridyn", "peridigm"}
        ``peridigm``: Peridigm's order of operations (docs/peridigm.md, Rounding): each step
        forms the deformed positions y = (x + u) + dt v(n + 1/2) before u is updated, the
        material's force comes from y (``Model.force_from_positions``: LPS) and
        a = (f + b) / rho. The prescribed DOFs take y = x + u. One process, float64.
    beyond_bound : {"refuse", "warn"}
        A ``dt`` above the stable step's Gershgorin bound (an upper bound of the largest
        frequency, so a sufficient condition only): refused, or run with a warning (Peridigm's
        own step, ``solver.step_rule: peridigm``); the state checks still stop a run that
        diverges.
    """

    def __init__(
        self,
        model: Model,
        loading: Loading | None = None,
        dt: float | None = None,
        safety: float = 0.8,
        damping: float = 0.0,
        damage: BondDamage | None = None,
        check_every: int = 10,
        contact: Contact | None = None,
        domain: Domain | None = None,
        prescribed_velocity: str = "rate",
        arithmetic: str = "peridyn",
        beyond_bound: str = "refuse",
    ):
        if arithmetic not in ("peridyn", "peridigm"):
            raise InputError(f"arithmetic must be 'peridyn' or 'peridigm', got {arithmetic!r}")
        if beyond_bound not in ("refuse", "warn"):
            raise InputError(f"beyond_bound must be 'refuse' or 'warn', got {beyond_bound!r}")
        if prescribed_velocity not in ("rate", "difference"):
            raise InputError(
                f"prescribed_velocity must be 'rate' or 'difference', got {prescribed_velocity!r}"
            )
        if not 0 < safety <= 1:
            raise InputError(f"time-step safety factor must lie in (0, 1], got {safety!r}")
        damping = _damping_coefficients(damping, model.body.n_points)
        self.model = model
        self.loading = loading if loading is not None else Loading(model.body)
        self.contact = contact
        self.domain = domain if domain is not None else Domain.serial(model.body.n_points)
        self.stable_dt = damped_stable_step(
            stable_time_step(model, contact, self.domain), self.domain.max(float(np.max(damping)))
        )
        if dt is None:
            dt = safety * self.stable_dt
        elif not dt > 0:
            raise InputError(f"time step must be positive, got {dt!r}")
        elif dt > self.stable_dt:
            message = (
                f"time step {dt:.4g} s exceeds the stable step {self.stable_dt:.4g} s of this "
                "model (Gershgorin bound)"
            )
            if beyond_bound != "warn":
                raise InputError(f"{message}: use dt <= {self.stable_dt:.4g} s or leave dt unset")
            warnings.warn(f"{message}: run as asked; a diverging state stops the run", stacklevel=2)
        self.dt = float(dt)
        self.damping = float(damping[0]) if damping.size == 1 else damping
        self._damping = damping if damping.any() else np.zeros(0)  # (0,): undamped
        self.damage = damage
        self.check_every = int(check_every)
        #: largest believable displacement, m (``runaway_limit``)
        self.max_displacement = self.domain.runaway_limit(model.body.points)
        n = model.body.n_points
        #: the force's own array (n_points, 3), N/m^3, or None: the force is written into the
        #: state's acceleration, which ``kernels.verlet.acceleration`` turns into a in place
        #: (a model that can, ``Model.force_fills_acceleration``, every row of a rank's part
        #: included, called as ``model.force`` (peridyn's order) with nothing reading the force
        #: after: no contact, no differenced velocity)
        into_acceleration = (
            model.force_fills_acceleration
            and arithmetic == "peridyn"
            and contact is None
            and prescribed_velocity == "rate"
        )
        self._force = None if into_acceleration else np.zeros((n, 3), dtype=model.dtype)
        # without body forces b is a read-only zero row seen n times, and one density's
        # 1 / rho one value seen n times: 32 bytes a point that a large body does not pay
        self._body_force = (
            np.zeros((n, 3)) if self.loading.body_force else np.broadcast_to(np.zeros(3), (n, 3))
        )
        self._inv_rho = _reciprocal(model.density)
        #: Peridigm's order: the deformed positions y (n_points, 3) m, else None
        self._positions = None
        if arithmetic == "peridigm":
            if self.domain.halo is not None:
                raise InputError("solver.arithmetic: peridigm runs in one process (not under MPI)")
            self._positions = np.empty((n, 3))
        #: the DOFs whose velocity is Peridigm's difference, and their force acceleration
        self._differenced = self.loading.displaced if prescribed_velocity == "difference" else None
        self._free = None
        #: under MPI without bond breaking, the force of the rows far from the ghosts is computed
        #: while u's ghost rows are exchanged (``Model.force_overlapped``); bond breaking reads
        #: every owned family's stretch first, so it waits for the ghosts
        self.overlap = self.domain.halo is not None and damage is None

    def __repr__(self) -> str:
        damping = self.damping if np.isscalar(self.damping) else f"up to {np.max(self.damping):g}"
        return f"ExplicitSolver(model={self.model!r}, dt={self.dt:.4g} s, damping={damping})"

    def initial_state(self) -> State:
        """The state at t = 0: initial conditions applied and accelerations computed."""
        state = State.zeros(self.model.body.n_points)
        self.loading.apply_start(self.dt, state.u, state.v, rates=self._differenced is None)
        self.domain.exchange(state.u)
        if self._positions is not None:
            np.add(self.model.body.points, state.u, out=self._positions)
        self._acceleration(state)
        return state

    def continued_state(self, u: np.ndarray, v: np.ndarray, time: float, step: int) -> State:
        """The state that continues another solver's run (a quasi-static one's last load
        step): displacement ``u`` (n_points, 3) m and velocity ``v`` (n_points, 3) m/s at
        ``time`` (s), numbered ``step``, its accelerations computed from its forces (copies:
        ``u`` and ``v`` are left as they are)."""
        u, v = np.array(u, dtype=np.float64), np.array(v, dtype=np.float64)
        state = State(u, v, np.zeros_like(u), time, step)
        self.domain.exchange(state.u)
        if self._positions is not None:
            np.add(self.model.body.points, state.u, out=self._positions)
        self._acceleration(state)
        return state

    def _acceleration(self, state: State, kick: bool = False, overlapped: bool = False) -> None:
        """``state.a`` from the forces at ``state.u`` (one fused pass: ``kernels.verlet``), with
        ``kick`` followed by the closing half step of the velocity, ``v += dt/2 a``.
        ``overlapped``: the exchange of u's ghost rows has been started, and is finished during
        the force (``Model.force_overlapped``)."""
        if self._positions is not None:
            f = self.model.force_from_positions(self._positions, self._force)
            if self.contact is not None:
                f = f.copy()  # self._force keeps the material's own (``internal_force``)
        elif overlapped:
            d = self.domain
            out = state.a if self._force is None else self._force
            f = self.model.force_overlapped(state.u, out, d.clear_rows, d.n_owned, d.finish_exchange)
        else:
            f = self.model.force(state.u, out=state.a if self._force is None else self._force)
        if self.contact is not None:  # Peridigm's order: at its deformed positions
            extra = () if self._positions is None else (self._positions,)
            self.contact.add_force(state.u, f, *extra)
        b = self._body_force
        if self.loading.body_force:  # else b stays zero
            self.loading.body_force_density(state.time, b)
        acceleration(
            f,
            b,
            self._inv_rho if self._positions is None else self.model.density,
            self._damping,
            state.v,
            self.loading.constrained,
            state.a,
            kick,
            0.5 * self.dt,
            self._positions is not None,
        )
        if self._differenced is not None:
            self._free = self._free_acceleration(f, b, state.v)

    def internal_force(self, state: State) -> np.ndarray:
        """The material's force density (n_points, 3), N/m^3, at ``state``: with Peridigm's
        order the one its last step (or ``initial_state``) computed from the deformed positions,
        else ``model.force(state.u)``."""
        if self._positions is not None:
            return self._force
        return self.model.force(state.u)

    def _free_acceleration(self, f: np.ndarray, b: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The acceleration (m/s^2) of the DOFs with Peridigm's differenced velocity, as
        ``kernels.verlet.acceleration`` computes it before their constraint zeroes it; (k,) in
        the order of ``v[self._differenced]``."""
        mask = self._differenced
        rows = np.nonzero(mask)[0]
        a = f[mask].astype(np.float64) + b[mask]
        if self._positions is None:
            a *= self._inv_rho[rows]
        else:
            a /= self.model.density[rows]
        if self._damping.size:
            a -= (self._damping if self._damping.size == 1 else self._damping[rows]) * v[mask]
        return a

    def step(self, state: State) -> int:
        """Advance ``state`` by one step in place; returns the number of bonds broken."""
        dt = self.dt
        differenced = self._differenced
        if differenced is not None:
            u_before = state.u[differenced]
        y = self._positions
        if y is not None:  # Peridigm's y = (x + u(n)) + dt v(n + 1/2)
            np.add(self.model.body.points, state.u, out=y)
        kick_drift(state.u, state.v, state.a, 0.5 * dt, dt)
        if y is not None:
            y += dt * state.v
        state.time += dt
        state.step += 1
        self.loading.apply_kinematics(state.time, dt, state.u, state.v, rates=differenced is None)
        if y is not None and self.loading.constrained.any():
            fixed = self.loading.constrained
            y[fixed] = self.model.body.points[fixed] + state.u[fixed]
        if self.overlap:
            self.domain.start_exchange(state.u)
            broken = 0
        else:
            self.domain.exchange(state.u)
            broken = self.damage.update(state.u, state.time) if self.damage is not None else 0
        self._acceleration(state, kick=True, overlapped=self.overlap)
        self.loading.apply_velocities(state.time, state.v)
        if differenced is not None:
            state.v[differenced] = (state.u[differenced] - u_before) / dt + 0.5 * dt * self._free
        if state.step % self.check_every == 0:
            self.domain.check_state(state, self.max_displacement)
        return broken

    def run(self, state: State, n_steps: int, observers: Sequence = (), progress=None) -> State:
        """Advance ``state`` by ``n_steps`` steps.

        Parameters
        ----------
        observers : sequence of objects with ``observe(state, solver)``
            Called after every step (recorders, checkpoints).
        progress : object with ``update(n)`` or None
            E.g. a tqdm bar.
        """
        advance(self, state, n_steps, observers, progress)
        self.domain.check_state(state, self.max_displacement)
        return state

    def kinetic_energy(self, state: State) -> float:
        """Total kinetic energy of the whole body, J."""
        n = self.domain.n_owned
        v2 = np.einsum("ij,ij->i", state.v[:n], state.v[:n])
        return float(0.5 * self.domain.sum(self.model.density[:n] * self.model.body.volumes[:n] * v2))


def stable_time_step(model: Model, contact: Contact | None = None, domain: Domain | None = None) -> float:
    """Largest stable velocity-Verlet step, s, of a model with optional contact (with a
    ``domain``: over its owned points, then over every rank)."""
    extra = None if contact is None else contact.stiffness_bound()
    if domain is None:
        return model.critical_time_step(extra)
    return domain.min(model.critical_time_step(extra, points=domain.owned))


def damped_stable_step(undamped_dt: float, damping: float) -> float:
    """Largest stable step, s, with mass-proportional damping ``damping`` (1/s).

    In this scheme the damping force uses the half-step velocity; for one mode of angular
    frequency w the step is stable while (w dt)^2 + 2 c dt < 4 (spectral radius of the
    amplification matrix; ``tests/unit/test_absorbing.py``). With the largest w = 2 /
    ``undamped_dt`` and the largest c this gives dt = 4 / (c + sqrt(c^2 + 4 w^2)).
    """
    if damping == 0:
        return float(undamped_dt)
    omega = 2.0 / undamped_dt
    return float(4.0 / (damping + np.sqrt(damping**2 + 4.0 * omega**2)))


def _damping_coefficients(damping, n_points: int) -> np.ndarray:
    """``damping`` as a (1,) or (n_points,) float64 array, checked."""
    c = np.atleast_1d(np.asarray(damping, dtype=float))
    if c.ndim != 1 or c.size not in (1, n_points):
        raise InputError(
            f"damping must be a number or one value per point ({n_points}), got shape {np.shape(damping)}"
        )
    if not np.all(np.isfinite(c) & (c >= 0)):
        raise InputError(
            "damping must be non-negative and finite (1/s)" + (f", got {damping!r}" if c.size == 1 else "")
        )
    return c


def _reciprocal(density: np.ndarray) -> np.ndarray:
    """``1 / density`` (n_points,), m^3/kg: one value seen n times (a read-only view) where every
    point has the same density, the same bits as the division point by point."""
    if np.all(density == density[0]):
        return np.broadcast_to(1.0 / density[0], density.shape)
    return 1.0 / density
