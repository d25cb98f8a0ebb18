"""A rank's part of a grid body on lattice storage (``peridyn.discretization.lattice``): a slab
of whole grid planes across x, with the planes of its ghosts either side.

Partition: the grid's ``nx`` planes across x are split into one slab of consecutive planes per
rank (``slab_bounds``, equal numbers of planes to one). x is the slowest axis of the point
generators' order (``discretization.geometry``), so a slab's points are one contiguous range of
the whole body's point numbers, owned in global order, and its ghosts, the points of the
neighbouring planes, come in the order of their owners' ranks, as ``peridyn.parallel.halo``
needs them.

Ghosts: ``2 r`` planes each side, r the stencil's largest offset across x (``ghost_planes``):
the two layers of bond reach of the bond-list path (``peridyn.parallel.halo``). Every point of
the first ``r`` ghost planes then has its whole family on the rank, so its per-point values
(the LPS weighted volume, dilatation and shear factor) come out as in a serial run from the
exchanged displacement, and every owned force is the serial one: the lattice kernels add each
point's pairs in an order set by the grid's y and z planes and the stencil alone, whatever the
grid's extent across x (``peridyn.kernels.lattice``). A bond whose ends lie on two
ranks is tested for breaking on both, from the same exchanged displacements, so its two bits
are set in the same step.

The local lattice is the whole grid's planes ``first .. stop - 1`` (owned and ghost), the
stencil that of the whole grid. ``LatticeDomain`` is a ``Domain`` whose per-bond gathers
(checkpoints) carry the broken words in the whole grid's layout.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from peridyn.errors import InputError
from peridyn.parallel.domain import Domain
from peridyn.parallel.halo import Halo

#: How the points were split, for the provenance.
PARTITION = "grid slabs across x"


def slab_bounds(n_planes: int, n_ranks: int) -> np.ndarray:
    """(n_ranks + 1,) int64: rank r owns the planes ``bounds[r] .. bounds[r + 1] - 1`` of the
    ``n_planes`` across x (equal numbers to one).

    Raises
    ------
    InputError
        When there are fewer planes than ranks.
    """
    if n_planes < n_ranks:
        raise InputError(
            f"lattice storage splits the grid's {n_planes} planes across x over the ranks: "
            f"use at most {n_planes} ranks, or discretization.storage: bonds"
        )
    return (np.arange(n_ranks + 1, dtype=np.int64) * n_planes) // n_ranks


def ghost_planes(offsets: np.ndarray) -> int:
    """Ghost planes each side of a slab for a stencil of integer ``offsets`` (n_off, 3): two
    layers of the largest reach across x."""
    return 2 * int(np.abs(offsets[:, 0]).max())


@dataclass(frozen=True)
class Slab:
    """A rank's planes across x of a grid of ``shape`` (nx, ny, nz).

    Attributes
    ----------
    shape : (3,) int64
        The whole grid's.
    lo, hi : int
        Owned planes ``lo .. hi - 1``.
    first, stop : int
        Local planes (ghosts included) ``first .. stop - 1``.
    """

    shape: np.ndarray
    lo: int
    hi: int
    first: int
    stop: int

    @classmethod
    def of_rank(cls, shape, bounds: np.ndarray, rank: int, ghosts: int) -> Slab:
        """The slab of ``rank`` for the ``slab_bounds`` ``bounds`` and ``ghosts`` planes each side."""
        lo, hi = int(bounds[rank]), int(bounds[rank + 1])
        nx = int(shape[0])
        return cls(np.asarray(shape, dtype=np.int64), lo, hi, max(0, lo - ghosts), min(nx, hi + ghosts))

    @property
    def local_shape(self) -> np.ndarray:
        """(3,) int64: the local grid's shape."""
        return np.array([self.stop - self.first, self.shape[1], self.shape[2]], dtype=np.int64)

    def points(self, grid_index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(owned, ghosts): the indices (int64, ascending) of the body points on whole-grid points
        ``grid_index`` ((n_points,) int64) in the owned planes and in the ghost planes."""
        plane = grid_index % int(self.shape[0])
        local = (plane >= self.first) & (plane < self.stop)
        mine = (plane >= self.lo) & (plane < self.hi)
        return np.flatnonzero(mine), np.flatnonzero(local & ~mine)

    def owners(self, bounds: np.ndarray, grid_index: np.ndarray) -> np.ndarray:
        """(k,) int64: the rank that owns each whole-grid point ``grid_index`` (``slab_bounds``)."""
        return np.searchsorted(bounds, grid_index % int(self.shape[0]), side="right") - 1

    def layout(self, spacing: np.ndarray, origin: np.ndarray, grid_index: np.ndarray) -> tuple:
        """(shape, spacing, origin, grid_index) of the local grid (``discretization.lattice``),
        for points on whole-grid points ``grid_index`` ((k,) int64, in the local planes)."""
        nx = int(self.shape[0])
        rows, ix = np.divmod(grid_index, nx)
        local = rows * (self.stop - self.first) + (ix - self.first)
        return self.local_shape, spacing, origin + np.array([self.first * spacing[0], 0.0, 0.0]), local


class LatticeDomain(Domain):
    """The ``Domain`` of a rank's slab (module docstring), whose per-bond collectives move the
    lattice's broken words ((n_words, n_grid) uint64, flat) in the whole grid's layout.

    Parameters as ``Domain``'s, with the rank's ``slab`` and the lattice's ``n_words``.
    """

    def __init__(self, comm, global_ids, n_owned: int, n_global: int, halo: Halo, slab: Slab, n_words: int):
        super().__init__(comm, global_ids, n_owned, n_global, halo, PARTITION)
        self.slab = slab
        self.n_words = int(n_words)

    def _whole_words(self, values: np.ndarray) -> np.ndarray:
        nx, ny, nz = (int(n) for n in self.slab.shape)
        return values.reshape(self.n_words, nz, ny, nx)

    def _local_words(self, values: np.ndarray) -> np.ndarray:
        _, ny, nz = (int(n) for n in self.slab.shape)
        return values.reshape(self.n_words, nz, ny, self.slab.stop - self.slab.first)

    def bond_offsets(self, offsets: np.ndarray) -> np.ndarray:
        """[0, words of the whole grid]: the broken words as one block (``offsets`` unused)."""
        return np.array([0, self.n_words * int(np.prod(self.slab.shape))], dtype=np.int64)

    def gather_bonds(self, values: np.ndarray, offsets: np.ndarray, whole: np.ndarray):
        """The whole grid's broken words (flat, serial layout) on rank 0 from each rank's owned
        planes of its local words ``values`` (None elsewhere)."""
        s = self.slab
        mine = np.ascontiguousarray(self._local_words(values)[..., s.lo - s.first : s.hi - s.first])
        parts = self.comm.gather((s.lo, s.hi, mine))
        if not self.is_root:
            return None
        out = np.empty(int(whole[-1]), dtype=values.dtype)
        grid = self._whole_words(out)
        for lo, hi, part in parts:
            grid[..., lo:hi] = part
        return out

    def scatter_bonds(self, values: np.ndarray, bonds, whole: np.ndarray) -> np.ndarray:
        """The local words (flat) of the whole grid's broken words ``values`` (flat, serial layout):
        the local planes, ghosts included, take the serial bits."""
        s = self.slab
        return np.ascontiguousarray(self._whole_words(values)[..., s.first : s.stop]).reshape(-1)
