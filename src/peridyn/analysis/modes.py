"""Mode identification for plate-like bodies, and the modal assurance criterion.

A plate lies in the x-y plane (length along x, width along y, thickness along z).
A mode is classified from its shape by where its kinetic energy goes and by
its nodal lines (sign changes of the mid-surface displacement):

- out-of-plane modes (most of the energy in u_z), split by the symmetry of
  u_z about the plate's long axis (y = centre):
  - antisymmetric: ``torsional``, order = sign changes along x of the twist
    u_z(x, +y) - u_z(x, -y);
  - symmetric, varying along x: ``bending``, order = nodal lines across the
    length minus 1 (the first free-free bending mode has two);
  - symmetric, varying along y: ``transverse bending``, order = nodal lines
    along the length minus 1;
- in-plane modes: ``in-plane bending`` when u_y dominates (order = nodal lines
  of u_y along x minus 1), ``other`` (e.g. extensional) otherwise;
- ``rigid`` for rigid-body modes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Samples below this fraction of a profile's peak do not count as sign changes.
NOISE_FRACTION = 0.05


@dataclass(frozen=True)
class ModeType:
    """Type and order of a mode (order 0 for rigid and other)."""

    type: str
    order: int

    def __str__(self) -> str:
        return self.type if self.order == 0 else f"{_ordinal(self.order)} {self.type}"


def classify_mode(points: np.ndarray, shape: np.ndarray, masses: np.ndarray, rigid: bool = False) -> ModeType:
    """Type of one plate mode.

    Parameters
    ----------
    points : (n_points, 3) float64, m
    shape : (n_points, 3) float64
        Mode shape.
    masses : (n_points,) float64, kg
    rigid : bool
        Known rigid-body mode.
    """
    if rigid:
        return ModeType("rigid", 0)
    energy = masses[:, None] * shape**2
    share = energy.sum(axis=0) / energy.sum()
    grid = _Grid(points)
    if share[2] >= 0.5:
        uz = grid.mid_surface(shape[:, 2])
        sym = 0.5 * (uz + uz[:, ::-1])
        anti = 0.5 * (uz - uz[:, ::-1])
        if np.sum(anti**2) > np.sum(sym**2):
            twist = anti[:, -1] - anti[:, 0]
            return ModeType("torsional", _sign_changes(twist))
        along_x = _sign_changes(sym.mean(axis=1))
        along_y = _sign_changes(sym[np.argmax(np.abs(sym).max(axis=1))])
        variation_x = grid.variation(sym, axis=0)
        variation_y = grid.variation(sym, axis=1)
        if variation_x >= variation_y and along_x >= 2:
            return ModeType("bending", along_x - 1)
        if along_y >= 2:
            return ModeType("transverse bending", along_y - 1)
        return ModeType("other", 0)
    if share[1] >= share[0]:
        uy = grid.mid_surface(shape[:, 1]).mean(axis=1)
        nodes = _sign_changes(uy)
        if nodes >= 2:
            return ModeType("in-plane bending", nodes - 1)
    return ModeType("other", 0)


def classify_modes(points, shapes, masses, rigid) -> list[ModeType]:
    """Types of every mode of a ``ModalResult`` (shapes (n_modes, n_points, 3))."""
    return [classify_mode(points, s, masses, bool(r)) for s, r in zip(shapes, rigid, strict=True)]


def mac_matrix(shapes_a: np.ndarray, shapes_b: np.ndarray, masses: np.ndarray) -> np.ndarray:
    """Modal assurance criterion (n_a, n_b): (a^T M b)^2 / ((a^T M a)(b^T M b)), in [0, 1]."""
    m = np.repeat(masses, 3)
    a = shapes_a.reshape(len(shapes_a), -1)
    b = shapes_b.reshape(len(shapes_b), -1)
    cross = (a * m) @ b.T
    return cross**2 / np.outer(np.einsum("ij,ij->i", a * m, a), np.einsum("ij,ij->i", b * m, b))


class _Grid:
    """Mid-surface sampling of a plate's points on the x-y grid of its columns."""

    def __init__(self, points: np.ndarray):
        self.ix, xs = _bin(points[:, 0])
        self.iy, ys = _bin(points[:, 1])
        self.shape = (len(xs), len(ys))
        self.dx = float(np.median(np.diff(xs))) if len(xs) > 1 else 1.0
        self.dy = float(np.median(np.diff(ys))) if len(ys) > 1 else 1.0
        self.occupied = np.zeros(self.shape, dtype=bool)
        self.occupied[self.ix, self.iy] = True

    def variation(self, field: np.ndarray, axis: int) -> float:
        """Sum of squared differences of a mid-surface field along ``axis`` over pairs of occupied
        columns (empty columns of non-rectangular bodies do not count), divided by the spacing^2."""
        pairs = np.diff(self.occupied.astype(np.int8), axis=axis) == 0
        pairs &= np.take(self.occupied, range(self.shape[axis] - 1), axis=axis)
        step = self.dx if axis == 0 else self.dy
        return float(np.sum(np.where(pairs, np.diff(field, axis=axis), 0.0) ** 2) / step**2)

    def mid_surface(self, values: np.ndarray) -> np.ndarray:
        """(n_x, n_y) through-thickness mean of ``values`` on each column (0 where empty)."""
        total = np.zeros(self.shape)
        count = np.zeros(self.shape)
        np.add.at(total, (self.ix, self.iy), values)
        np.add.at(count, (self.ix, self.iy), 1.0)
        return np.divide(total, count, out=np.zeros(self.shape), where=count > 0)


def _bin(coord: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    levels, index = np.unique(np.round(coord, 12), return_inverse=True)
    return index.ravel(), levels


def _sign_changes(profile: np.ndarray) -> int:
    """Sign changes of a 1D profile, ignoring samples below NOISE_FRACTION of its peak."""
    peak = np.max(np.abs(profile))
    if peak == 0:
        return 0
    signs = np.sign(profile[np.abs(profile) > NOISE_FRACTION * peak])
    return int(np.count_nonzero(np.diff(signs)))


def _ordinal(n: int) -> str:
    suffix = "th" if 10 <= n % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"
