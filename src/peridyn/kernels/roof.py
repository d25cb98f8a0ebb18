"""Square-root and division throughput: the compute-roof probes of ``peridyn bench``.

Each row of ``buf`` (shape (rows, m), m small enough to stay in the L1 cache) is iterated
``reps`` times in place, one row per thread: ``x <- sqrt(x + c)`` or ``x <- c / x``. The m
elements of a row are independent, so the loop vectorises and measures the packed
throughput (not the latency) of the operation, as the force kernels use it. With a ``c``
and a start of no special form (not a power of two) the values keep full mantissas, as the
force kernels' do: some dividers finish early on operands such as 1.0 or 2.0.
"""

import numba
import numpy as np


@numba.njit(parallel=True, cache=True)
def sqrt_probe(buf, c, reps):
    """``buf`` (IN/OUT, (rows, m)): every element x replaced ``reps`` times by ``sqrt(x + c)``."""
    for r in numba.prange(buf.shape[0]):
        row = buf[r]
        for _ in range(reps):
            for i in range(row.shape[0]):
                row[i] = np.sqrt(row[i] + c)
    return buf


@numba.njit(parallel=True, cache=True)
def div_probe(buf, c, reps):
    """``buf`` (IN/OUT, (rows, m)): every element replaced ``reps`` times by ``c / element``."""
    for r in numba.prange(buf.shape[0]):
        row = buf[r]
        for _ in range(reps):
            for i in range(row.shape[0]):
                row[i] = c / row[i]
    return buf
