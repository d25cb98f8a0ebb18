"""Points, bonds and peak memory of a job estimated from its case alone, before anything is
allocated; ``check_memory`` refuses, with the numbers and a spacing that fits, a job that
would not fit in memory.

Points come from the grid the geometry builder would make (``geometry.cell_counts``), less
the removals (their share measured on a coarse copy of the body). Directed bonds are counted
exactly on the lattice: each offset ``o`` (in cells) within the horizon joins
``prod_a (n_a - |o_a|)`` ordered pairs of a grid of ``n_a`` points per axis, which gives
the surface loss of thin plates, 2D bodies and small boxes without building anything.

Peak bytes are ``BASE_BYTES + points * per_point + bonds * per_bond`` with per-job
coefficients (``COSTS``) counted from the arrays each solver holds at its peak (see their
comments), plus the sparse factor of a shift-invert modal run
(``linalg.ordering.estimated_factor_entries``, as ``jobs.modal`` chooses it).
benchmarks/RESULTS.md ("Memory per bond and the estimate") compares them with measured peaks.
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass, field

import numpy as np

from peridyn.discretization import geometry
from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import Case
from peridyn.setup.storage import lattice_refusals

#: Resident bytes of the interpreter with numpy, scipy, numba (and its loaded kernels), h5py
#: and peridyn imported, before the first array: measured with ``/usr/bin/time -v`` on a
#: 2 500-point case (bar_pulse at 2 mm: 310 MB; benchmarks/HISTORY.md, "Memory estimate against
#: measured peaks").
BASE_BYTES = 300e6


@dataclass(frozen=True)
class Costs:
    """Bytes per point and per directed bond held at a job's peak (float64 kernels)."""

    per_point: float
    per_bond: float


#: Per-job costs. Per directed bond, every job holds the Bonds arrays (neighbour 4, length 8,
#: influence 8, volume factor 8, intact 1 = 29 B) and, while they are built, the pairs of the
#: search (8 B) and the reverse-bond permutation with its sort temporaries (24 B).
#: ``explicit``: + the model's per-bond arrays (PMB: 1/length, stiffness, surface factor: 24 B;
#: LPS: weight, deviatoric coefficient, shear factor: 24 B, and in float32 the length), the reference bond
#: vectors that the float64 force kernels read (24 B; a PMB half list holds its per-pair copies
#: instead, 26 B a directed bond, ``discretization.pairs``) and the kernels' temporaries: about
#: 116 B; per point the body (points, volumes, cells, sets: 64 B) and the state (x, u, v, a, f,
#: forces, damping: 8 x 24 B).
#: ``static``, ``newton``, ``newmark``: + a bond-stiffness assembly (9 entries of 8 B values + 2 x 4 B
#: indices per bond, COO then CSR) and the bond vectors of the force: about 424 B.
#: ``fatigue``: statics by AMG-preconditioned CG (or a factor) and modal analyses before and after:
#: 2 400 B per bond, fitted to one measured run (dog-bone at 0.33 mm, 795 k directed bonds,
#: 2.05 GiB peak) and 7-11 % high on the SEN strip at 132 k-1.24 M bonds (benchmarks/HISTORY.md,
#: "Memory estimate against measured peaks").
#: ``modal``: + the stiffness parts P and G (LPS) in COO and CSR and the augmented matrix:
#: about 500 B; per point the mode shapes are small (n_modes x 24 B) next to the bonds.
COSTS = {
    "explicit": Costs(per_point=350.0, per_bond=116.0),
    "newmark": Costs(per_point=600.0, per_bond=424.0),
    "static": Costs(per_point=600.0, per_bond=424.0),
    "newton": Costs(per_point=600.0, per_bond=424.0),
    "fatigue": Costs(per_point=600.0, per_bond=2400.0),
    "modal": Costs(per_point=600.0, per_bond=500.0),
}
#: The bytes per directed bond of the model's own arrays that ``COSTS`` count (PMB, LPS); the
#: material's ``Model.bond_bytes`` takes their place.
COSTS_MODEL_BYTES = 24.0

