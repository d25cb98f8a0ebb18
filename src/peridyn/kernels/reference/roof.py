"""Reference of ``peridyn.kernels.roof``: the square-root and division probes."""

import numpy as np


def sqrt_probe(buf, c, reps):
    """``buf`` with every element x replaced ``reps`` times by ``sqrt(x + c)`` (a new array)."""
    out = buf.copy()
    for _ in range(reps):
        out = np.sqrt(out + c)
    return out


def div_probe(buf, c, reps):
    """``buf`` with every element replaced ``reps`` times by ``c / element`` (a new array)."""
    out = buf.copy()
    for _ in range(reps):
        out = c / out
    return out
