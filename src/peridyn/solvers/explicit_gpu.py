"""Explicit dynamics on the GPU: velocity Verlet with the state kept on the device.

``GPUExplicitSolver`` takes the arguments of ``ExplicitSolver`` and steps as it does (the same
operations, in the same order: see ``peridyn.solvers.explicit``), with u, v, a, the force and
the bonds' intact mask on a Warp device (``peridyn.kernels.gpu``; ``solvers.gpu_force``):

- prescribed displacements and velocities and body forces (PZT actuators) are written on the
  device by one launch per boundary condition and step, from the amplitudes uploaded once and
  the time function's value (a number; an expression in x, y, z, t uploads its values);
- absorbing layers are the per-point damping of the acceleration kernel;
- bond breaking tests every intact bond at every step on the device (the CPU's skin only skips
  bonds that cannot break yet: the same bonds break); the count of bonds broken is read each
  step, and the intact mask copied back to ``bonds.intact`` at the steps where bonds broke;
- the observers (recorders, checkpoints) get a state whose ``u``, ``v``, ``a`` are copied from
  the device when first read at a step: nothing is copied at a step where nothing is recorded;
  at a step where only a recorder's series are due, the state is checked on the device and only
  the probe points' u and v come back (:meth:`GPUExplicitSolver.probe_values`).

Contact and MPI ranks are refused (InputError naming them).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from peridyn.discretization.state import State
from peridyn.errors import InputError
from peridyn.kernels.gpu import device, device_description
from peridyn.kernels.gpu.update import (
    acceleration_kernel,
    difference_velocity_kernel,
    gather_rows_kernel,
    kick_drift_kernel,
    prescribe_kernel,
    stretch_break_kernel,
    unsound_kernel,
)
from peridyn.physics.materials.base import Model
from peridyn.solvers.explicit import ExplicitSolver
from peridyn.solvers.gpu_force import DeviceForce, check_fits
from peridyn.solvers.stepping import advance


class DeviceState:
    """The state an observer sees during a GPU run: ``time`` and ``step``, and ``u``, ``v``, ``a``
    ((n_points, 3) float64 host arrays), each copied from the device when first read at a step
    (a series record reads u and v, a step without a record nothing)."""

    def __init__(self, solver: GPUExplicitSolver, host: State):
        self._solver = solver
        self._host = host
        self.time = host.time
        self.step = host.step
        self._copied = {}  # field -> the step whose values are in ``_host``

    def _field(self, name: str) -> np.ndarray:
        target = getattr(self._host, name)
        if self._copied.get(name) != self.step:
            target[:] = self._solver.device_array(name).numpy()
            self._copied[name] = self.step
        return target

    def sync(self) -> State:
        """The host state with every field copied from the device at this step."""
        for name in ("u", "v", "a"):
            self._field(name)
        self._host.time, self._host.step = self.time, self.step
        return self._host

    @property
    def u(self) -> np.ndarray:
        return self._field("u")

    @property
    def v(self) -> np.ndarray:
        return self._field("v")

    @property
    def a(self) -> np.ndarray:
        return self._field("a")


class _DeviceBound:
    """One boundary condition (``physics.loads._Bound``) on the device: its points, components
    and amplitude, and how to write its values at a time."""

    def __init__(self, bound, put):
        self.bound = bound
        self.index = put(bound.index.astype(np.int32))
        self.comps = put(np.asarray(bound.components, dtype=np.int32))
        self.amplitude = put(np.ascontiguousarray(bound.amplitude, dtype=np.float64))
        self.shape = bound.amplitude.shape
        self._put = put

    def inputs(self, values_or_scale):
        """(amplitude array, scale) of the kernel: the uploaded amplitude and the time function's
        value, or the values of an expression in x, y, z, t with scale 1."""
        if np.ndim(values_or_scale) == 0:
            return self.amplitude, float(values_or_scale)
        return self._put(np.ascontiguousarray(values_or_scale, dtype=np.float64)), 1.0

    def value(self, t: float):
        b = self.bound
        return b.function(t) if b.points is None else b.value(t)

    def rate(self, t: float, dt: float):
        b = self.bound
        return b.function.derivative(t, dt) if b.points is None else b.rate(t, dt)


class GPUExplicitSolver(ExplicitSolver):
    """Velocity Verlet on a GPU (module docstring); the parameters of ``ExplicitSolver``, and
    ``device_name`` (a Warp device; None: ``peridyn.kernels.gpu.device()``).

    Attributes
    ----------
    device : str
        The Warp device, e.g. ``"cuda:0"`` or ``"cpu"`` (``PERIDYN_GPU_ON_CPU=1``).
    memory : dict
        The device memory estimated before allocating (``solvers.gpu_force.device_bytes``).
    """

    def __init__(
        self,
        model: Model,
        loading=None,
        dt=None,
        safety: float = 0.8,
        damping=0.0,
        damage=None,
        check_every: int = 10,
        contact=None,
        domain=None,
        prescribed_velocity: str = "rate",
        device_name: str | None = None,
    ):
        refused = [
            what
            for what, present in (
                ("contact", contact is not None),
                ("MPI ranks", domain is not None and domain.size > 1),
            )
            if present
        ]
        if refused:
            raise InputError(f"the GPU backend does not run {', '.join(refused)} yet: use --backend cpu")
        super().__init__(
            model, loading, dt, safety, damping, damage, check_every, None, domain, prescribed_velocity
        )
        self.device = device_name or device()
        self.memory = check_fits(model, damage is not None, self.device)
        self.force_on_device = DeviceForce(model, self.device)
        wp = self.wp = self.force_on_device.wp
        n = model.body.n_points
        self._u, self._v, self._a, self._b = (
            wp.zeros((n, 3), dtype=wp.float64, device=self.device) for _ in range(4)
        )
        self._inv_rho_d = self._put(self._inv_rho.astype(np.float64))
        self._damping_d = self._put(self._damping.astype(np.float64))
        self._constrained = self._put(self.loading.constrained.astype(np.uint8))
        ld = self.loading
        self._displacement = [_DeviceBound(b, self._put) for b in ld.displacement]
        self._velocity = [_DeviceBound(b, self._put) for b in ld.velocity]
        self._body_force = [_DeviceBound(b, self._put) for b in ld.body_force]
        self._counter = wp.zeros(1, dtype=wp.int32, device=self.device)
        # Peridigm's differenced velocity: the DOFs, u before the step and their force acceleration
        self._diff_mask = self._u_before = None
        self._free_d = wp.zeros((1, 3), dtype=wp.float64, device=self.device)  # unused without it
        if self._differenced is not None:
            self._diff_mask = self._put(self._differenced.astype(np.uint8))
            self._u_before = wp.zeros((n, 3), dtype=wp.float64, device=self.device)
            self._free_d = wp.zeros((n, 3), dtype=wp.float64, device=self.device)
        self._limit = None
        if damage is not None:
            self._limit = self.force_on_device.per_bond(damage.critical_lengths(), np.inf)
        self._probes = {}  # id -> (probe points, their device indices, output buffer)
        #: directed bonds broken on the device so far
        self.bonds_broken = 0

    def __repr__(self) -> str:
        return f"GPUExplicitSolver(model={self.model!r}, dt={self.dt:.4g} s, device={self.device!r})"

    @property
    def device_name(self) -> str:
        """The device's name, e.g. ``"NVIDIA H200"`` (``"CPU"`` on Warp's CPU device)."""
        return device_description(self.device)

    def _put(self, array: np.ndarray):
        dtype = {np.dtype(np.float64): self.wp.float64, np.dtype(np.int32): self.wp.int32}.get(
            array.dtype, self.wp.uint8
        )
        return self.wp.array(np.ascontiguousarray(array), dtype=dtype, device=self.device)

    def _launch(self, kernel, dim, inputs):
        self.wp.launch(kernel, dim=dim, inputs=inputs, device=self.device)

    def upload(self, state: State) -> None:
        """Copy ``state``'s u, v, a and the bonds' intact mask to the device."""
        for dev, host in ((self._u, state.u), (self._v, state.v), (self._a, state.a)):
            dev.assign(np.ascontiguousarray(host, dtype=np.float64))
        fd = self.force_on_device
        fd.intact.assign(fd.slots.to_ell(self.model.bonds.intact, np.uint8))

    def device_array(self, name: str):
        """The device's ``"u"``, ``"v"`` or ``"a"`` (a Warp (n_points, 3) float64 array)."""
        return {"u": self._u, "v": self._v, "a": self._a}[name]

    def initial_state(self) -> State:
        state = State.zeros(self.model.body.n_points)
        self.loading.apply_start(self.dt, state.u, state.v, rates=self._differenced is None)
        self.upload(state)
        self._device_acceleration(0.0, kick=False)
        state.a[:] = self._a.numpy()
        return state

    def _prescribe(self, bounds, target, values, add: int) -> None:
        for db, value in zip(bounds, values, strict=True):
            amplitude, scale = db.inputs(value)
            self._launch(prescribe_kernel(), db.shape, [target, db.index, db.comps, amplitude, scale, add])

    def _device_acceleration(self, time: float, kick: bool) -> None:
        """a (and with ``kick`` the closing half step of v) from the force at the device's u."""
        f = self.force_on_device.compute(self._u)
        if self._body_force:
            self._b.zero_()
            self._prescribe(self._body_force, self._b, [db.value(time) for db in self._body_force], 1)
        inputs = [f, self._b, self._inv_rho_d, self._damping_d, self._v, self._constrained, self._a]
        n = self.model.body.n_points
        keep = int(self._differenced is not None)
        inputs = [*inputs, int(kick), 0.5 * self.dt, keep, self._free_d]
        self._launch(acceleration_kernel(self.force_on_device.scalar), (n, 3), inputs)

    def step(self, state) -> int:
        """Advance the device state by one step (``state``: the :class:`DeviceState` of
        :meth:`run`, whose time and step are advanced); returns the number of bonds broken."""
        dt = self.dt
        n = self.model.body.n_points
        differenced = self._differenced is not None
        if differenced:
            self.wp.copy(self._u_before, self._u)
        self._launch(kick_drift_kernel(), (n, 3), [self._u, self._v, self._a, 0.5 * dt, dt])
        state.time += dt
        state.step += 1
        t = state.time
        if self._displacement:
            self._prescribe(self._displacement, self._u, [db.value(t) for db in self._displacement], 0)
            if not differenced:
                self._prescribe(self._displacement, self._v, [db.rate(t, dt) for db in self._displacement], 0)
        broken = self._break_bonds() if self._limit is not None else 0
        self._device_acceleration(t, kick=True)
        if self._velocity:
            self._prescribe(self._velocity, self._v, [db.value(t) for db in self._velocity], 0)
        if differenced:
            inputs = [self._u, self._u_before, self._free_d, self._diff_mask, dt, 0.5 * dt, self._v]
            self._launch(difference_velocity_kernel(), (n, 3), inputs)
        if state.step % self.check_every == 0:
            self._check(state)
        return broken

    def _break_bonds(self) -> int:
        """Break the over-stretched bonds on the device; the count (read back), and the intact
        mask copied to ``bonds.intact`` when some broke."""
        fd = self.force_on_device
        self._counter.zero_()
        inputs = [*fd.xi, self._u, fd.count, fd.nbr, self._limit, fd.intact, self._counter]
        self._launch(stretch_break_kernel(), self.model.body.n_points, inputs)
        broken = int(self._counter.numpy()[0])
        if broken:
            self.model.bonds.intact[:] = fd.intact_host()
            self.bonds_broken += broken
        return broken

    def probe_values(self, state, u_points: np.ndarray, v_points: np.ndarray, limit: float):
        """u at the points ``u_points`` (k,) and v at ``v_points`` (s,) of the device state, (k, 3)
        and (s, 3) float64, after checking the whole state on the device against the runaway
        ``limit`` (m; InstabilityError naming the point, from the host check, when unsound)."""
        self._check(state, limit)
        values = []
        for field, points in ((self._u, u_points), (self._v, v_points)):
            index, out = self._probe_buffers(points)
            if len(points):
                self._launch(gather_rows_kernel(), (len(points), 3), [field, index, out])
            values.append(out.numpy())
        return values[0], values[1]

    def _probe_buffers(self, points: np.ndarray):
        """The device copy of the probe indices ``points`` (k,) and a (k, 3) output buffer, made on
        the first call with these points (a run's recorder asks for the same ones every time)."""
        key = id(points)
        if key not in self._probes or self._probes[key][0] is not points:
            index = self._put(np.asarray(points, dtype=np.int32))
            out = self.wp.zeros((len(points), 3), dtype=self.wp.float64, device=self.device)
            self._probes[key] = (points, index, out)
        return self._probes[key][1:]

    def _check(self, state, limit: float | None = None) -> None:
        """Count the unsound points on the device (``limit``: the runaway displacement, m; None:
        the solver's); when there is one, the host check names it."""
        limit = self.max_displacement if limit is None else limit
        self._counter.zero_()
        self._launch(
            unsound_kernel(), self.model.body.n_points, [self._u, self._v, float(limit), self._counter]
        )
        if int(self._counter.numpy()[0]):
            self.domain.check_state(state.sync() if isinstance(state, DeviceState) else state, limit)

    def run(self, state: State, n_steps: int, observers: Sequence = (), progress=None) -> State:
        """Advance the host ``state`` by ``n_steps`` steps on the device (uploaded first, copied
        back at the end, also when an error or an interrupt ends the loop)."""
        self.upload(state)
        on_device = DeviceState(self, state)
        try:
            advance(self, on_device, n_steps, observers, progress)
        finally:
            on_device.sync()
        self.domain.check_state(state, self.max_displacement)
        return state