#: An explicit run on lattice storage (``discretization.storage``, docs/user-guide.md) holds no
#: per-bond array. Bytes a body point holds at such a run's peak (its end), by part (float64,
#: counted from the arrays of ``physics.materials.lattice``, ``solvers.explicit`` and the build):
#: ``body``: positions 24, volume 8, the ``all`` set 8, grid index 8, the domain's point ids 8 and
#: a plate's layer 1 (one cell size is seen by every point); ``state``: u, v, a (the lattice
#: force is written into a); ``grid``: the grid's displacement 24, volume 8, each grid point's
#: body row 4 and the force kernels' sum of each grid point's pair forces 24; ``loads``: the
#: constrained-DOF mask; ``end``: the last snapshot's float32 displacement (12) and the sums of
#: the final energy or damage (16). The material and damage
#: add ``LATTICE_LPS_BYTES``, ``LATTICE_SHEAR_FACTOR_BYTES``, ``LATTICE_DAMAGE_BYTES``, float32
#: kernels ``LATTICE_FLOAT32_BYTES``; per point and stencil offset, one broken bit
#: (``LATTICE_BIT_BYTES``, in 64-bit words). Measured: 249 B a point on the Lamb plate (LPS with
#: the shear factor, 240 k-480 k points; this model then: 236 B) before the pair forces' sum,
#: benchmarks/RESULTS.md "Lattice storage".
LATTICE_POINT_BYTES = {"body": 57.0, "state": 72.0, "grid": 60.0, "loads": 3.0, "end": 28.0}
#: LPS: alpha, the dilatation and pressure coefficients (float64) and the dilatation itself.
LATTICE_LPS_BYTES = 32.0
#: LPS with ``surface_correction: shear-factor``: the factor of each point.
LATTICE_SHEAR_FACTOR_BYTES = 8.0
#: Bond breaking: the displacement of the last bond test (24) and which points may break (1).
LATTICE_DAMAGE_BYTES = 25.0
#: float32 kernels: the solver's own force (12), the float32 grid displacement beside the float64
#: one of the energy and bond tests (12) and LPS's float32 coefficients (12), less the half of the
#: pair forces' sum that float32 saves (12).
LATTICE_FLOAT32_BYTES = 24.0
LATTICE_BIT_BYTES = 1.0 / 8.0

#: Bytes per directed bond an explicit run saves with float32 kernels: half of the model's 32 B,
#: and the 24 B of bond vectors that only the float64 kernels read.
FLOAT32_SAVING = 40.0

#: ``modal``: bytes per point and mode asked for (``solver.modes``): the mode shapes (3 float64)
#: and LOBPCG's blocks of as many vectors (X, AX, R, AR, P, AP and the Rayleigh-Ritz basis), ten
#: of them; a request of many modes is refused with this part named.
MODE_BYTES = 240.0

#: Bytes per entry of a sparse factor (8-byte value, 4-byte index), as ``jobs.modal`` counts.
FACTOR_ENTRY_BYTES = 12.0

#: Points of the coarse copy on which the removals' share is measured.
REMOVAL_SAMPLE_POINTS = 50_000

#: Offsets (lattice points of the horizon ball's bounding box) counted exactly; beyond, the
#: ball's volume over the cell's gives the bonds per point (an over-estimate near surfaces).
MAX_OFFSETS = 2_000_000


@dataclass(frozen=True)
class Estimate:
    """What a job would hold: ``points``, directed ``bonds`` and ``peak_bytes`` (by ``parts``),
    on the ``storage`` of its bonds (``bonds`` or ``lattice``)."""

    job: str
    points: int
    bonds: int
    peak_bytes: float
    parts: dict = field(default_factory=dict)
    storage: str = "bonds"


def parse_bytes(text) -> int:
    """Bytes from ``"4e9"``, ``"4GB"`` (10^9), ``"4GiB"`` (2^30), ``"512 MB"``, ``"2T"``.

    >>> parse_bytes("4GB"), parse_bytes("1.5GiB"), parse_bytes("1000")
    (4000000000, 1610612736, 1000)
    """
    match = re.fullmatch(r"\s*([0-9.]+(?:[eE][+-]?[0-9]+)?)\s*([kKMGT]?)(i?)[bB]?\s*", str(text))
    if not match:
        raise InputError(f"memory size {text!r}: expected bytes, e.g. 4GB, 512MiB or 4e9")
    number, prefix, binary = match.groups()
    power = " kMGT".index(prefix.replace("K", "k")) if prefix else 0
    value = float(number) * (1024.0 if binary else 1000.0) ** power
    if not (math.isfinite(value) and value >= 1):
        raise InputError(f"memory size {text!r}: expected at least 1 byte")
    return int(value)


