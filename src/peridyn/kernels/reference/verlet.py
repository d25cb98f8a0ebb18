"""References of ``peridyn.kernels.verlet``: the NumPy expressions of a velocity-Verlet step
(the kernels' roundings are their definition, so these compute in the inputs' dtypes,
operation by operation, as ``ExplicitSolver`` did before the kernels)."""

import numpy as np


def kick_drift(u, v, a, half_dt, dt):
    """``(u + dt * v', v')`` with ``v' = v + half_dt * a``."""
    v = v + half_dt * a
    return u + dt * v, v


def acceleration(f, b, rho, damping, v, constrained, kick, half_dt, divide=False):
    """``(a, v')``: ``a = (f + b) * rho[:, None] - damping * v`` (``/ rho[:, None]`` with
    ``divide``; no damping term for an empty ``damping``), zero where ``constrained``;
    ``v' = v + half_dt * a`` with ``kick``, else ``v``."""
    a = np.add(f, b, dtype=np.float64)
    if divide:
        a /= rho[:, None]
    else:
        a *= rho[:, None]
    if len(damping):
        a -= (damping if len(damping) == 1 else damping[:, None]) * v
    a[constrained] = 0.0
    return a, (v + half_dt * a if kick else v.copy())


def state_is_sound(u, v, max_displacement):
    """``max |u| <= max_displacement`` (false with a NaN) and every ``v`` finite."""
    return bool(np.max(np.abs(u), initial=0.0) <= max_displacement and np.isfinite(v).all())
