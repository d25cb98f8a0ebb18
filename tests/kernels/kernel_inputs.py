"""Small random inputs and the comparison rule shared by the kernel tests (``tests/kernels``).

The inputs are kept small (tens of points, about a thousand directed bonds) so that the
whole folder also runs in a minute or two with the JIT off
(``NUMBA_DISABLE_JIT=1 PYTHONPATH=src python -m pytest -m kernels -q -p no:cacheprovider``),
where the kernels run as plain Python.

Tolerances. A kernel and its reference evaluate the same sums in different orders and
with different roundings (the force kernels fuse multiply-adds, the references sum with
``np.add.at``). Each term of a sum then carries a few roundings, so the
difference is bounded by a small multiple of the unit roundoff times the sum of the terms'
magnitudes (the ``scale`` of :func:`assert_close`), with at most ~100 terms per sum here:

- float64 (unit roundoff 1.1e-16): ``TOL64 = 1e-12`` of the scale;
- float32 (6e-8): ``TOL32 = 1e-5`` of the scale (the references evaluate in float64).
"""

from dataclasses import dataclass, replace

import numpy as np

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.kernels.reference import family_sum

TOL64 = 1e-12
TOL32 = 1e-5
TOL = {np.float64: TOL64, np.float32: TOL32}

#: Grid spacing of the inputs, m.
SPACING = 1e-3


@dataclass(frozen=True)
class Families:
    """CSR bond families of a small jittered grid, with some bonds broken.

    x (n, 3) float64 m; volumes (n,) m^3; offsets (n + 1,) int64; nbr (n_bonds,) int32;
    length (n_bonds,) m; intact (n_bonds,) bool.
    """

    x: np.ndarray
    volumes: np.ndarray
    offsets: np.ndarray
    nbr: np.ndarray
    length: np.ndarray
    intact: np.ndarray

    @property
    def n(self) -> int:
        return len(self.x)

    @property
    def n_bonds(self) -> int:
        return len(self.nbr)


def jittered_families(
    rng, shape=(4, 4, 3), horizon_factor=2.015, broken=0.1, partial_volumes=True
) -> Families:
    """Families of a ``shape`` grid of spacing ``SPACING`` whose points are moved at random by up
    to 0.1 spacing per axis (so no two bonds are alike), partial volumes as asked, and a share
    ``broken`` of the directed bonds broken at random (one copy of a bond may be broken
    without the other: the kernels must not assume otherwise)."""
    body = geometry.box(tuple(k * SPACING for k in shape), SPACING)
    body = replace(body, points=body.points + 0.1 * SPACING * rng.uniform(-1.0, 1.0, body.points.shape))
    bonds = find_bonds(body, horizon_factor * SPACING, partial_volumes=partial_volumes)
    return Families(
        x=body.points,
        volumes=body.volumes,
        offsets=bonds.offsets,
        nbr=bonds.neighbours,
        length=bonds.length,
        intact=rng.random(bonds.n_bonds) >= broken,
    )


def per_bond(rng, fam: Families, scale=1.0) -> np.ndarray:
    """(n_bonds,) float64 positive per-bond coefficients, uniform in [0.5, 1.5] ``scale``."""
    return scale * rng.uniform(0.5, 1.5, fam.n_bonds)


def displacement(rng, fam: Families, strain: float) -> np.ndarray:
    """(n, 3) float64 random displacement, m, of typical bond strain ``strain``."""
    return strain * SPACING * rng.standard_normal((fam.n, 3))


def family_magnitude(offsets, terms) -> np.ndarray:
    """(n_points,) per-point sum of the magnitudes of per-bond ``terms`` (n_bonds,)."""
    return family_sum(offsets, np.abs(terms))


def assert_close(got, ref, tol, scale):
    """|got - ref| <= tol * scale elementwise (``scale`` broadcast over the trailing axes:
    e.g. one value per point for (n_points, 3) forces)."""
    got = np.asarray(got, dtype=np.float64)
    scale = np.asarray(scale, dtype=np.float64)
    bound = tol * np.broadcast_to(scale.reshape(scale.shape + (1,) * (got.ndim - scale.ndim)), got.shape)
    error = np.abs(got - ref)
    worst = np.unravel_index(np.argmax(error - bound), error.shape)
    assert np.all(error <= bound), (
        f"error {error[worst]:.3e} > bound {bound[worst]:.3e} at {worst} "
        f"(got {got[worst]!r}, reference {ref[worst]!r})"
    )
