"""Boundary and initial conditions on node sets, per displacement component.

Kinds of boundary condition:

- ``displacement``: u[set, c] = profile * f(t) (m); the velocity follows by difference;
- ``velocity``: v[set, c] = profile * f(t) (m/s); the displacement integrates it;
- ``force``: a total force f(t) (N) per component, spread over the set as a uniform
  body-force density f(t) / (sum of the set's volumes);
- ``body_force``: body-force density b[set, c] = profile * f(t) (N/m^3).

A force on a component whose motion another condition prescribes is an error, unless the force
condition says ``where_prescribed="yield"``: the prescribed motion then wins, the force still
counting in the point's acceleration (as in Peridigm).

``profile`` is an optional spatial amplitude, (n_set,) or (n_set, n_components),
e.g. the radial displacement field of a PZT patch. ``f`` may instead be an expression in
x, y, z and t (``peridyn.physics.expressions.SpaceTime``), evaluated on the set's points.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from peridyn.discretization.body import Body
from peridyn.errors import InputError, did_you_mean
from peridyn.physics.expressions import SpaceTime
from peridyn.physics.timefunctions import Constant, TimeFunction

BC_KINDS = ("displacement", "velocity", "force", "body_force")
IC_KINDS = ("displacement", "velocity")
COMPONENTS = {"x": 0, "y": 1, "z": 2}


def parse_components(components) -> tuple[int, ...]:
    """Component indices from "x", "xy", ["x", "z"] or [0, 2]."""
    if isinstance(components, str):
        components = list(components)
    out = []
    for c in components:
        if isinstance(c, str):
            if c not in COMPONENTS:
                raise InputError(f"unknown component {c!r}: use x, y or z")
            out.append(COMPONENTS[c])
        elif c in (0, 1, 2):
            out.append(int(c))
        else:
            raise InputError(f"unknown component {c!r}: use x, y, z or 0, 1, 2")
    if not out or len(set(out)) != len(out):
        raise InputError(f"components must be distinct and not empty, got {components!r}")
    return tuple(out)


@dataclass(frozen=True)
class BoundaryCondition:
    """A condition on the components of a node set over time (see the module docstring)."""

    node_set: str
    kind: str
    components: tuple = (0, 1, 2)
    function: TimeFunction | SpaceTime = field(default_factory=lambda: Constant(0.0))
    profile: np.ndarray | None = None
    #: a force on a component whose motion is prescribed: "error", or "yield" to the motion
    where_prescribed: str = "error"

    def __post_init__(self):
        if self.where_prescribed not in ("error", "yield"):
            raise InputError(f"where_prescribed {self.where_prescribed!r}: use 'error' or 'yield'")
        if self.kind not in BC_KINDS:
            raise InputError(
                f"unknown boundary condition kind {self.kind!r}"
                f"{did_you_mean(self.kind, BC_KINDS)}; choose one of {BC_KINDS}"
            )
        object.__setattr__(self, "components", parse_components(self.components))


@dataclass(frozen=True)
class InitialCondition:
    """u or v of the components of a node set at t = 0: ``value`` (float or (n_set, n_comp))."""

    node_set: str
    kind: str
    components: tuple = (0, 1, 2)
    value: float | np.ndarray = 0.0

    def __post_init__(self):
        if self.kind not in IC_KINDS:
            raise InputError(f"unknown initial condition kind {self.kind!r}; choose one of {IC_KINDS}")
        object.__setattr__(self, "components", parse_components(self.components))


@dataclass
class _Bound:
    index: np.ndarray  # (n_set,) point indices
    components: tuple
    function: TimeFunction | SpaceTime
    amplitude: np.ndarray  # (n_set, n_comp)
    points: np.ndarray | None = None  # (n_set, 3) m, the set's points for a SpaceTime function

    def value(self, t: float) -> np.ndarray:
        """amplitude * f(t), (n_set, n_comp)."""
        if self.points is None:
            return self.amplitude * self.function(t)
        return self.amplitude * self.function.at(self.points, t)[:, None]

    def rate(self, t: float, dt: float) -> np.ndarray:
        """amplitude * f'(t) by f's central difference, (n_set, n_comp)."""
        if self.points is None:
            return self.amplitude * self.function.derivative(t, dt)
        return self.amplitude * self.function.derivative(self.points, t, dt)[:, None]


class Loading:
    """Boundary conditions bound to a body, checked for conflicts.

    Parameters
    ----------
    body : Body
    conditions, initial : sequences of BoundaryCondition and InitialCondition
    set_volume : callable or None
        ``body`` is a rank's part (``peridyn.parallel``): ``set_volume(name, idx)`` is the volume
        (m^3) of the whole set ``name`` of which the part holds the points ``idx`` (a force's
        spread), and a set may hold none of the part's points. None: ``body`` is whole.

    Attributes
    ----------
    constrained : (n_points, 3) bool
        DOFs whose motion is prescribed (displacement or velocity).
    """

    def __init__(self, body: Body, conditions=(), initial=(), set_volume=None):
        self.body = body
        self._set_volume = set_volume
        self.displacement: list[_Bound] = []
        self.velocity: list[_Bound] = []
        self.body_force: list[_Bound] = []
        self.initial = list(initial)
        self.constrained = np.zeros((body.n_points, 3), dtype=bool)
        owner = np.full((body.n_points, 3), -1)
        forced = np.zeros((body.n_points, 3), dtype=bool)
        for number, bc in enumerate(conditions):
            bound = self._bind(bc)
            idx, comps = bound.index, list(bound.components)
            if bc.kind in ("displacement", "velocity"):
                taken = owner[np.ix_(idx, comps)]
                if np.any(taken >= 0):
                    other = conditions[int(taken[taken >= 0][0])]
                    raise InputError(
                        f"boundary conditions on sets {other.node_set!r} ({other.kind}) and "
                        f"{bc.node_set!r} ({bc.kind}) prescribe the same component of the same "
                        "points: a point's motion can be prescribed only once"
                    )
                owner[np.ix_(idx, comps)] = number
                (self.displacement if bc.kind == "displacement" else self.velocity).append(bound)
            else:
                if bc.where_prescribed == "error":
                    forced[np.ix_(idx, comps)] = True
                if bc.kind == "force":
                    whole = body.volumes[idx].sum() if set_volume is None else set_volume(bc.node_set, idx)
                    bound.amplitude = bound.amplitude / whole
                self.body_force.append(bound)
        self.constrained = owner >= 0
        self._initial = [(ic.kind, self._bind_initial(ic)) for ic in self.initial]
        clash = self.constrained & forced
        if clash.any():
            point = int(np.flatnonzero(clash.any(axis=1))[0])
            raise InputError(
                f"point {point} has both a prescribed motion and an applied force on the same "
                "component: the force would be ignored"
            )

    def _points(self, name: str) -> np.ndarray:
        """The indices of set ``name``: on a part (``set_volume`` given) possibly none."""
        return self.body.node_set(name, self._set_volume is not None)

    def _bind(self, bc: BoundaryCondition) -> _Bound:
        idx = self._points(bc.node_set)
        amplitude = _amplitude(bc.profile, len(idx), len(bc.components), bc.node_set)
        points = self.body.points[idx] if isinstance(bc.function, SpaceTime) else None
        return _Bound(idx, bc.components, bc.function, amplitude, points)

    def _bind_initial(self, ic: InitialCondition) -> _Bound:
        idx = self._points(ic.node_set)
        amp = _amplitude(ic.value, len(idx), len(ic.components), ic.node_set)
        return _Bound(idx, ic.components, Constant(1.0), amp)

    def restricted(self, body: Body, points: np.ndarray) -> Loading:
        """This loading on the part ``body`` of its body made of the points ``points`` ((k,)
        indices into ``self.body``, in ``body``'s order): every condition keeps its values
        (a force's spread over the whole set included) on the points taken."""
        new_index = np.full(self.body.n_points, -1, dtype=np.int64)
        new_index[np.asarray(points, dtype=np.int64)] = np.arange(len(points))

        def restrict(b: _Bound) -> _Bound:
            local = new_index[b.index]
            keep = local >= 0
            points = None if b.points is None else b.points[keep]
            return _Bound(local[keep], b.components, b.function, b.amplitude[keep], points)

        part = Loading(body)
        part.displacement = [restrict(b) for b in self.displacement]
        part.velocity = [restrict(b) for b in self.velocity]
        part.body_force = [restrict(b) for b in self.body_force]
        part.initial = list(self.initial)
        part._initial = [(kind, restrict(b)) for kind, b in self._initial]
        part.constrained = self.constrained[points]
        return part

    @property
    def has_loads(self) -> bool:
        """True when any boundary condition is defined."""
        return bool(self.displacement or self.velocity or self.body_force)

    def apply_initial(self, u: np.ndarray, v: np.ndarray) -> None:
        """Write the initial conditions into ``u`` and ``v`` (IN/OUT, (n_points, 3))."""
        for kind, b in self._initial:
            target = u if kind == "displacement" else v
            target[np.ix_(b.index, list(b.components))] = b.amplitude

    def apply_start(self, dt: float, u: np.ndarray, v: np.ndarray, rates: bool = True) -> None:
        """The state of a dynamic run at t = 0 (IN/OUT): initial conditions, then the
        prescribed displacements and velocities at t = 0 (``dt``: step, for derivatives;
        ``rates``: see ``apply_kinematics``)."""
        self.apply_initial(u, v)
        self.apply_kinematics(0.0, dt, u, v, rates)
        self.apply_velocities(0.0, v)

    def apply_kinematics(self, t: float, dt: float, u: np.ndarray, v: np.ndarray, rates: bool = True) -> None:
        """Impose the prescribed displacements at time ``t`` (IN/OUT) and, with ``rates``,
        their velocity (the time function's central difference over ``dt``)."""
        for b in self.displacement:
            cols = list(b.components)
            u[np.ix_(b.index, cols)] = b.value(t)
            if rates:
                v[np.ix_(b.index, cols)] = b.rate(t, dt)

    @property
    def displaced(self) -> np.ndarray:
        """(n_points, 3) bool: the DOFs with a prescribed displacement."""
        mask = np.zeros((self.body.n_points, 3), dtype=bool)
        for b in self.displacement:
            mask[np.ix_(b.index, list(b.components))] = True
        return mask

    def apply_velocities(self, t: float, v: np.ndarray) -> None:
        """Impose the prescribed velocities at time ``t`` (IN/OUT ``v``)."""
        for b in self.velocity:
            v[np.ix_(b.index, list(b.components))] = b.value(t)

    def body_force_density(self, t: float, out: np.ndarray) -> np.ndarray:
        """External body-force density at ``t``, N/m^3, written into ``out`` (n_points, 3)."""
        out[:] = 0.0
        for b in self.body_force:
            out[np.ix_(b.index, list(b.components))] += b.value(t)
        return out


def _amplitude(profile, n: int, n_comp: int, name: str) -> np.ndarray:
    if profile is None:
        return np.ones((n, n_comp))
    arr = np.asarray(profile, dtype=float)
    if arr.ndim == 0:
        return np.full((n, n_comp), float(arr))
    if arr.shape == (n,):
        arr = np.repeat(arr[:, None], n_comp, axis=1)
    if arr.shape == (n_comp,):
        arr = np.broadcast_to(arr, (n, n_comp)).copy()
    if arr.shape != (n, n_comp):
        raise InputError(f"profile for set {name!r} must have shape ({n}, {n_comp}), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"profile for set {name!r} has non-finite values")
    return arr
