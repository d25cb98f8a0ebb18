"""From a validated case to the objects of a run: body, bonds, material model, loads, damage
and contact (``build``); the ``build_*`` steps are there for Python users who want to stop
half-way (e.g. to inspect the bonds)."""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from peridyn import interrupts
from peridyn.discretization.body import Body, BodySize
from peridyn.discretization.bonds import (
    HORIZON_RTOL,
    Bonds,
    crossing_finite_plane,
    crossing_mask,
    crossing_rectangle,
    crossing_segment,
    crossing_triangles,
    cut_bonds,
    find_bonds,
    listed_pairs,
    reorder_bonds,
    search_reach,
    without_bonds,
)
from peridyn.discretization.lattice import (
    build_lattice,
    check_families,
    cut_lattice,
    grid_layout,
    grid_stencil,
    lattice_on_grid,
)
from peridyn.discretization.pairs import index_bandwidth, row_blocks
from peridyn.errors import CaseFileError, InputError
from peridyn.io import exodus, mesh_text
from peridyn.io.case import Case, Geometry, Region, box_cells
from peridyn.parallel.contact import RankContact
from peridyn.parallel.domain import Domain, agree
from peridyn.parallel.halo import Halo, clearance, ghost_layers, plan_halo
from peridyn.parallel.lattice_domain import LatticeDomain, Slab, ghost_planes, slab_bounds
from peridyn.parallel.partition import rcb
from peridyn.physics.contact import Contact
from peridyn.physics.damage import BondDamage, protected_points
from peridyn.physics.expressions import SpaceTime
from peridyn.physics.lattice_damage import LatticeDamage
from peridyn.physics.loads import BoundaryCondition, InitialCondition, Loading
from peridyn.physics.materials import Model, make_model
from peridyn.physics.materials.blocks import BlockMaterial, assign_blocks, make_block_model
from peridyn.physics.materials.lattice import make_lattice_model
from peridyn.physics.timefunctions import from_spec
from peridyn.physics.transducers import pin_force_actuator, pzt_radial_actuator
from peridyn.setup.grid_points import grid_points, pad3, region_mask
from peridyn.setup.slab_body import grid_plan, slab_points, slab_refusals
from peridyn.setup.storage import choose_storage

#: What ``Interrupted`` says a job was doing when it stopped during ``build``.
BUILDING = "building the model"


@dataclass
class Setup:
    """Everything a case builds before running.

    Under MPI (``build`` with a communicator of several ranks) ``body``, ``bonds``, ``model``,
    ``loading`` and ``damage`` are the rank's part (owned points, then ghosts: see
    ``peridyn.parallel``), ``whole_body`` the body of the case and ``domain`` the part's
    place in it; in one process ``whole_body`` is ``body`` and ``domain`` the serial stand-in.
    """

    body: Body
    bonds: Bonds
    model: Model
    loading: Loading
    damage: BondDamage | None
    contact: Contact | None = None
    domain: Domain | None = None
    #: rank 0's whole body; a ``BodySize`` on the other ranks of a run made slab by slab
    whole_body: Body | BodySize | None = None
    #: ``bonds`` (``bonds`` a ``Bonds``) or ``lattice`` (``bonds`` a ``discretization.lattice.Lattice``)
    storage: str = "bonds"

    def __post_init__(self):
        if self.domain is None:
            self.domain = Domain.serial(self.body.n_points)
        if self.whole_body is None:
            self.whole_body = self.body


def build_body(case: Case, base_dir=".") -> Body:
    """Points of the case geometry, minus removals, with the case's node sets (and ``all``)."""
    body = build_points(case, base_dir)
    body = body.with_node_set("all", np.ones(body.n_points, dtype=bool))
    for name, region in case.node_sets.items():
        mask = region_mask(body, region, f"node_sets.{name}")
        if not mask.any():
            raise _empty_set(case, name, region)
        body = body.with_node_set(name, mask)
    if case.geometry.is_mesh:
        check_mesh_sets(case, body)
    return body


def check_mesh_sets(case: Case, body: Body) -> None:
    """Refuse references to node sets that neither the case nor the mesh defines (the case
    file alone cannot tell for a mesh's sets)."""
    for where, name in case.set_references():
        if name not in body.node_sets and name not in case.actuators:
            raise CaseFileError(
                case.name, where, name, f"a node set of the case or of the mesh: {sorted(body.node_sets)}"
            )


def build_points(case: Case, base_dir=".", removals: bool = True) -> Body:
    """Points of the case geometry, minus its removals (unless ``removals`` is False)."""
    g, d = case.geometry, case.discretization
    if not g.is_mesh and d.spacing is None:
        raise CaseFileError(case.name, "discretization.spacing", None, "a positive spacing (m)")
    body = mesh_body(g, base_dir) if g.is_mesh else grid_points(case)
    for k, region in enumerate(case.removals if removals else []):
        body = body.remove(region_mask(body, region, f"removals[{k}]"))
    return body


def mesh_body(g: Geometry, base_dir=".") -> Body:
    """The body of a text-mesh or Exodus geometry, its file relative to ``base_dir``; a mesh
    with two points at one place (their bond would have zero length) is refused."""
    mesh = Path(g.file) if Path(g.file).is_absolute() else Path(base_dir) / g.file
    read = exodus.body_from_exodus if g.type == "exodus" else mesh_text.from_text_mesh
    body = read(mesh, dim=g.dimension, thickness=g.thickness, plane=g.plane if g.dimension == 2 else None)
    check_distinct_points(body.points, str(mesh))
    return body


