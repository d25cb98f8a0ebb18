"""Compute-roof probes (``peridyn.kernels.roof``) against their NumPy reference."""

import numpy as np
import pytest

from peridyn.kernels.reference import roof as ref
from peridyn.kernels.roof import div_probe, sqrt_probe

pytestmark = pytest.mark.kernels


@pytest.mark.bitwise
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_sqrt_probe(rng, dtype):
    """Exactly NumPy's iterated sqrt(x + c): compiled without fast-math, each operation is rounded once."""
    buf = rng.uniform(0.5, 4.0, (3, 40)).astype(dtype)
    c = dtype(1.7)
    expected = ref.sqrt_probe(buf, c, 3)
    np.testing.assert_array_equal(sqrt_probe(buf, c, 3), expected)


@pytest.mark.bitwise
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_div_probe(rng, dtype):
    """Exactly NumPy's iterated c / x: compiled without fast-math, IEEE division is correctly rounded."""
    buf = rng.uniform(0.5, 4.0, (3, 40)).astype(dtype)
    c = dtype(1.7)
    expected = ref.div_probe(buf, c, 3)
    np.testing.assert_array_equal(div_probe(buf, c, 3), expected)
