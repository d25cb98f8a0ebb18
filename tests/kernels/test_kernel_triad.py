"""STREAM triad (``peridyn.kernels.triad``) against its NumPy reference."""

import numpy as np
import pytest

from peridyn.kernels.reference import triad as ref
from peridyn.kernels.triad import triad

pytestmark = pytest.mark.kernels


@pytest.mark.bitwise
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_triad(rng, dtype):
    """a = b + s c, exactly: compiled without fast-math, one product and one sum, each
    rounded as NumPy rounds them (no fused multiply-add)."""
    b, c = (rng.standard_normal(1000).astype(dtype) for _ in range(2))
    s = dtype(0.37)
    a = np.full_like(b, np.nan)
    triad(a, b, c, s)
    np.testing.assert_array_equal(a, ref.triad(b, c, s))
