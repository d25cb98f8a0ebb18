"""From a validated case to the objects of a run: body, bonds, material model, loads, damage
and contact (``build``); the ``build_*`` steps are there for Python users who want to stop
half-way (e.g. to inspect the bonds)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from peridyn.discretization import geometry
from peridyn.discretization.body import Body, in_box, in_cylinder, in_sphere
from peridyn.discretization.bonds import Bonds, crossing_rectangle, crossing_segment, cut_bonds, find_bonds
from peridyn.errors import CaseFileError, InputError
from peridyn.io import mesh_text
from peridyn.io.case import Case, Region
from peridyn.physics.contact import Contact
from peridyn.physics.damage import BondDamage
from peridyn.physics.loads import BoundaryCondition, InitialCondition, Loading
from peridyn.physics.materials import Model, make_model
from peridyn.physics.timefunctions import from_spec
from peridyn.physics.transducers import pin_force_actuator, pzt_radial_actuator


@dataclass
class Setup:
    """Everything a case builds before running."""

    body: Body
    bonds: Bonds
    model: Model
    loading: Loading
    damage: BondDamage | None
    contact: Contact | None = None


def build_body(case: Case, base_dir=".") -> Body:
    """Points of the case geometry, minus removals, with the case's node sets (and ``all``)."""
    body = build_points(case, base_dir)
    body = body.with_node_set("all", np.ones(body.n_points, dtype=bool))
    for name, region in case.node_sets.items():
        mask = region_mask(body, region, f"node_sets.{name}")
        if not mask.any():
            raise CaseFileError(
                case.name,
                f"node_sets.{name}",
                region.model_dump(exclude_none=True),
                "a region that contains at least one point",
            )
        body = body.with_node_set(name, mask)
    return body


def build_points(case: Case, base_dir=".", removals: bool = True) -> Body:
    """Points of the case geometry, minus its removals (unless ``removals`` is False)."""
    g, d = case.geometry, case.discretization
    if g.type != "mesh" and d.spacing is None:
        raise CaseFileError(case.name, "discretization.spacing", None, "a positive spacing (m)")
    if g.type == "box":
        body = geometry.box(g.size, d.spacing, g.origin or (0.0, 0.0, 0.0))
    elif g.type == "plate":
        body = geometry.plate(
            *g.size,
            spacing=d.spacing,
            layers=g.layers,
            origin=g.origin or (0.0, 0.0, 0.0),
            layer_placement=g.layer_placement,
        )
    elif g.type == "rectangle":
        body = geometry.rectangle(
            *g.size,
            spacing=d.spacing,
            thickness=g.thickness,
            plane=g.plane,
            origin=(g.origin or (0.0, 0.0))[:2],
        )
    else:
        mesh = Path(g.file) if Path(g.file).is_absolute() else Path(base_dir) / g.file
        body = mesh_text.from_text_mesh(
            mesh, dim=g.dimension, thickness=g.thickness, plane=g.plane if g.dimension == 2 else None
        )
    for k, region in enumerate(case.removals if removals else []):
        body = body.remove(region_mask(body, region, f"removals[{k}]"))
    return body


def region_mask(body: Body, region: Region, where: str) -> np.ndarray:
    """(n_points,) bool mask of a case-file region."""
    pad = pad3
    if region.type == "all":
        return np.ones(body.n_points, dtype=bool)
    if region.type == "box":
        return in_box(pad(region.min), pad(region.max))(body.points)
    if region.type == "sphere":
        return in_sphere(pad(region.center), region.radius)(body.points)
    if region.type == "cylinder":
        return in_cylinder(pad(region.center), region.radius, region.axis)(body.points)
    if region.type == "face":
        return geometry.face(body, region.face, region.depth)
    try:
        return geometry.layer(body, region.index)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def pad3(v) -> list:
    """A 2- or 3-component coordinate as 3 components (z = 0 for 2D input)."""
    return list(v) + [0.0] * (3 - len(v))