def check_distinct_points(points: np.ndarray, source: str) -> None:
    """Refuse ``points`` (n, 3), m, of which two are equal, naming the first such pair (0-based).

    Raises
    ------
    InputError
    """
    order = np.lexsort(points.T[::-1])
    same = np.flatnonzero(np.all(points[order[1:]] == points[order[:-1]], axis=1))
    if same.size:
        i, j = sorted((int(order[same[0]]), int(order[same[0] + 1])))
        raise InputError(
            f"{source}: points {i} and {j} are at the same place {points[i].tolist()} m "
            f"({same.size} duplicate point{'s' if same.size > 1 else ''}): a mesh needs distinct points"
        )


def case_horizon(case: Case, body: Body) -> float:
    """The horizon of the case's discretisation, m."""
    return case.discretization.horizon_metres(body.spacing)


def block_horizons(case: Case, body: Body, of_block=None) -> np.ndarray | None:
    """(n_points,) each point's horizon (m) when the case's blocks have horizons of their own
    that differ (docs/blocks.md); None when every point's is ``case_horizon``. ``of_block``:
    the points' block indices (``block_index``), given by a rank's part of the body."""
    default = case_horizon(case, body)
    values = np.array([b.horizon_metres(body.spacing, default) for b in case.blocks.values()])
    if np.all(values == default):
        return None
    return values[block_index(case, body) if of_block is None else of_block]


def build_bonds(case: Case, body: Body, required=None, of_block=None) -> Bonds:
    """Families of the case's discretisation, with its pre-cracks cut (``required``: the
    points that must have a neighbour, default all; see ``find_bonds``); with blocks of their
    own horizons, each bond within the smaller of its ends' (``block_horizons``, ``of_block``
    as there)."""
    d = case.discretization
    point_horizon = block_horizons(case, body, of_block)
    horizon = case_horizon(case, body) if point_horizon is None else float(np.max(point_horizon))
    box = neighbourhood_box(case, body, horizon)
    if d.points_without_bonds == "warn":
        required = np.zeros(0, dtype=np.int64)
    bonds = find_bonds(
        body, horizon, d.influence, d.partial_volumes, required=required, box=box, point_horizon=point_horizon
    )
    if d.points_without_bonds == "warn":
        warn_points_without_bonds(case, body, bonds)
    cut_precracks(case, body, bonds, in_weighted_volume=False)
    return filtered(case, body, bonds, of_block)


def warn_points_without_bonds(case: Case, body: Body, bonds: Bonds) -> None:
    """Warn of the points that have no neighbour within the horizon
    (``discretization.points_without_bonds: warn``), naming the first few."""
    alone = np.flatnonzero(np.diff(bonds.offsets) == 0)
    if len(alone):
        named = ", ".join(f"{int(p)} at {body.points[p].tolist()}" for p in alone[:3])
        more = f" and {len(alone) - 3} more" if len(alone) > 3 else ""
        warnings.warn(
            f"{case.name}: {len(alone)} points have no neighbour within the horizon ({named}{more}): "
            "no bond holds them (discretization.points_without_bonds: warn)",
            stacklevel=3,
        )


def cut_precracks(case: Case, body: Body, bonds: Bonds, in_weighted_volume: bool) -> None:
    """Break the bonds of the case's pre-cracks whose ``in_weighted_volume`` is the one given:
    those not counting in LPS's weighted volumes before the model is made (``build_bonds``),
    those counting in them after (``build_model``'s callers)."""
    for crack in case.precracks:
        if crack.in_weighted_volume != in_weighted_volume:
            continue
        cut_bonds(body, bonds, precrack_crossing(crack))


def surface_triangles(path) -> np.ndarray:
    """(m, 3, 3) corners (m) of the triangles of an Exodus surface mesh (3-node elements, or
    4-node ones split into two triangles by their first diagonal)."""
    mesh = exodus.read_exodus(path)
    triangles = []
    for block in mesh.blocks:
        nodes = mesh.coordinates[block.connectivity]
        if nodes.shape[1] == 3:
            triangles.append(nodes)
        elif nodes.shape[1] == 4:
            triangles += [nodes[:, [0, 1, 2]], nodes[:, [0, 2, 3]]]
        else:
            raise InputError(f"{path}: block {block.name!r} of {nodes.shape[1]}-node elements, not a surface")
    return np.concatenate(triangles)


def filtered(case: Case, body: Body, bonds: Bonds, of_block=None) -> Bonds:
    """``bonds`` less those the case's bond filters take out, and those between blocks when
    ``discretization.bonds_between_blocks`` is false (``of_block`` as ``block_horizons``'s)."""
    d = case.discretization
    mask = np.zeros(bonds.n_bonds, dtype=bool)
    for f in d.bond_filters:

        def meets(a, b, f=f):
            return crossing_finite_plane(a, b, f.corner, f.normal, f.bottom, f.bottom_length, f.side_length)

        mask |= crossing_mask(body, bonds, meets)
    if not d.bonds_between_blocks and case.blocks:
        blocks = block_index(case, body) if of_block is None else of_block
        mask |= blocks[bonds.owners()] != blocks[bonds.neighbours]
    return without_bonds(bonds, mask) if mask.any() else bonds


