"""Plain NumPy references of the numba kernels, used by the tests in ``tests/kernels``.

One module per kernel module (``reference.pmb`` for ``kernels.pmb``, ...), one function per
kernel, named as the kernel and taking its arguments less the OUT array; it returns what
the kernel writes or returns (IN/OUT arrays are not touched: their new value is returned).
Each is written from the definition in the kernel's docstring, vectorised over bonds
(``np.add.at``, ``np.bincount``, dense matrices), not transcribed from the loops: slow, but
obviously correct. The kernels' private helpers (``damage._test_family``,
``damage._break_reverse``) are part of the public kernel that calls them and are checked
through it.

Floating-point inputs are evaluated in float64 whatever their dtype, so a float32 kernel
is compared with the value of its own inputs to double precision. The exceptions are the
references of the kernels whose roundings are part of their definition
(:func:`bond_differences`, ``damage.squared_length``, ``triad``, ``roof``): those compute in the
input dtype, operation by operation.

This module holds the helpers shared by the references of the bond kernels.
"""

import numpy as np


def bond_differences(xj, xi, uj, ui):
    """``(xj - xi, uj - ui, (xj - xi) + (uj - ui))`` in the inputs' dtype: the reference of
    :func:`peridyn.kernels.bond_differences` (any shapes that broadcast)."""
    d = xj - xi
    du = uj - ui
    return d, du, d + du


def deformed_component(xi, uj, ui):
    """``xi + (uj - ui)`` in the inputs' dtype: the reference of
    :func:`peridyn.kernels.deformed_component`."""
    return xi + (uj - ui)


def owners(offsets):
    """(n_bonds,) int64: the point whose CSR family holds each directed bond."""
    return np.repeat(np.arange(len(offsets) - 1), np.diff(offsets))


def bond_vectors(x, u, offsets, nbr):
    """Bond vectors of every directed bond i->j, float64 (n_bonds, 3), m:
    ``xi = x_j - x_i``, ``du = u_j - u_i`` and ``Y = xi + du``."""
    i = owners(offsets)
    j = np.asarray(nbr, dtype=np.int64)
    x = np.asarray(x, dtype=np.float64)
    u = np.asarray(u, dtype=np.float64)
    xi = x[j] - x[i]
    du = u[j] - u[i]
    return xi, du, xi + du


def deformed_vectors(xi, u, offsets, nbr):
    """(n_bonds, 3) float64, m: ``Y = xi + (u_j - u_i)`` of every directed bond from its stored
    reference vector ``xi`` (n_bonds, 3) (the float64 force kernels' input)."""
    i = owners(offsets)
    j = np.asarray(nbr, dtype=np.int64)
    u = np.asarray(u, dtype=np.float64)
    return np.asarray(xi, dtype=np.float64) + (u[j] - u[i])


def stored_extension(xi, u, offsets, nbr, length):
    """``(|xi|, e, Y)`` as :func:`extension` with a stored ``length``, from the stored reference
    vectors ``xi`` (n_bonds, 3) instead of the points: the float64 force kernels' inputs."""
    length = np.asarray(length, dtype=np.float64)
    y = deformed_vectors(xi, u, offsets, nbr)
    return length, np.linalg.norm(y, axis=1) - length, y


def extension(x, u, offsets, nbr, length=None):
    """``(|xi|, e, Y)`` of every directed bond: (n_bonds,), (n_bonds,) and (n_bonds, 3) float64, m.

    The extension is ``e = |Y| - |xi|``. With a stored ``length`` (n_bonds,), |xi| is that
    and ``e = |Y| - length`` (the cancellation is then part of the definition: the stored
    length is only known to its last bit). With ``length`` None, |xi| = |x_j - x_i| and e is
    taken from the identity ``|Y| - |xi| = du . (Y + xi) / (|Y| + |xi|)``, exact algebra
    (|Y|^2 - |xi|^2 = (Y - xi) . (Y + xi)) with no cancellation, so that e keeps its precision
    relative to |du| however small the strain.
    """
    xi, du, y = bond_vectors(x, u, offsets, nbr)
    r = np.linalg.norm(y, axis=1)
    if length is not None:
        length = np.asarray(length, dtype=np.float64)
        return length, r - length, y
    length = np.linalg.norm(xi, axis=1)
    return length, np.einsum("ba,ba->b", du, y + xi) / (r + length), y


def unit_vectors(x, offsets, nbr, length):
    """(n_bonds, 3) float64: reference bond directions n = xi / |xi|, |xi| the stored ``length``."""
    xi, _, _ = bond_vectors(x, np.zeros_like(x), offsets, nbr)
    return xi / np.asarray(length, dtype=np.float64)[:, None]


def bond_index(offsets, nbr, first, second):
    """(n_pairs,) int64: index of the directed bond first[p] -> second[p] in the CSR families,
    or -1 where there is none."""
    n = len(offsets) - 1
    key = owners(offsets) * n + np.asarray(nbr, dtype=np.int64)
    order = np.argsort(key, kind="stable")
    wanted = np.asarray(first, dtype=np.int64) * n + np.asarray(second, dtype=np.int64)
    pos = np.minimum(np.searchsorted(key[order], wanted), len(key) - 1)
    return np.where(key[order][pos] == wanted, order[pos], -1)


def family_sum(offsets, values):
    """Sum of per-bond ``values`` (n_bonds, ...) over each point's family: (n_points, ...)."""
    values = np.asarray(values, dtype=np.float64)
    out = np.zeros((len(offsets) - 1,) + values.shape[1:])
    np.add.at(out, owners(offsets), values)
    return out


def as64(*arrays):
    """The arrays as float64 (a list)."""
    return [np.asarray(a, dtype=np.float64) for a in arrays]
