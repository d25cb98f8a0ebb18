"""Lattice storage: a grid body's bonds as one stencil of offsets and a broken bit per bond.

On a regular grid (boxes, plates, rectangles, with holes and pre-cracks) every point's
family is the same set of integer offsets: a bond's reference vector xi, its length, its
influence weight and its partial-volume factor depend on the offset only. A
:class:`Lattice` keeps those per-offset tables (:class:`Stencil`), a volume per grid point
(0 where there is no material: removed points, holes) and one broken bit per (grid point,
offset), instead of the CSR bond arrays of ``peridyn.discretization.bonds`` (about 45 bytes
a directed bond); the kernels of ``peridyn.kernels.lattice`` run over it.

Grid order: grid point (ix, iy, iz) has flat index ``(iz ny + iy) nx + ix`` (rows along x,
contiguous). A body's own point order differs (``geometry`` puts the last axis fastest);
``grid_index`` maps each body point to its grid point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from peridyn.discretization.body import Body
from peridyn.discretization.bonds import HORIZON_RTOL, influence_function, search_cells
from peridyn.errors import InputError
from peridyn.kernels.bond_search import box_fraction_in_ball
from peridyn.kernels.lattice import lattice_bond_sum, lattice_owned_bonds

#: Largest distance of a point from its grid position, as a share of the spacing, for a body
#: to count as a grid.
GRID_RTOL = 1e-6
#: Bits per word of ``Lattice.broken``.
WORD_BITS = 64


@dataclass(frozen=True, eq=False)
class Stencil:
    """The bonds every grid point has, one row per integer offset (lexicographic in (ox, oy, oz)).

    Attributes
    ----------
    offsets : (n_off, 3) int64
        Integer offsets (ox, oy, oz) of the neighbour.
    xi : (n_off, 3) float64, m
        Reference bond vector, offsets times the grid spacings.
    length : (n_off,) float64, m
    influence : (n_off,) float64
        omega(|xi|) of the lattice's influence function.
    volume_factor : (n_off,) float64
        Fraction of the neighbour's cell inside the horizon (1 without partial volumes).
    reverse : (n_off,) int64
        Row of the opposite offset.
    """

    offsets: np.ndarray
    xi: np.ndarray
    length: np.ndarray
    influence: np.ndarray
    volume_factor: np.ndarray
    reverse: np.ndarray

    @property
    def size(self) -> int:
        """Number of offsets."""
        return len(self.offsets)


@dataclass(frozen=True, eq=False)
class Lattice:
    """A grid body's bonds in lattice storage.

    Attributes
    ----------
    shape : (3,) int64
        Grid points (nx, ny, nz) (nz = 1 for a 2D body).
    spacing : (3,) float64, m
        Grid spacings (dx, dy, dz); a 2D body's dz is its thickness (no offset uses it).
    origin : (3,) float64, m
        Position of grid point (0, 0, 0).
    volume : (n_grid,) float64, m^3
        Volume of each grid point, 0 where there is no material.
    grid_index : (n_points,) int64
        The grid point of each body point.
    stencil : Stencil
    broken : (n_words, n_grid) uint64
        Bit ``k % 64`` of word ``k // 64`` of grid point g: the bond along offset k is broken.
        Written in place (pre-cracks, damage).
    horizon : float, m
    influence_name : str
    dim : {2, 3}
    """

    shape: np.ndarray
    spacing: np.ndarray
    origin: np.ndarray
    volume: np.ndarray
    grid_index: np.ndarray
    stencil: Stencil
    broken: np.ndarray
    horizon: float
    influence_name: str
    dim: int

    @property
    def n_grid(self) -> int:
        """Grid points, with and without material."""
        return int(np.prod(self.shape))

    @property
    def n_points(self) -> int:
        """Points with material (the body's points)."""
        return len(self.grid_index)

    def horizons(self) -> float:
        """The horizon (m), one for every point (as ``Bonds.horizons``)."""
        return self.horizon

    def bond_sum(self, coef, every: bool = False) -> np.ndarray:
        """(n_grid,) float64: sum_k coef_k V_j over each grid point's bonds to material, the
        intact ones only unless ``every`` (``kernels.lattice.lattice_bond_sum``)."""
        s = self.stencil
        coef = np.ascontiguousarray(np.broadcast_to(coef, (s.size,)), dtype=np.float64)
        out = np.empty(self.n_grid)
        return lattice_bond_sum(self.volume, self.broken, self.shape, s.offsets, coef, every, out)

    def family_sizes(self) -> np.ndarray:
        """(n_points,) int64: bonds of each body point (to points with material)."""
        occupied = (self.volume > 0).astype(np.float64)
        s = self.stencil
        counts = lattice_bond_sum(
            occupied, self.broken, self.shape, s.offsets, np.ones(s.size), True, np.empty(self.n_grid)
        )
        return np.rint(counts[self.grid_index]).astype(np.int64)

    @property
    def n_bonds(self) -> int:
        """Directed bonds between points with material (each bond counted from both ends)."""
        return self.owned_bond_counts(self.n_points)[0]

    def owned_bond_counts(self, n_owned: int) -> tuple[int, int]:
        """(directed bonds, broken ones) of the body points ``0 .. n_owned - 1`` (a rank's owned
        points come first; a broken bond has both bits set), counted without an array of the
        body's size."""
        s = self.stencil
        counts = lattice_owned_bonds(
            self.volume, self.broken, self.shape, s.offsets, self.grid_index, n_owned
        )
        return int(counts[0]), int(counts[1])

    def n_broken(self, points=None) -> int:
        """Directed bonds broken (pre-cracks and damage; a broken bond has both bits set), of
        the body points ``points`` (indices or a slice, default all)."""
        if points is None:
            return int(np.bitwise_count(self.broken).sum())
        return int(np.bitwise_count(self.broken[:, self.grid_index[points]]).sum())

    def __repr__(self) -> str:
        return (
            f"Lattice(shape={self.shape.tolist()}, n_points={self.n_points}, "
            f"offsets={self.stencil.size}, horizon={self.horizon:g} m, influence={self.influence_name!r})"
        )


def grid_layout(body: Body, whole=None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(shape, spacing, origin, grid_index) of a body whose points sit on a regular grid of its
    cells (every cell the same box, each point at a grid position); see :class:`Lattice`. With
    ``whole`` = (origin (3,) m, shape (3,)) of a whole grid's, of which ``body`` is a part (a
    rank's slab), those of that grid, and each point's index in it.

    Raises
    ------
    InputError
        Naming why the body is not a grid (cells of several sizes, a point off the grid).
    """
    cells = body.cells
    if not np.all(cells == cells[0]):
        raise InputError("the body is not a grid: its cells are not all the same size")
    spacing = cells[0].copy()
    origin = body.points.min(axis=0) if whole is None else np.asarray(whole[0], dtype=np.float64)
    if body.dim == 2:
        spacing[2] = body.thickness
    index = np.rint((body.points - origin) / spacing).astype(np.int64)
    off = np.abs(origin + index * spacing - body.points).max(axis=0) / spacing
    if np.any(off > GRID_RTOL):
        axis = "xyz"[int(np.argmax(off))]
        raise InputError(
            f"the body is not a grid: a point lies {off.max():.3g} spacings off the grid along {axis}"
        )
    shape = index.max(axis=0) + 1 if whole is None else np.asarray(whole[1], dtype=np.int64)
    grid_index = (index[:, 2] * shape[1] + index[:, 1]) * shape[0] + index[:, 0]
    if len(np.unique(grid_index)) != body.n_points:
        raise InputError("the body is not a grid: two points share a grid position")
    return shape, spacing, origin, grid_index


def make_stencil(
    spacing: np.ndarray,
    horizon: float,
    dim: int,
    influence: str = "constant",
    partial_volumes: bool = True,
    quadrature_points: int = 8,
    shape=None,
) -> Stencil:
    """The offsets of a grid of ``spacing`` (3,) m within the ``horizon`` (m), as ``find_bonds``
    keeps bonds: every neighbour whose cell reaches into the horizon sphere with partial volumes
    (its factor by the same quadrature), else those with ``|xi| <= horizon (1 + 1e-12)``;
    with the grid's ``shape`` (3,), only offsets that fit in it (``|o_a| < n_a``)."""
    omega = influence_function(influence)
    cell = spacing.copy()
    if dim == 2:
        cell[2] = 0.0  # the partial-volume test of a 2D body takes rectangles (``search_cells``)
    reach = horizon * (1 + HORIZON_RTOL)
    if partial_volumes:
        reach += 0.5 * float(np.linalg.norm(cell))
    bound = np.floor(reach / spacing).astype(np.int64)
    if dim == 2:
        bound[2] = 0
    if shape is not None:
        bound = np.minimum(bound, np.asarray(shape, dtype=np.int64) - 1)
    axes = [np.arange(-b, b + 1) for b in bound]
    offsets = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    offsets = offsets[np.any(offsets != 0, axis=1)]
    xi = offsets * spacing
    length = np.linalg.norm(xi, axis=1)
    radius = horizon * (1 + HORIZON_RTOL)
    if partial_volumes:
        factor = np.array([box_fraction_in_ball(*v, *cell, radius, quadrature_points) for v in xi])
    else:
        factor = (length <= radius).astype(np.float64)
    keep = factor > 0
    offsets, xi, length, factor = offsets[keep], xi[keep], length[keep], factor[keep]
    lookup = {tuple(o): k for k, o in enumerate(offsets.tolist())}
    reverse = np.array([lookup[(-a, -b, -c)] for a, b, c in offsets.tolist()], dtype=np.int64)
    return Stencil(offsets, xi, length, omega(length, horizon), factor, reverse)


def build_lattice(
    body: Body,
    horizon: float,
    influence: str = "constant",
    partial_volumes: bool = True,
    quadrature_points: int = 8,
) -> Lattice:
    """The :class:`Lattice` of a grid body (``grid_layout``) for ``horizon`` (m): the bonds that
    ``find_bonds`` would find with the same arguments, none broken.

    Raises
    ------
    InputError
        When the body is not a grid, or a point has no neighbour within the horizon.
    """
    layout = grid_layout(body)
    stencil = grid_stencil(body, layout[0], layout[1], horizon, influence, partial_volumes, quadrature_points)
    lattice = lattice_on_grid(body, layout, stencil, horizon, influence)
    check_families(lattice, body)
    return lattice


def grid_stencil(
    body: Body,
    shape: np.ndarray,
    spacing: np.ndarray,
    horizon: float,
    influence: str = "constant",
    partial_volumes: bool = True,
    quadrature_points: int = 8,
) -> Stencil:
    """The stencil (``make_stencil``) of a grid body of ``shape`` (3,) and ``spacing`` (3,) m
    (``grid_layout``: the whole body's, also for a part of it).

    Raises
    ------
    InputError
        When the horizon is smaller than half the spacing.
    """
    if horizon < 0.5 * float(np.min(search_cells(body)[0, : body.dim])):
        raise InputError(
            f"horizon {horizon:g} m is smaller than half the spacing: points would have no neighbours"
        )
    return make_stencil(spacing, horizon, body.dim, influence, partial_volumes, quadrature_points, shape)


def lattice_on_grid(body: Body, layout, stencil: Stencil, horizon: float, influence: str) -> Lattice:
    """The :class:`Lattice` of ``body`` on the grid ``layout`` = (shape, spacing, origin,
    grid_index) (``grid_layout``, or a rank's slab of it) with ``stencil``, none broken."""
    shape, spacing, origin, grid_index = layout
    volume = np.zeros(int(np.prod(shape)))
    volume[grid_index] = body.volumes
    n_words = -(-stencil.size // WORD_BITS)
    broken = np.zeros((n_words, len(volume)), dtype=np.uint64)
    shape = np.asarray(shape, dtype=np.int64)
    return Lattice(
        shape, spacing, origin, volume, grid_index, stencil, broken, float(horizon), influence, body.dim
    )


def check_families(lattice: Lattice, body: Body, points=None, names=None) -> None:
    """Refuse a lattice where one of ``points`` (indices of ``body``'s points, default all) has no
    neighbour within the horizon, naming it by ``names[i]`` (default its index ``i``).

    Raises
    ------
    InputError
    """
    sizes = lattice.family_sizes()
    rows = np.arange(body.n_points) if points is None else np.asarray(points, dtype=np.int64)
    lonely = rows[sizes[rows] == 0]
    if len(lonely):
        i = int(lonely[0])
        name = i if names is None else int(names[i])
        raise InputError(
            f"point {name} at {body.points[i].tolist()} has no neighbour within the horizon "
            f"{lattice.horizon:g} m (spacing {body.spacing:g} m): increase the horizon"
        )


#: Grid points tested at a time by :func:`cut_lattice` (bounds its (chunk, 3) temporaries).
CUT_CHUNK = 1_000_000


def cut_lattice(body: Body, lattice: Lattice, crossing) -> int:
    """Break (in place) every bond for which ``crossing(x_i, x_j)`` or ``crossing(x_j, x_i)`` is
    True, as ``bonds.cut_bonds`` with ``both_copies``: both bits of the bond; returns the
    number of directed bonds newly cut. ``body``: the lattice's body (its points' positions)."""
    nx, ny, nz = (int(s) for s in lattice.shape)
    point_of = np.full(lattice.n_grid, -1, dtype=np.int64)
    point_of[lattice.grid_index] = np.arange(lattice.n_points)
    s = lattice.stencil
    before = lattice.n_broken()
    for k, (ox, oy, oz) in enumerate(s.offsets.tolist()):
        if k > s.reverse[k]:
            continue  # each bond once, from the offset that comes first
        for start in range(0, lattice.n_grid, CUT_CHUNK):
            g = np.arange(start, min(start + CUT_CHUNK, lattice.n_grid))
            ix, iy, iz = g % nx + ox, (g // nx) % ny + oy, g // (nx * ny) + oz
            inside = (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny) & (iz >= 0) & (iz < nz)
            q = np.where(inside, (iz * ny + iy) * nx + ix, 0)
            pair = inside & (point_of[g] >= 0) & (point_of[q] >= 0)
            a, b = body.points[point_of[g[pair]]], body.points[point_of[q[pair]]]
            cut = crossing(a, b) | crossing(b, a)
            set_bits(lattice.broken, g[pair][cut], k)
            set_bits(lattice.broken, q[pair][cut], int(s.reverse[k]))
    return lattice.n_broken() - before


def set_bits(broken: np.ndarray, grid_points: np.ndarray, k: int) -> None:
    """Set the broken bit of offset ``k`` of ``grid_points`` (int) in ``broken`` (in place)."""
    broken[k // WORD_BITS, grid_points] |= np.uint64(1) << np.uint64(k % WORD_BITS)