def build_bonds(case: Case, body: Body) -> Bonds:
    """Families of the case's discretisation, with its pre-cracks cut."""
    d = case.discretization
    horizon = d.horizon_m if d.horizon_m is not None else d.horizon * body.spacing
    bonds = find_bonds(body, horizon, d.influence, d.partial_volumes)
    for crack in case.precracks:
        if crack.type == "rectangle":

            def crossing(a, b, c=crack):
                return crossing_rectangle(a, b, c.origin, c.edge_u, c.edge_v)
        else:

            def crossing(a, b, c=crack):
                return crossing_segment(a, b, c.start, c.end)

        cut_bonds(body, bonds, crossing)
    return bonds


def add_actuators(case: Case, body: Body) -> tuple[Body, list[BoundaryCondition]]:
    """The body with a node set per actuator, and the actuators' boundary conditions."""
    conditions = []
    for name, a in case.actuators.items():
        signal = from_spec(a.signal, f"actuators.{name}.signal")
        if a.type == "pzt_radial":
            body, bcs = pzt_radial_actuator(
                body, a.center, a.size, signal, shape=a.shape, layer=a.layer, amplitude=a.amplitude, name=name
            )
        else:
            body, bcs = pin_force_actuator(
                body,
                a.center,
                a.size,
                signal,
                shape=a.shape,
                layer=a.layer,
                line_force=a.line_force,
                name=name,
            )
        conditions += bcs
    return body, conditions


def build_loading(case: Case, body: Body, extra=()) -> Loading:
    """Boundary and initial conditions of the case (plus ``extra`` ones), checked for conflicts."""
    bcs = [
        BoundaryCondition(
            bc.set, bc.kind, bc.components, from_spec(bc.value, f"boundary_conditions[{k}].value")
        )
        for k, bc in enumerate(case.boundary_conditions)
    ]
    ics = [InitialCondition(ic.set, ic.kind, ic.components, ic.value) for ic in case.initial_conditions]
    return Loading(body, [*extra, *bcs], ics)


def check_placements(case: Case, body: Body) -> None:
    """Refuse sensors, line-probe ends, PZT sensors and actuators outside the body.

    A position is outside when it lies more than half a spacing outside the cell of every
    point near it (an in-plane ``center`` is compared with the x-y cells only).

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
    if not spots:
        return
    in_plane = [len(v) == 2 and body.dim == 3 for _, v in spots]
    for axes, chosen in ((3, [not p for p in in_plane]), (2, in_plane)):
        items = [spot for spot, c in zip(spots, chosen, strict=True) if c]
        if items:
            far = distance_outside(body, np.array([pad3(v)[:axes] for _, v in items]), axes)
            for (key, value), d in zip(items, far, strict=True):
                if d > 0.5 * body.spacing:
                    raise CaseFileError(
                        case.name,
                        key,
                        value,
                        f"a position inside the body: it is {d:.3g} m outside "
                        f"(spacing {body.spacing:g} m; the body spans "
                        f"{body.points.min(axis=0).tolist()} to {body.points.max(axis=0).tolist()} m)",
                    )


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


def build(case: Case, base_dir=".") -> Setup:
    """Body, bonds, model, loading and damage of a case."""
    body = build_body(case, base_dir)
    check_placements(case, body)
    body, actuation = add_actuators(case, body)
    bonds = build_bonds(case, body)
    mat = case.material
    model = make_model(
        mat.model,
        body,
        bonds,
        E=mat.E,
        density=mat.density,
        nu=mat.nu,
        surface_correction=mat.surface_correction,
        dtype=case.solver.dtype,
    )
    damage = None
    if mat.damage is not None:
        damage = BondDamage(
            model,
            mat.damage.critical_stretch,
            mat.damage.fracture_energy,
            mat.damage.no_damage_sets,
            critical_bond_stress=mat.damage.critical_bond_stress,
        )
    loading = build_loading(case, body, actuation)
    check_loading(case, loading)
    return Setup(body, bonds, model, loading, damage, build_contact(case, model))


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


def build_contact(case: Case, model: Model) -> Contact | None:
    """The case's short-range contact forces, or None without a ``contact`` block."""
    c = case.contact
    if c is None:
        return None
    radius = c.radius_m if c.radius_m is not None else c.radius * model.body.spacing
    try:
        return Contact(model, radius, c.stiffness_factor)
    except InputError as exc:
        raise CaseFileError(case.name, "contact", c.model_dump(exclude_none=True), str(exc)) from None
