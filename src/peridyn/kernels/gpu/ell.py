"""The ELL layout of bond families (host side, NumPy): bond ``k`` of point ``i`` at ``[k, i]``.

Built once from the CSR families (``offsets`` (n_points + 1,), per-bond arrays (n_bonds,)) that
the rest of the package uses; ``to_ell`` lays out any per-bond array, ``from_ell`` takes one back.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class EllSlots:
    """Where each CSR bond sits in the ELL arrays.

    Attributes
    ----------
    count : (n_points,) int32
        Bonds of each point.
    k_max : int
        The longest family: the ELL arrays are (k_max, n_points).
    row, col : (n_bonds,) int64
        Bond ``b`` of the CSR list is at ``[row[b], col[b]]`` (``col`` its owner).
    """

    count: np.ndarray
    k_max: int
    row: np.ndarray
    col: np.ndarray

    @classmethod
    def of(cls, offsets: np.ndarray) -> EllSlots:
        """The slots of the CSR families ``offsets`` (n_points + 1,)."""
        offsets = np.asarray(offsets, dtype=np.int64)
        count = np.diff(offsets)
        col = np.repeat(np.arange(len(count), dtype=np.int64), count)
        row = np.arange(offsets[-1], dtype=np.int64) - offsets[col]
        return cls(count.astype(np.int32), int(count.max(initial=0)), row, col)

    @property
    def shape(self) -> tuple[int, int]:
        """(k_max, n_points)."""
        return (self.k_max, len(self.count))

    def to_ell(self, values: np.ndarray, dtype, fill=0) -> np.ndarray:
        """(k_max, n_points) array of ``dtype`` holding the per-bond ``values`` (n_bonds,), ``fill``
        in the padding."""
        out = np.full(self.shape, fill, dtype=dtype)
        out[self.row, self.col] = values
        return out

    def from_ell(self, values: np.ndarray) -> np.ndarray:
        """(n_bonds,): the per-bond values of a (k_max, n_points) array in CSR order."""
        return values[self.row, self.col]
