"""``peridyn.kernels.bond_differences`` and ``deformed_component`` against their NumPy references."""

import numpy as np
import pytest

from peridyn.kernels import bond_differences, deformed_component
from peridyn.kernels.reference import bond_differences as reference
from peridyn.kernels.reference import deformed_component as deformed_reference

pytestmark = pytest.mark.kernels


@pytest.mark.bitwise
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_bond_differences(rng, dtype):
    """(xj - xi, uj - ui, xi_a + du_a), exactly: compiled without fast-math, its three
    roundings are its definition; swapping the ends negates all three exactly (round to
    nearest is symmetric), which is what Newton's third law of the force kernels rests on."""
    xj, xi = (rng.uniform(0.0, 1e-2, 50).astype(dtype) for _ in range(2))
    uj, ui = (1e-6 * rng.standard_normal(50).astype(dtype) for _ in range(2))
    got = np.array([bond_differences(*args) for args in zip(xj, xi, uj, ui, strict=True)]).T
    for component, expected in zip(got, reference(xj, xi, uj, ui), strict=True):
        np.testing.assert_array_equal(component, expected)
    swapped = np.array([bond_differences(*args) for args in zip(xi, xj, ui, uj, strict=True)]).T
    np.testing.assert_array_equal(swapped, -got)


@pytest.mark.bitwise
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_deformed_component_from_a_stored_reference_vector(rng, dtype):
    """``xi + (uj - ui)`` exactly (its reference, in the dtype); with ``xi = xj - xi`` rounded as
    ``bond_differences`` rounds it, the very bits of that function's Y: why the force kernels
    that read stored bond vectors compute the same forces as those that gathered x."""
    xj, xi = (rng.uniform(0.0, 1e-2, 50).astype(dtype) for _ in range(2))
    uj, ui = (1e-6 * rng.standard_normal(50).astype(dtype) for _ in range(2))
    stored = xj - xi
    got = np.array([deformed_component(*args) for args in zip(stored, uj, ui, strict=True)])
    np.testing.assert_array_equal(got, deformed_reference(stored, uj, ui))
    _, _, y = reference(xj, xi, uj, ui)
    np.testing.assert_array_equal(got, y)
    swapped = np.array([deformed_component(*args) for args in zip(-stored, ui, uj, strict=True)])
    np.testing.assert_array_equal(swapped, -got)