def add_actuators(case: Case, body: Body, part: bool = False) -> tuple[Body, list[BoundaryCondition]]:
    """The body with a node set per actuator, and the actuators' boundary conditions; ``part``:
    ``body`` is a rank's part, which may hold none of a PZT patch's points (``slab_refusals``:
    no pin-force actuator)."""
    conditions = []
    for name, a in case.actuators.items():
        signal = from_spec(a.signal, f"actuators.{name}.signal")
        patch = dict(shape=a.shape, layer=a.layer, name=name)
        if a.type == "pzt_radial":
            body, bcs = pzt_radial_actuator(
                body, a.center, a.size, signal, amplitude=a.amplitude, part=part, **patch
            )
        else:
            body, bcs = pin_force_actuator(body, a.center, a.size, signal, line_force=a.line_force, **patch)
        conditions += bcs
    return body, conditions


def build_loading(case: Case, body: Body, extra=(), set_volume=None) -> Loading:
    """Boundary and initial conditions of the case (plus ``extra`` ones), checked for conflicts;
    ``set_volume``: ``body`` is a rank's part (``Loading``)."""
    bcs = [
        BoundaryCondition(
            bc.set,
            bc.kind,
            bc.components,
            value_function(bc.value, f"boundary_conditions[{k}]"),
            where_prescribed=bc.where_prescribed,
        )
        for k, bc in enumerate(case.boundary_conditions)
    ]
    ics = []
    for k, ic in enumerate(case.initial_conditions):
        value = ic.value
        if isinstance(value, dict):
            where = f"initial_conditions[{k}].value"
            if value.get("type") != "expression":
                raise InputError(f"{where}: a number or {{type: expression, text: ...}}, got {value!r}")
            at = body.points[body.node_set(ic.set, set_volume is not None)]
            values = value_function(value, f"initial_conditions[{k}]").at(at, 0.0)
            value = np.repeat(values[:, None], len(ic.components), axis=1)
        ics.append(InitialCondition(ic.set, ic.kind, ic.components, value))
    return Loading(body, [*extra, *bcs], ics, set_volume)


def value_function(spec, where: str):
    """The time function of a condition's ``value`` (``from_spec``), or for ``{type:
    expression, text}`` its expression in x, y, z and t (``SpaceTime``)."""
    if not (isinstance(spec, dict) and spec.get("type") == "expression"):
        return from_spec(spec, f"{where}.value")
    if set(spec) != {"type", "text"} or not isinstance(spec["text"], str):
        raise InputError(f"{where}.value: an expression takes one 'text' (a string), got {spec!r}")
    try:
        return SpaceTime(spec["text"])
    except InputError as exc:
        raise InputError(f"{where}.value: {exc}") from None


def check_placements(case: Case, body: Body, nearest=None, bounds=None) -> None:
    """Refuse sensors, line-probe ends, PZT sensors and actuators outside the body, and
    pre-cracks that do not meet it (``check_precracks``).

    A position is outside when it lies more than half a spacing outside the cell of every
    point near it (an in-plane ``center`` is compared with the x-y cells only). On a rank's
    part, ``nearest`` takes the least of the ranks' distances ((m,) m) and ``bounds`` ((2, 3)
    m) are the whole body's lowest and highest coordinates.

    Raises
    ------
    CaseFileError
        Naming the key (e.g. ``output.sensors.tip``), the position and the distance (m).
    """
    out = case.output
    spots = [(f"output.sensors.{k}", v) for k, v in out.sensors.items()]
    for k, line in out.lines.items():
        spots += [(f"output.lines.{k}.start", line.start), (f"output.lines.{k}.end", line.end)]
    spots += [(f"output.pzt_sensors.{k}.center", v.center) for k, v in out.pzt_sensors.items()]
    spots += [(f"actuators.{k}.center", v.center) for k, v in case.actuators.items()]
    check_precracks(case, body, nearest, bounds)
    if not spots:
        return
    nearest = nearest or (lambda gaps: gaps)
    low, high = (body.points.min(axis=0), body.points.max(axis=0)) if bounds is None else bounds
    in_plane = [len(v) == 2 and body.dim == 3 for _, v in spots]
    for axes, chosen in ((3, [not p for p in in_plane]), (2, in_plane)):
        items = [spot for spot, c in zip(spots, chosen, strict=True) if c]
        if items:
            far = nearest(distance_outside(body, np.array([pad3(v)[:axes] for _, v in items]), axes))
            for (key, value), d in zip(items, far, strict=True):
                if d > 0.5 * body.spacing:
                    raise CaseFileError(
                        case.name,
                        key,
                        value,
                        f"a position inside the body: it is {d:.3g} m outside "
                        f"(spacing {body.spacing:g} m; the body spans "
                        f"{low.tolist()} to {high.tolist()} m)",
                    )


#: Most sample points along a pre-crack's edge (``check_precracks``).
MAX_CRACK_SAMPLES = 200


