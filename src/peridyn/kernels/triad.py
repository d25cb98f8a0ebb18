"""STREAM triad ``a = b + s c``: the memory-bandwidth probe of ``peridyn bench``."""

import numba


@numba.njit(parallel=True, cache=True)
def triad(a, b, c, s):
    for i in numba.prange(a.shape[0]):
        a[i] = b[i] + s * c[i]
