"""Numba CPU kernels: pure functions of arrays, no checks, no objects.

Layout expected by every kernel (the drivers in ``peridyn.materials`` and
``peridyn.solvers`` normalise inputs once):

- ``x, u, f``: (n_points, 3) C-contiguous, float64 or float32 (all the same);
- ``offsets``: (n_points + 1,) int64; ``nbr``: (n_bonds,) int32 (CSR families);
- per-bond arrays (n_bonds,) and per-point arrays (n_points,) of the float dtype;
- ``intact``: (n_bonds,) bool.

``reference.py`` holds plain NumPy versions used by the tests.
"""

#: Fast-math flags used by the force kernels: reassociation lets LLVM vectorise
#: the per-point sums; NaN/inf semantics are kept so blow-ups are still detected.
FASTMATH = {"reassoc", "contract", "nsz", "arcp"}