def lattice_offsets(counts, cell, reach: float) -> np.ndarray:
    """(k, 3) int offsets (in cells) of the grid neighbours within ``reach`` (m) of a point,
    the zero offset excluded; each axis is limited to ``counts - 1``."""
    cell = np.asarray(cell, dtype=float)
    half = [min(math.floor(reach / cell[a]), int(counts[a]) - 1) for a in range(3)]
    axes = [np.arange(-m, m + 1) for m in half]
    offsets = np.stack([o.ravel() for o in np.meshgrid(*axes, indexing="ij")], axis=1)
    r = np.linalg.norm(offsets * cell, axis=1)
    return offsets[(r > 0) & (r <= reach)]


def neighbour_offsets(counts, cell, horizon: float, partial_volumes: bool, dim: int):
    """Offsets (k, 3) of a grid point's neighbours as ``find_bonds`` keeps them, and each
    neighbour's volume factor (k,): the share of its cell inside the horizon, or 1.

    A neighbour is in when its centre lies within the horizon or, with partial volumes,
    when part of its cell does.
    """
    from peridyn.kernels.bond_search import box_fraction_in_ball

    radius = horizon * (1 + 1e-12)
    sides = np.asarray(cell, dtype=float).copy()
    if dim == 2:
        sides[2] = 0.0
    if not partial_volumes:
        offsets = lattice_offsets(counts, cell, radius)
        return offsets, np.ones(len(offsets))
    offsets = lattice_offsets(counts, cell, radius + 0.5 * float(np.linalg.norm(sides)))
    xi = offsets * np.asarray(cell, dtype=float)
    factor = np.array([box_fraction_in_ball(*x, *sides, radius, 8) for x in xi])
    return offsets[factor > 0], factor[factor > 0]


def lattice_bonds(counts, cell, horizon: float, partial_volumes: bool, dim: int) -> float:
    """Directed bonds of a grid of ``counts`` points per axis with ``cell`` sides (m): each
    neighbour offset ``o`` joins ``prod_a (n_a - |o_a|)`` ordered pairs."""
    counts = np.asarray(counts, dtype=float)
    cell = np.asarray(cell, dtype=float)
    reach = horizon + (0.5 * float(np.linalg.norm(cell[:dim])) if partial_volumes else 0.0)
    if math.prod(2 * min(math.floor(reach / cell[a]), counts[a] - 1) + 1 for a in range(3)) > MAX_OFFSETS:
        # the ball of radius reach, thinned along each axis shorter than it (a thin plate's
        # family is a disc: (4/3) pi r^3 x 0.75 L / r = pi r^2 L)
        extent = counts * cell
        ball = 4.0 / 3.0 * math.pi * reach**3 if dim == 3 else math.pi * reach**2 * cell[2]
        ball *= math.prod(min(1.0, 0.75 * extent[a] / reach) for a in range(dim))
        return float(np.prod(counts)) * min(ball / float(np.prod(cell)), float(np.prod(counts)) - 1)
    offsets, _ = neighbour_offsets(counts, cell, horizon, partial_volumes, dim)
    return float(np.prod(counts - np.abs(offsets), axis=1).sum())