def check_precracks(case: Case, body: Body, nearest=None, bounds=None) -> None:
    """Refuse a pre-crack that lies wholly outside the body (it would cut no bond): none of its
    sample points (every half spacing along it, at most ``MAX_CRACK_SAMPLES`` an edge) within
    half a spacing of a point's cell (``nearest`` and ``bounds``: ``check_placements``').

    Raises
    ------
    CaseFileError
        Naming ``precracks[i]`` and how far outside it lies (m).
    """
    axes = 3 if body.dim == 3 else 2
    nearest = nearest or (lambda gaps: gaps)
    for i, crack in enumerate(case.precracks):
        if crack.type == "rectangle":
            o, u, v = (np.asarray(pad3(p)) for p in (crack.origin, crack.edge_u, crack.edge_v))
            a, b = _samples(u, body.spacing), _samples(v, body.spacing)
            samples = o + a[:, None, None] * u + b[None, :, None] * v
        elif crack.type == "surface":  # the triangles' corners and centroids
            triangles = surface_triangles(crack.file)
            samples = np.concatenate([triangles.reshape(-1, 3), triangles.mean(axis=1)])
        elif crack.type == "bonds":  # the bonds' ends, in the plane or in space
            samples = np.reshape(crack.pairs, (-1, len(crack.pairs[0]) // 2))
        else:
            start, end = np.asarray(pad3(crack.start)), np.asarray(pad3(crack.end))
            samples = start + _samples(end - start, body.spacing)[:, None] * (end - start)
        within = samples.shape[-1] if crack.type == "bonds" else axes
        samples = samples.reshape(-1, samples.shape[-1])[:, :within]
        gap = float(nearest(distance_outside(body, samples, within)).min())
        low, high = (body.points.min(axis=0), body.points.max(axis=0)) if bounds is None else bounds
        if gap > 0.5 * body.spacing:
            raise CaseFileError(
                case.name,
                f"precracks[{i}]",
                crack.model_dump(exclude_none=True),
                f"a pre-crack that meets the body: it lies {gap:.3g} m outside and would cut no bond "
                f"(the body spans {low.tolist()} to {high.tolist()} m)",
            )


def _samples(edge: np.ndarray, spacing: float) -> np.ndarray:
    """Fractions 0..1 along ``edge`` (m) every half ``spacing``, at most ``MAX_CRACK_SAMPLES``."""
    n = int(min(MAX_CRACK_SAMPLES, np.ceil(2.0 * np.linalg.norm(edge) / spacing) + 1))
    return np.linspace(0.0, 1.0, max(n, 2))


#: Nearest points searched for the cell that a position is closest to.
NEAREST_CELLS = 8


def distance_outside(body: Body, positions: np.ndarray, axes: int = 3) -> np.ndarray:
    """(m,) distance (m) from each of ``positions`` (m, axes) to the nearest point's cell
    (0 inside a cell), over the first ``axes`` coordinates."""
    tree = cKDTree(body.points[:, :axes])
    k = min(NEAREST_CELLS, body.n_points)
    _, idx = tree.query(positions, k=k)
    idx = np.asarray(idx).reshape(len(positions), k)
    found = idx < body.n_points  # the tree finds none where the distance overflows (a 1e300 m position)
    idx = np.where(found, idx, 0)
    cells = body.cells if body.dim == 3 else np.column_stack([body.cells[:, :2], np.zeros(body.n_points)])
    gap = np.abs(positions[:, None, :] - body.points[idx, :axes]) - 0.5 * cells[idx, :axes]
    with np.errstate(over="ignore"):  # a distance beyond the floats is inf: outside, as it should
        far = np.linalg.norm(np.clip(gap, 0.0, None), axis=2)
    return np.min(np.where(found, far, np.inf), axis=1)


def build(case: Case, base_dir=".", comm=None) -> Setup:
    """Body, bonds, model, loading and damage of a case; with a communicator of several ranks
    (``peridyn.parallel.comm``), the part of this rank (``build_part``).

    Within ``peridyn.interrupts.deferred``, a SIGINT or SIGTERM stops a serial build after the
    phase under way (points, bonds, model) with ``Interrupted``."""
    if comm is not None and comm.size > 1:
        if choose_storage(case, None) == "lattice":
            return build_lattice_part(case, comm, base_dir)
        return build_part(case, comm, base_dir)
    body = build_body(case, base_dir)
    interrupts.check(where=BUILDING)
    check_placements(case, body)
    body, actuation = add_actuators(case, body)
    if choose_storage(case, body) == "lattice":
        return build_on_lattice(case, body, actuation)
    bonds = build_bonds(case, body)
    interrupts.check(where=BUILDING)
    model = build_model(case, body, bonds)
    cut_precracks(case, body, bonds, in_weighted_volume=True)
    damage = build_damage(case, model)
    interrupts.check(where=BUILDING)
    loading = build_loading(case, body, actuation)
    check_loading(case, loading)
    return Setup(body, bonds, model, loading, damage, build_contact(case, model))


def build_on_lattice(case: Case, body: Body, actuation=()) -> Setup:
    """The Setup of a case on lattice storage (``setup.storage``): the body's lattice with the
    pre-cracks cut, the material and damage on it (``setup.bonds`` is the lattice)."""
    d = case.discretization
    lattice = build_lattice(body, case_horizon(case, body), d.influence, d.partial_volumes)
    interrupts.check(where=BUILDING)
    model, damage = lattice_model(case, body, lattice)
    loading = build_loading(case, body, actuation)
    check_loading(case, loading)
    return Setup(body, lattice, model, loading, damage, storage="lattice")


def lattice_model(case: Case, body: Body, lattice, protected=None) -> tuple:
    """The case's pre-cracks cut into ``lattice`` (in place), then its material and bond breaking
    (None without ``material.damage``) on ``body`` and ``lattice`` (``protected``: the points of
    its no-damage sets, (n_points,) bool, given by a rank's part)."""
    for crack in case.precracks:
        cut_lattice(body, lattice, precrack_crossing(crack))
    interrupts.check(where=BUILDING)
    mat = case.material
    model = make_lattice_model(
        mat.model,
        body,
        lattice,
        E=mat.E,
        density=mat.density,
        nu=mat.nu,
        surface_correction=mat.surface_correction,
        dtype=case.solver.dtype,
    )
    d = mat.damage
    damage = None
    if d is not None:
        no_damage = d.no_damage_sets if protected is None else ()
        damage = LatticeDamage(
            model, d.critical_stretch, d.fracture_energy, no_damage, d.critical_bond_stress, protected
        )
    interrupts.check(where=BUILDING)
    return model, damage


def build_lattice_part(case: Case, comm, base_dir=".") -> Setup:
    """This rank's part of a case on lattice storage (``peridyn.parallel.lattice_domain``): a
    slab of grid planes across x and the ghost planes either side, its lattice with the whole
    grid's stencil, the pre-cracks, model, damage and loading on it. Collective: every rank
    calls it, and an error on one rank is raised on all. A case ``slab_refusals`` names is
    made whole on every rank first; others slab by slab (``setup.slab_body``), rank 0 making
    the whole body for the recorder."""
    part = _build_lattice_part if slab_refusals(case) else _build_lattice_slab
    setup, owned, ghosts, ghost_owner, slab = agree(comm, part, case, comm, base_dir)
    halo = Halo(comm, plan_halo(comm, owned, ghosts, ghost_owner))
    local_ids = np.concatenate([owned, ghosts])
    n_words = setup.bonds.broken.shape[0]
    setup.domain = LatticeDomain(comm, local_ids, len(owned), setup.whole_body.n_points, halo, slab, n_words)
    return setup


def _build_lattice_part(case: Case, comm, base_dir):
    """``build_lattice_part`` up to the halo plan: the part's Setup, the owned and ghost global
    indices (local order), the ghosts' ranks and the rank's ``Slab``."""
    body = build_body(case, base_dir)
    check_placements(case, body)
    body, actuation = add_actuators(case, body)
    loading = build_loading(case, body, actuation)
    check_loading(case, loading)
    d = case.discretization
    horizon = case_horizon(case, body)
    shape, spacing, origin, grid_index = grid_layout(body)
    stencil = grid_stencil(body, shape, spacing, horizon, d.influence, d.partial_volumes)
    bounds = slab_bounds(int(shape[0]), comm.size)
    slab = Slab.of_rank(shape, bounds, comm.rank, ghost_planes(stencil.offsets))
    owned, ghosts = slab.points(grid_index)  # planes ascending: the ghosts by owner rank
    if not len(owned):
        raise InputError(
            f"lattice storage: rank {comm.rank}'s planes across x ({slab.lo} to {slab.hi - 1}) "
            "hold no point: use fewer ranks, or discretization.storage: bonds"
        )
    local_ids = np.concatenate([owned, ghosts])
    part = body.subset(local_ids)
    layout = slab.layout(spacing, origin, grid_index[local_ids])
    lattice = lattice_on_grid(part, layout, stencil, horizon, d.influence)
    check_families(lattice, part, np.arange(len(owned)), local_ids)
    no_damage = case.material.damage.no_damage_sets if case.material.damage is not None else []
    model, damage = lattice_model(case, part, lattice, protected_points(body, no_damage)[local_ids])
    ghost_owner = slab.owners(bounds, grid_index[ghosts])
    loading = loading.restricted(part, local_ids)
    setup = Setup(part, lattice, model, loading, damage, None, None, body, "lattice")
    return setup, owned, ghosts, ghost_owner, slab


def _build_lattice_slab(case: Case, comm, base_dir):
    """``_build_lattice_part`` from the rank's planes alone (``setup.slab_body``): the node sets,
    actuators, placement checks and force spreads of the whole body by reductions over the
    ranks; the whole body on rank 0 only (``BodySize`` elsewhere)."""
    d = case.discretization
    plan = grid_plan(case, comm)
    plane = grid_points(case, (plan.first, plan.first + 1))  # the grid's cells, dim and spacing
    horizon = case_horizon(case, plane)
    spacing = grid_layout(plane)[1]
    stencil = grid_stencil(plane, plan.shape, spacing, horizon, d.influence, d.partial_volumes)
    bounds = slab_bounds(int(plan.shape[0]), comm.size)
    slab = Slab.of_rank(plan.shape, bounds, comm.rank, ghost_planes(stencil.offsets))
    part, ids = slab_points(case, plan, slab.first, slab.stop)
    grid_index = grid_layout(part, (plan.origin, plan.shape))[3]
    owned, ghosts = slab.points(grid_index)  # planes ascending: the ghosts by owner rank
    if not len(owned):
        raise InputError(
            f"lattice storage: rank {comm.rank}'s planes across x ({slab.lo} to {slab.hi - 1}) "
            "hold no point: use fewer ranks, or discretization.storage: bonds"
        )
    local = np.concatenate([owned, ghosts])
    part, ids, grid_index, n_owned = part.subset(local), ids[local], grid_index[local], len(owned)
    part = _slab_node_sets(case, part, plan, comm, n_owned)
    check_placements(case, part, lambda gaps: comm.allreduce(gaps, "min"), plan.bounds)
    part, actuation = add_actuators(case, part, part=True)
    for name in case.actuators:
        if not comm.allreduce(int(np.count_nonzero(part.node_sets[name] < n_owned))):
            add_actuators(case, part)  # no rank holds a point of the patch: the serial error
    volumes = _set_volumes(case, part, comm, n_owned)
    loading = build_loading(case, part, actuation, lambda name, idx: volumes[name])
    check_loading(case, loading)
    layout = slab.layout(spacing, plan.origin, grid_index)
    lattice = lattice_on_grid(part, layout, stencil, horizon, d.influence)
    check_families(lattice, part, np.arange(n_owned), ids)
    no_damage = case.material.damage.no_damage_sets if case.material.damage is not None else []
    model, damage = lattice_model(case, part, lattice, protected_points(part, no_damage, empty=True))
    ghost_owner = slab.owners(bounds, grid_index[n_owned:])
    whole = _whole_body(case, base_dir) if comm.rank == 0 else BodySize(plan.n_points, part.dim, part.spacing)
    setup = Setup(part, lattice, model, loading, damage, None, None, whole, "lattice")
    return setup, ids[:n_owned], ids[n_owned:], ghost_owner, slab


def _whole_body(case: Case, base_dir) -> Body:
    """The whole body with its node sets and actuators' sets (rank 0's, for the recorder)."""
    return add_actuators(case, build_body(case, base_dir))[0]


def _slab_node_sets(case: Case, part: Body, plan, comm, n_owned: int) -> Body:
    """``part`` (a rank's points, the first ``n_owned`` its own) with the case's node sets and
    ``all``, as ``build_body`` makes them on the whole body (faces by its bounds), a set no
    rank holds a point of refused as there."""
    part = part.with_node_set("all", np.ones(part.n_points, dtype=bool))
    for name, region in case.node_sets.items():
        mask = region_mask(part, region, f"node_sets.{name}", plan.bounds)
        if not comm.allreduce(int(np.count_nonzero(mask[:n_owned]))):
            raise _empty_set(case, name, region)
        part = part.with_node_set(name, mask, empty=True)
    return part


def _empty_set(case: Case, name: str, region: Region) -> CaseFileError:
    """The error of a node set whose region holds no point of the body."""
    return CaseFileError(
        case.name,
        f"node_sets.{name}",
        region.model_dump(exclude_none=True),
        "a region that contains at least one point",
    )


def _set_volumes(case: Case, part: Body, comm, n_owned: int) -> dict:
    """The volume (m^3) of each set a ``force`` condition spreads over, summed over the whole
    set in the whole body's point order (the ranks' owned points in rank order), as a serial
    run sums it."""
    volumes = {}
    for bc in case.boundary_conditions:
        if bc.kind == "force" and bc.set not in volumes:
            idx = part.node_set(bc.set, empty=True)
            mine = part.volumes[idx[idx < n_owned]]
            volumes[bc.set] = np.concatenate(comm.allgather(mine)).sum()
    return volumes


def precrack_crossing(crack):
    """``crossing(x_from, x_to)`` (bool mask of the segments that cross) of a case's pre-crack."""
    if crack.type == "rectangle":
        return lambda a, b: crossing_rectangle(a, b, crack.origin, crack.edge_u, crack.edge_v)
    if crack.type == "surface":
        triangles = surface_triangles(crack.file)
        return lambda a, b: crossing_triangles(a, b, triangles)
    if crack.type == "bonds":
        return listed_pairs(crack.pairs, crack.tolerance)
    return lambda a, b: crossing_segment(a, b, crack.start, crack.end)


#: Ghost layers of a rank's part (``peridyn.parallel.halo``): two, so that every per-point
#: quantity of a neighbour of an owned point (LPS dilatation, surface corrections) is computed
#: on the rank from that neighbour's whole family.
GHOST_LAYERS = 2


def build_part(case: Case, comm, base_dir=".") -> Setup:
    """This rank's part of the case: the points that recursive coordinate bisection gives it and
    two layers of ghosts (``peridyn.parallel``), their bonds only, the model, damage and loading
    on them. Each owned point's family keeps the serial order (the search runs on the part's
    points in global order, then the owned points are moved first, farthest from the ghosts
    first, and the ghosts after), so that the kernels sum every force in the serial order.
    Collective: every rank calls it, and an error on one rank is raised on all.
    """
    setup, owned, ghosts, ghost_owner, clear_rows = agree(comm, _build_part, case, comm, base_dir)
    halo = Halo(comm, plan_halo(comm, owned, ghosts, ghost_owner))
    local_ids = np.concatenate([owned, ghosts])
    n_points = setup.whole_body.n_points
    setup.domain = Domain(
        comm, local_ids, len(owned), n_points, halo, "recursive coordinate bisection", clear_rows
    )
    setup.contact = agree(comm, build_contact, case, setup.model, setup.domain, setup.whole_body)
    return setup


def _build_part(case: Case, comm, base_dir):
    """``build_part`` up to the halo plan: the part's Setup (its domain set after), the owned
    and ghost global indices (local order), the ghosts' ranks and the numbers of leading owned
    rows of clearance 1 and 2 (``Domain.clear_rows``)."""
    body = build_body(case, base_dir)
    check_placements(case, body)
    body, actuation = add_actuators(case, body)
    loading = build_loading(case, body, actuation)
    check_loading(case, loading)
    owner = rcb(body.points, comm.size)
    owned = np.flatnonzero(owner == comm.rank)
    of_block = block_index(case, body) if case.blocks else None  # of the whole body's points
    ghosts = ghost_layers(body.points, owned, bond_reach(case, body), GHOST_LAYERS)
    near = np.union1d(owned, ghosts)
    bonds = build_bonds(
        case,
        body.subset(near),
        required=np.searchsorted(near, owned),
        of_block=None if of_block is None else of_block[near],
    )
    # ghosts without a neighbour on the rank (an outer ghost whose cells all miss) are dropped
    ghosts = ghosts[np.diff(bonds.offsets)[np.searchsorted(near, ghosts)] > 0]
    # by owner rank; in each rank's block, the ghosts an owned point's family holds first (the
    # rows whose dilatation an owned force reads: ``LPSModel.force_overlapped``)
    read = np.zeros(len(near), dtype=bool)
    owned_row = np.zeros(len(near), dtype=bool)
    owned_row[np.searchsorted(near, owned)] = True
    read[bonds.neighbours[owned_row[bonds.owners()]]] = True
    unread = ~read[np.searchsorted(near, ghosts)]
    ghosts = ghosts[np.lexsort((ghosts, unread, owner[ghosts]))]
    clear = clearance(bonds.offsets, bonds.neighbours, np.searchsorted(near, owned), GHOST_LAYERS)
    owned = owned[np.argsort(-clear, kind="stable")]  # farthest from the ghosts first
    clear_rows = tuple(int(np.count_nonzero(clear >= c)) for c in range(1, GHOST_LAYERS + 1))
    local_ids = np.concatenate([owned, ghosts])
    bonds = reorder_bonds(bonds, np.searchsorted(near, local_ids), len(near))
    bonds = with_whole_body_rows(comm, bonds, local_ids, len(owned), body.n_points)
    part = body.subset(local_ids)
    part_blocks = None if of_block is None else of_block[local_ids]
    model = build_model(case, part, bonds, part_blocks)
    cut_precracks(case, part, bonds, in_weighted_volume=True)
    materials = case.block_materials().values()
    no_damage = sorted({name for m in materials if m.damage is not None for name in m.damage.no_damage_sets})
    protected = protected_points(body, no_damage)[local_ids]
    damage = build_damage(case, model, protected, part_blocks)
    setup = Setup(part, bonds, model, loading.restricted(part, local_ids), damage, None, None, body)
    return setup, owned, ghosts, owner[ghosts], clear_rows


def with_whole_body_rows(comm, bonds: Bonds, local_ids: np.ndarray, n_owned: int, n_points: int) -> Bonds:
    """A rank's ``bonds`` with the whole body's row numbers ``local_ids`` and row blocks
    (``discretization.pairs``: the PMB force then sums in the serial run's order). The index
    bandwidth is the largest over the ranks' owned families (every bond is in one)."""
    owned_bonds = bonds.offsets[n_owned]
    offsets = bonds.offsets[: n_owned + 1]
    bandwidth = index_bandwidth(offsets, bonds.neighbours[:owned_bonds], local_ids)
    blocks = row_blocks(n_points, int(comm.allreduce(bandwidth, "max")))
    return replace(bonds, global_rows=local_ids, row_blocks=blocks)


def neighbourhood_box(case: Case, body: Body, horizon: float) -> np.ndarray | None:
    """(3,) half-widths (m) of the box families of ``discretization.neighbourhood: box``:
    ``box_cells`` along each axis; None for spheres."""
    if case.discretization.neighbourhood != "box":
        return None
    return box_cells(horizon, body.cells[0]) * body.cells[0]


def bond_reach(case: Case, body: Body) -> float:
    """Distance (m) within which ``build_bonds`` finds a point's neighbours: the largest
    horizon's search reach (``search_reach``), or a box family's half-diagonal."""
    point_horizon = block_horizons(case, body)
    horizon = case_horizon(case, body) if point_horizon is None else float(np.max(point_horizon))
    box = neighbourhood_box(case, body, horizon)
    if box is not None:
        return float(np.linalg.norm(box * (1 + HORIZON_RTOL)))
    return search_reach(body, horizon, case.discretization.partial_volumes)


def block_index(case: Case, body: Body) -> np.ndarray:
    """(n_points,) int64: each point's block, an index into ``case.blocks`` (in order).

    Raises
    ------
    CaseFileError
        At ``blocks``, when a block holds no point or a point lies in two blocks or in none.
    """
    masks = {
        name: region_mask(body, b.region, f"blocks.{name}.region")
        if b.region is not None
        else np.isin(np.arange(body.n_points), body.node_set(b.set))
        for name, b in case.blocks.items()
    }
    try:
        return assign_blocks(masks)
    except InputError as exc:
        raise CaseFileError(case.name, "blocks", None, str(exc), has_value=False) from None


def build_model(case: Case, body: Body, bonds: Bonds, of_block=None) -> Model:
    """The case's material bound to ``body`` and ``bonds``: one material, or the materials of
    its blocks (``peridyn.physics.materials.blocks``; ``of_block``: the points' block indices,
    given by a rank's part of the body)."""
    if case.blocks:
        mats = [case.materials[b.material] for b in case.blocks.values()]
        return make_block_model(
            mats[0].model,
            body,
            bonds,
            block_index(case, body) if of_block is None else of_block,
            [BlockMaterial(m.E, m.density, m.nu) for m in mats],
            surface_correction=mats[0].surface_correction,
            dtype=case.solver.dtype,
        )
    mat = case.material
    return make_model(
        mat.model,
        body,
        bonds,
        E=mat.E,
        density=mat.density,
        nu=mat.nu,
        surface_correction=mat.surface_correction,
        dtype=case.solver.dtype,
    )


def build_damage(case: Case, model: Model, protected=None, of_block=None) -> BondDamage | None:
    """The case's bond breaking on ``model`` (None without ``material.damage``, or with blocks
    none of whose materials has damage); ``protected`` ((n_points,) bool or None): the points of
    the no-damage sets, and ``of_block`` the points' block indices, given by a rank's part."""
    if case.blocks:
        return block_damage(case, model, protected, of_block)
    d = case.material.damage
    if d is None:
        return None
    timed = isinstance(d.critical_stretch, dict)
    return BondDamage(
        model,
        None if timed else d.critical_stretch,
        d.fracture_energy,
        d.no_damage_sets if protected is None else (),
        critical_bond_stress=d.critical_bond_stress,
        protected=protected,
        schedule=from_spec(d.critical_stretch, "material.damage.critical_stretch") if timed else None,
    )


def block_damage(case: Case, model: Model, protected=None, of_block=None) -> BondDamage | None:
    """Bond breaking of a body of several blocks (docs/blocks.md): each point's critical stretch
    from its block's material damage (inf, never, where it has none), a bond breaking at the
    smaller of its ends' (``BondDamage``); the no-damage sets of every material's damage
    (``protected`` and ``of_block`` as ``build_damage``'s)."""
    blocks = list(case.blocks.values())
    specs = [case.materials[b.material].damage for b in blocks]
    if all(d is None for d in specs):
        return None
    of_point = block_index(case, model.body) if of_block is None else of_block
    stretch = np.full(model.body.n_points, np.inf)
    for k, (block, d) in enumerate(zip(blocks, specs, strict=True)):
        if d is None:
            continue
        mine = of_point == k
        if isinstance(d.critical_stretch, dict):
            raise InputError(
                f"materials.{block.material}.damage.critical_stretch: a number (a critical "
                "stretch in time is for a body of one material)"
            )
        if d.critical_stretch is not None:
            stretch[mine] = d.critical_stretch
        elif d.fracture_energy is not None:
            stretch[mine] = model.critical_stretch(d.fracture_energy)[mine]
        else:
            stretch[mine] = d.critical_bond_stress / case.materials[block.material].E
    no_damage = sorted({name for d in specs if d is not None for name in d.no_damage_sets})
    if protected is not None:
        return BondDamage(model, critical_stretch=stretch, protected=protected)
    return BondDamage(model, critical_stretch=stretch, no_damage_sets=no_damage)


def check_loading(case: Case, loading: Loading) -> None:
    """Refuse loads that leave the case's solver nothing to do."""
    if case.solver.type == "static" and not loading.has_loads:
        raise CaseFileError(case.name, "boundary_conditions", [], "at least one load for a static run")
    if case.solver.type == "newmark" and not (loading.has_loads or loading.initial):
        raise CaseFileError(
            case.name, "boundary_conditions", [], "a load or an initial condition: nothing would move"
        )
    if case.solver.type == "newton" and not loading.has_loads:
        raise CaseFileError(case.name, "boundary_conditions", [], "at least one load for a newton run")
    if case.solver.type == "explicit" and not (loading.has_loads or loading.initial):
        raise CaseFileError(
            case.name, "boundary_conditions", [], "a load or an initial condition: nothing would move"
        )


def build_contact(
    case: Case, model: Model, domain: Domain | None = None, whole_body: Body | None = None
) -> Contact | None:
    """The case's short-range contact forces, or None without a ``contact`` block; with the
    ``domain`` of a rank's part (several ranks) and the case's ``whole_body``, the rank's
    (``peridyn.parallel.contact``)."""
    c = case.contact
    if c is None:
        return None
    radius = c.radius_m if c.radius_m is not None else c.radius * model.body.spacing
    try:
        if domain is not None and domain.size > 1:
            return RankContact(model, domain, whole_body, radius, c.stiffness_factor)
        return Contact(model, radius, c.stiffness_factor, beyond_horizon=c.beyond_horizon == "allow")
    except InputError as exc:
        raise CaseFileError(case.name, "contact", c.model_dump(exclude_none=True), str(exc)) from None
