"""Which storage of the bonds a case runs on (``discretization.storage``): bond lists, or the
lattice of a grid body (``peridyn.discretization.lattice``), and why a case needs bond lists."""

from __future__ import annotations

from peridyn.discretization.body import Body
from peridyn.discretization.lattice import grid_layout
from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import Case
from peridyn.physics.materials.lattice import lattice_support


def lattice_refusals(case: Case) -> list[str]:
    """What in ``case`` lattice storage cannot run (empty: nothing), before any point is made."""
    why = []
    g, d, s, out = case.geometry, case.discretization, case.solver, case.output
    if g.is_mesh:
        why.append(
            f"a {g.type} geometry read from a file (lattice storage takes box, plate and rectangle grids)"
        )
    if case.blocks:
        why.append("several blocks")
    if case.contact is not None:
        why.append("contact")
    if d.neighbourhood != "sphere":
        why.append(f"a {d.neighbourhood} neighbourhood")
    if s.type != "explicit":
        why.append(f"a {s.type} solver (lattice storage runs explicit solvers)")
    if s.step_rule == "peridigm":
        why.append("solver.step_rule peridigm")
    if s.arithmetic == "peridigm":
        why.append("solver.arithmetic peridigm")
    if out.stress or out.strain:
        why.append("the stress and strain outputs")
    if out.exodus:
        why.append("Exodus output")
    if s.backend != "cpu":
        why.append(f"solver.backend {s.backend} (the GPU backend runs on bond lists)")
    if d.bond_filters or not d.bonds_between_blocks:
        why.append("bond filters")
    if any(c.type == "surface" or c.in_weighted_volume for c in case.precracks):
        why.append("pre-cracks from surface meshes or counted in the weighted volume")
    damage = case.material.damage if case.material is not None else None
    if damage is not None and isinstance(damage.critical_stretch, dict):
        why.append("a critical stretch that changes in time")
    if case.material is not None:
        reason = lattice_support(case.material.model, case.material.surface_correction)
        if reason is not None:
            why.append(reason)
    return why


def choose_storage(case: Case, body: Body | None) -> str:
    """``bonds`` or ``lattice`` for ``case`` on its ``body``: ``discretization.storage``, with
    ``auto`` taking the lattice where the case allows it and the body is a grid (``body`` None:
    the case's generated grid, before its points are made, as under MPI; a box, plate or
    rectangle is a grid by construction, a mesh is refused by ``lattice_refusals``).

    Raises
    ------
    CaseFileError
        Under ``storage: lattice``, naming what needs bond lists.
    """
    asked = case.discretization.storage
    if asked == "bonds":
        return "bonds"
    why = lattice_refusals(case)
    if not why and body is not None:
        try:
            grid_layout(body)
        except InputError as exc:
            why.append(str(exc))
    if not why:
        return "lattice"
    if asked == "auto":
        return "bonds"
    raise CaseFileError(
        case.name,
        "discretization.storage",
        asked,
        f"bonds or auto: lattice storage cannot run {'; '.join(why)}",
    )