def grid_shape(case: Case, base_dir=".") -> tuple[np.ndarray, np.ndarray, int]:
    """Points per axis (3,), cell sides (3,) m and dimension of the case's body, unbuilt.

    A text or Exodus mesh has no grid: its points are read and taken as one row (its bonds are then
    counted as if every point had a full family).
    """
    g, d = case.geometry, case.discretization
    if not g.is_mesh and d.spacing is None:
        raise CaseFileError(case.name, "discretization.spacing", None, "a positive spacing (m)")
    spacing = np.broadcast_to(np.asarray(d.spacing, dtype=float), (3,)) if g.type == "box" else None
    try:
        if g.type == "box":
            return geometry.cell_counts(np.asarray(g.size, float), spacing, warn=False), spacing, 3
        if g.type in ("plate", "rectangle"):
            h = float(d.spacing if np.isscalar(d.spacing) else d.spacing[0])
            xy = geometry.cell_counts(np.asarray(g.size[:2], float), np.array([h, h]), warn=False)
            if g.type == "rectangle":
                return np.array([*xy, 1]), np.array([h, h, g.thickness]), 2
            dz = g.size[2] / (g.layers - 1 if g.layer_placement == "surface" and g.layers > 1 else g.layers)
            return np.array([*xy, g.layers]), np.array([h, h, dz]), 3
    except InputError as exc:
        raise CaseFileError(case.name, "discretization.spacing", d.spacing, str(exc)) from None
    from peridyn.setup.build import mesh_body

    body = mesh_body(g, base_dir)
    return np.array([body.n_points, 1, 1]), np.array([body.spacing] * 3), g.dimension


def kept_share(case: Case, counts: np.ndarray, base_dir=".") -> float:
    """Share of the grid's points left after the case's removals (1 without removals),
    measured on a copy of the body at a spacing giving about ``REMOVAL_SAMPLE_POINTS``."""
    if not case.removals or case.geometry.is_mesh:
        return 1.0
    from peridyn.setup.build import build_points

    coarsen = max(1.0, (float(np.prod(counts)) / REMOVAL_SAMPLE_POINTS) ** (1 / 3))
    d = case.discretization
    spacing = (np.asarray(d.spacing, dtype=float) * coarsen).tolist()
    coarse = case.model_copy(update={"discretization": d.model_copy(update={"spacing": spacing})})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        full = build_points(coarse, base_dir, removals=False).n_points
        return build_points(coarse, base_dir).n_points / full


def estimate_case(case: Case, base_dir=".", job: str | None = None) -> Estimate:
    """Points, directed bonds and peak bytes of ``case`` run as ``job`` (default: its solver
    type; ``"fatigue"`` for a fatigue run), allocating nothing of its size."""
    job = job or case.solver.type
    counts, cell, dim = grid_shape(case, base_dir)
    d = case.discretization
    spacing = float(np.max(cell[:dim])) if case.geometry.type != "plate" else float(cell[0])
    horizon = d.horizon_metres(spacing)
    share = kept_share(case, counts, base_dir)
    points = float(np.prod(counts.astype(float))) * share
    bonds = lattice_bonds(counts, cell, horizon, d.partial_volumes, dim) * share
    costs = COSTS[job]
    per_bond = costs.per_bond - COSTS_MODEL_BYTES + case.material_class().bond_bytes
    per_bond -= FLOAT32_SAVING if job == "explicit" and case.solver.dtype == "float32" else 0
    parts = {"base": BASE_BYTES, "points": points * costs.per_point, "bonds": bonds * per_bond}
    storage = "lattice" if job == "explicit" and runs_on_lattice(case) else "bonds"
    if storage == "lattice":
        offsets = len(neighbour_offsets(counts, cell, horizon, d.partial_volumes, dim)[0])
        words = 8.0 * math.ceil(offsets / 64)  # the broken bits, in 64-bit words per grid point
        grid = float(np.prod(counts.astype(float)))  # removed points keep their grid place
        parts.update(
            points=points * lattice_point_bytes(case), bonds=grid * max(words, offsets * LATTICE_BIT_BYTES)
        )
    if job == "modal":
        parts["factor"] = modal_factor_bytes(case, base_dir, points, horizon)
        parts["modes"] = MODE_BYTES * points * case.solver.modes
    return Estimate(job, int(round(points)), int(round(bonds)), float(sum(parts.values())), parts, storage)


def lattice_point_bytes(case: Case) -> float:
    """Bytes a body point of ``case`` holds in an explicit run on lattice storage
    (``LATTICE_POINT_BYTES`` and what its material, damage and kernel dtype add)."""
    total = sum(LATTICE_POINT_BYTES.values())
    material = case.material
    if material is not None and case.material_class().state_based:  # LPS: dilatation, alpha ...
        total += LATTICE_LPS_BYTES
        total += LATTICE_SHEAR_FACTOR_BYTES if material.surface_correction == "shear-factor" else 0.0
    if material is not None and material.damage is not None:
        total += LATTICE_DAMAGE_BYTES
    return total + (LATTICE_FLOAT32_BYTES if case.solver.dtype == "float32" else 0.0)


