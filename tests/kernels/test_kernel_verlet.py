"""Velocity-Verlet kernels (``peridyn.kernels.verlet``) against their NumPy references
(``kernels.reference.verlet``). Their roundings are their definition (compiled without
fast-math: no fused multiply-add, signed zeros kept), so the comparison is exact, bit for
bit, signed zeros included."""

import numpy as np
import pytest

from peridyn.kernels import verlet
from peridyn.kernels.reference import verlet as ref

pytestmark = pytest.mark.kernels

N = 200


def _same_bits(got, want):
    assert got.dtype == want.dtype
    np.testing.assert_array_equal(got.view(np.uint64), want.view(np.uint64))


def _fields(rng):
    """u, v, a with signed zeros among them (a -0.0 + 0.0 would show)."""
    u, v, a = (rng.standard_normal((N, 3)) * s for s in (1e-6, 1e-2, 1e4))
    for x in (u, v, a):
        x[rng.random((N, 3)) < 0.1] = -0.0
    return u, v, a


def test_kick_drift_rounds_as_numpy(rng):
    u, v, a = _fields(rng)
    want_u, want_v = ref.kick_drift(u, v, a, 0.5 * 1.07e-7, 1.07e-7)
    verlet.kick_drift(u, v, a, 0.5 * 1.07e-7, 1.07e-7)
    _same_bits(u, want_u)
    _same_bits(v, want_v)


@pytest.mark.parametrize("damping", ["none", "one", "per point"])
@pytest.mark.parametrize("force_dtype", [np.float64, np.float32])
@pytest.mark.parametrize("kick", [False, True])
@pytest.mark.parametrize("divide", [False, True])
def test_acceleration_rounds_as_numpy(rng, damping, force_dtype, kick, divide):
    _, v, _ = _fields(rng)
    f = (rng.standard_normal((N, 3)) * 1e7).astype(force_dtype)
    f[rng.random((N, 3)) < 0.1] = -0.0
    b = np.zeros((N, 3))
    b[: N // 2] = rng.standard_normal((N // 2, 3)) * 1e3
    rho = rng.uniform(1000.0, 8000.0, N)
    rho = rho if divide else 1.0 / rho  # the density, or its inverse
    c = {"none": np.zeros(0), "one": np.array([3e4]), "per point": rng.uniform(0.0, 1e5, N)}[damping]
    constrained = rng.random((N, 3)) < 0.2
    want_a, want_v = ref.acceleration(f, b, rho, c, v, constrained, kick, 0.5e-7, divide)
    a = np.full((N, 3), np.nan)
    verlet.acceleration(f, b, rho, c, v, constrained, a, kick, 0.5e-7, divide)
    _same_bits(a, want_a)
    _same_bits(v, want_v)


@pytest.mark.parametrize(
    "spoil, sound",
    [(None, True), (("u", 2.0), False), (("u", -2.0), False), (("u", np.nan), False), (("v", np.inf), False)],
)
def test_state_is_sound(rng, spoil, sound):
    u, v, _ = _fields(rng)
    u *= 1e5  # |u| up to about 0.5 m, under the limit of 1 m
    if spoil is not None:
        field, value = spoil
        (u if field == "u" else v)[N // 3, 1] = value
    assert ref.state_is_sound(u, v, 1.0) is sound
    assert verlet.state_is_sound(u, v, 1.0) is sound