def runs_on_lattice(case: Case) -> bool:
    """Whether ``discretization.storage`` puts the case on lattice storage (``setup.storage``):
    ``lattice``, or ``auto`` where nothing needs bond lists (a box, plate or rectangle is a grid)."""
    return case.discretization.storage != "bonds" and not lattice_refusals(case)


def modal_factor_bytes(case: Case, base_dir, points: float, horizon: float) -> float:
    """Bytes of the shift-invert factor when ``setup.eigensolver.choose_eigensolver`` would pick it
    (0 for LOBPCG, which factorises nothing)."""
    from peridyn.linalg.ordering import estimated_factor_entries
    from peridyn.setup.build import build_points
    from peridyn.setup.eigensolver import FACTOR_BUDGET, MEMORY_SHARE

    method = case.solver.eigensolver
    if method == "lobpcg" or (method == "auto" and points * 24 > FACTOR_BUDGET):
        return 0.0  # the factor of so many points would exceed the budget anyway
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        body = build_points(case, base_dir)
    unknowns = 4 if case.material_class().state_based else 3  # state-based: theta too
    needed = FACTOR_ENTRY_BYTES * estimated_factor_entries(body.points, horizon, unknowns)
    if method == "auto" and needed > min(FACTOR_BUDGET, MEMORY_SHARE * geometry.memory_limit()):
        return 0.0
    return needed


def check_memory(case: Case, max_memory: float | None = None, base_dir=".", job: str | None = None):
    """The job's ``Estimate``; raises ``InputError`` with the numbers and a spacing that fits
    when its peak exceeds ``max_memory`` bytes (default: ``geometry.memory_limit()``)."""
    limit = geometry.memory_limit() if max_memory is None else float(max_memory)
    est = estimate_case(case, base_dir, job)
    if est.peak_bytes <= limit:
        return est
    raise InputError(
        f"{case.name}: this {est.job} job would hold about {est.points:.3g} points and "
        f"{est.bonds:.3g} bonds and need ~{est.peak_bytes / 1e9:.3g} GB, more than the "
        f"{limit / 1e9:.3g} GB available{_suggestion(case, est, limit)}"
    )


def _suggestion(case: Case, est: Estimate, limit: float) -> str:
    """``"; a spacing of about X m fits"`` from the points' and bonds' scaling with spacing
    (``"; ask for fewer modes"`` where the modes asked for take most of it)."""
    modes = est.parts.get("modes", 0.0)
    if modes > 0.5 * est.peak_bytes:
        asked = case.solver.modes
        return f"; the {asked} modes asked for take ~{modes / 1e9:.3g} GB: ask for fewer (--modes)"
    budget = limit - est.parts["base"]
    varying = est.peak_bytes - est.parts["base"]
    if budget <= 0:
        return f"; the interpreter and libraries alone take ~{est.parts['base'] / 1e9:.2g} GB"
    if varying <= 0 or case.discretization.spacing is None:
        return ""
    power = 2 if case.geometry.type in ("plate", "rectangle") else 3
    if case.discretization.horizon_m is not None:
        power += 3 if case.geometry.type == "box" else 2  # more bonds per point as well
    factor = 1.05 * (varying / budget) ** (1 / power)
    spacing = np.asarray(case.discretization.spacing, dtype=float) * factor
    return f"; a spacing of about {float(np.max(spacing)):.3g} m would fit"


def largest_study_run(case: Case, spacings, horizon_factors) -> Case:
    """The modal run of a spacing x horizon study that holds the most: the finest spacing (m)
    with the widest horizon (a multiple of the spacing)."""
    d = case.discretization.model_copy(
        update={"spacing": min(spacings), "horizon": max(horizon_factors), "horizon_m": None}
    )
    solver = case.solver.model_copy(update={"type": "modal"})
    return case.model_copy(update={"discretization": d, "solver": solver})
