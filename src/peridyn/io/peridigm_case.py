"""A Peridigm deck (``peridyn.io.peridigm_deck.read_deck``) as a peridyn case (``deck_case``).

The case dict that ``deck_case`` returns is one that ``peridyn.io.case.validate_case`` accepts
(``peridyn convert DECK`` writes it as YAML), with each of Peridigm's conventions written out
as a case key: the PdQuickGrid cells as a box geometry, |xi| <= horizon families without
partial volumes, the material constants from the bulk and shear moduli, the step count
floor((final - initial) / dt), and Exodus output of the deck's variables, under Peridigm's
names, in ``<Output Filename>.e`` at the deck's output frequency (docs/peridigm.md).

Anything a deck asks that peridyn cannot do is a ``CaseFileError`` naming the deck parameter
(an unknown material model, a contact section, ...).
Several block groups become ``materials`` and ``blocks`` (docs/blocks.md).
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import Case, apply_override, load_case, validate_case
from peridyn.io.exodus import read_exodus
from peridyn.io.exodus_write import PERIDIGM_VARIABLES
from peridyn.io.mesh_text import read_text_mesh
from peridyn.io.peridigm_deck import is_peridigm_deck, read_deck
from peridyn.physics.expressions import SpaceTime
from peridyn.physics.materials.elastic import bulk_modulus, shear_modulus
from peridyn.physics.materials.registry import model_class

#: Peridigm's material models that peridyn runs: name -> peridyn model ("Linear LPS": LPS
#: linearised about the reference configuration, ``peridyn.physics.materials.linear_lps``;
#: "Linear Elastic": the older decks' name of "Elastic", Peridigm's
#: ``LinearElasticIsotropicMaterial``, the same force state ``computeInternalForceLinearElastic``).
MATERIALS = {
    "Elastic": "lps",
    "Elastic Bond Based": "pmb",
    "Linear LPS": "linear_lps",
    "Linear Elastic": "lps",
}
#: Words of Peridigm's material model names -> the feature peridyn lacks to run them.
LACKING = {
    "correspondence": "correspondence (non-ordinary state-based) models",
    "plastic": "plasticity",
    "thermal": "thermal models",
    "diffusion": "thermal models",
    "viscoelastic": "viscoelasticity",
    "viscoplastic": "viscoplasticity",
    "pals": "position-aware linear solid models",
}
#: Peridigm's partial-volume models, refused with ``PARTIAL_VOLUME_DIFFERS``.
PARTIAL_VOLUME = ("Elastic Partial Volume", "Linear LPS Partial Volume")
PARTIAL_VOLUME_DIFFERS = (
    "a model without Peridigm's partial volumes (there a bond's volumes are the parts of the "
    "two mesh elements inside each other's horizon spheres, one for each direction of the bond; "
    "peridyn's are the part of a cube of the point's volume, centred on it, inside the sphere)"
)
#: Peridigm's influence functions that peridyn has: name -> peridyn name.
INFLUENCE = {"One": "constant"}
#: Top-level deck sections read (others are refused by name).
SECTIONS = {
    "Verbose",
    "Discretization",
    "Materials",
    "Blocks",
    "Boundary Conditions",
    "Solver",
    "Output",
    "Compute Class Parameters",
    "Damage Models",
    "Contact",
}
#: Material parameters that change how Peridigm computes, not what: its tangent by automatic
#: differentiation or by finite differences gives the same equilibrium.
IGNORED_MATERIAL = {"Apply Automatic Differentiation Jacobian"}
#: Initial-condition kinds of the deck's boundary conditions.
INITIAL = {"Initial Displacement": "displacement", "Initial Velocity": "velocity"}
#: Boundary-condition kinds of the deck's boundary conditions.
BOUNDARY = {"Prescribed Displacement": "displacement", "Body Force": "body_force"}


class _Deck:
    """Access to a deck's parameters that names the parameter in every error."""

    def __init__(self, params: dict, source: str):
        self.params, self.source = params, source

    def error(self, key: str, value, expected: str, has_value: bool = True) -> CaseFileError:
        return CaseFileError(self.source, key, value, expected, has_value=has_value)

    def get(self, key: str, kind=None, default=...):
        """The value at the dotted path ``key`` (names may hold spaces, not dots)."""
        node = self.params
        for part in key.split("."):
            if not isinstance(node, dict) or part not in node:
                if default is not ...:
                    return default
                raise self.error(key, None, "a parameter that the deck must give", has_value=False)
            node = node[part]
        if kind is float and isinstance(node, int) and not isinstance(node, bool):
            node = float(node)
        if kind is not None and (not isinstance(node, kind) or (kind is not bool and isinstance(node, bool))):
            raise self.error(key, node, f"a {getattr(kind, '__name__', kind)}")
        if kind is float and not math.isfinite(node):
            raise self.error(key, node, "a finite number")
        return node


def deck_case(params: dict, name: str, source: str = "<deck>", deck_dir=".") -> dict:
    """The peridyn case (a dict for ``validate_case``) of a deck's parameters.

    Parameters
    ----------
    params : dict
        The deck, as ``read_deck`` gives it.
    name : str
        The case name (``peridyn convert`` and ``peridyn run`` use the deck's file stem).
    source : str
        The deck's path, for error messages.
    deck_dir : path
        The folder that the deck's mesh and node-set files are relative to; the case refers to
        the mesh by its absolute path (``relative_mesh`` makes it relative to a case file's
        folder).

    Raises
    ------
    CaseFileError
        Naming the deck parameter that peridyn cannot run or that is missing.
    """
    deck = _Deck(params, source)
    deck_dir = Path(deck_dir)
    for key in params:
        if key not in SECTIONS and not key.startswith("Output") and not re.fullmatch(r"Solver\d+", key):
            raise deck.error(key, None, f"one of the sections peridyn reads: {sorted(SECTIONS)}", False)
    for group in deck.get("Blocks", dict):  # the material models first: what peridyn lacks
        _material(deck, deck.get(f"Blocks.{group}.Material", str))
    groups = _with_default(deck, _groups(deck), deck_dir)
    horizon = max(g.horizon for g in groups)
    if len(groups) == 1:  # materials and solver first: their refusals before a missing mesh's
        (group,) = groups
        materials = {"material": _material(deck, group.material) | _damage(deck, group.damage_key)}
    else:
        if deck.get("Discretization.Type", str) == "PdQuickGrid":
            raise deck.error(
                "Blocks", [g.name for g in groups], "one block group on a PdQuickGrid (its one block)"
            )
        materials = dict(zip(("materials", "blocks"), _block_materials(deck, groups, horizon), strict=True))
    solver = _solvers(deck)
    planes = {_plane(deck, g.material) for g in groups}
    if len(planes) > 1:
        raise deck.error("Materials", sorted(g.material for g in groups), "materials of one dimension")
    (plane,) = planes
    if plane is not None and deck.get("Discretization.Type", str) == "PdQuickGrid":
        raise deck.error("Discretization.Type", "PdQuickGrid", "a mesh for a 2D material (a 3D grid)")
    geometry, discretization, grid = _discretization(deck, deck_dir, horizon)
    if plane is not None:
        geometry |= {"dimension": 2, "plane": plane[0], "thickness": plane[1]}
    case = {
        "name": name,
        "description": f"Peridigm deck {Path(source).name}, translated by peridyn",
        "geometry": geometry,
        "discretization": discretization,
        **materials,
        "solver": solver,
    }
    first_id = 0 if older_form(deck) or _lists_node_zero(deck) else 1
    sets, bcs, ics = _conditions(deck, deck_dir, grid, geometry["type"] == "exodus", first_id)
    if sets:
        case["node_sets"] = sets
    if bcs:
        case["boundary_conditions"] = bcs
    if ics:
        case["initial_conditions"] = ics
    cracks = _initial_damage(deck, groups, deck_dir)
    if cracks:
        case["precracks"] = cracks
    if "Contact" in params:
        case["contact"] = _contact(deck, groups, case.get("material") or case["materials"])
    model = (case.get("material") or next(iter(case["materials"].values())))["model"]
    if solver["type"] == "explicit" and model == "lps" and plane is None:
        solver["arithmetic"] = "peridigm"  # Peridigm's order of operations (docs/peridigm.md)
    case["output"] = _output(deck, model, _compute_classes(deck))
    for exodus in [case["output"].get("exodus"), *case["output"].get("exodus_more", [])]:
        if exodus is not None:  # Peridigm's numbering of a grid; three components in 2D
            exodus["point_order"] = "grid" if grid is not None else "peridyn"
            exodus["three_d"] = plane is not None
    return case


#: Peridigm's compute classes of a variable over a set: class -> the parameter naming the set.
COMPUTE_CLASSES = {"Block_Data": "Block", "Node_Set_Data": "Node Set"}
#: Their calculation types: deck name -> ``SetSum.calculation``.
CALCULATIONS = {"Sum": "sum", "Maximum": "maximum", "Minimum": "minimum"}


def _compute_classes(deck: _Deck) -> dict:
    """Output label -> ``{variable, set, calculation}`` of each "Block_Data" or "Node_Set_Data"
    of ``Compute Class Parameters``: a variable's sum, maximum or minimum over a block or a
    node set."""
    out = {}
    for name in deck.get("Compute Class Parameters", dict, {}):
        where = f"Compute Class Parameters.{name}"
        kind = deck.get(f"{where}.Compute Class", str)
        if kind not in COMPUTE_CLASSES:
            raise deck.error(f"{where}.Compute Class", kind, f"one of {sorted(COMPUTE_CLASSES)}")
        calculation = deck.get(f"{where}.Calculation Type", str)
        if calculation not in CALCULATIONS:
            raise deck.error(f"{where}.Calculation Type", calculation, f"one of {sorted(CALCULATIONS)}")
        variable = deck.get(f"{where}.Variable", str)
        if variable not in PERIDIGM_VARIABLES:
            raise deck.error(f"{where}.Variable", variable, f"one of {sorted(PERIDIGM_VARIABLES)}")
        out[deck.get(f"{where}.Output Label", str)] = {
            "variable": variable,
            "set": deck.get(f"{where}.{COMPUTE_CLASSES[kind]}", str),
            "calculation": CALCULATIONS[calculation],
        }
    return out


@dataclass(frozen=True)
class _Group:
    """One block group of the deck's ``Blocks``: its mesh blocks, material, horizon (m) and the
    deck key of its damage model."""

    name: str
    block_names: tuple[str, ...]
    material: str
    horizon: float
    damage_key: str


def older_form(deck: _Deck) -> bool:
    """True for Peridigm's older deck form: one horizon under ``Discretization`` (not per
    block), and node sets as 0-based node ids (docs/peridigm.md)."""
    return "Horizon" in deck.get("Discretization", dict)


def _groups(deck: _Deck) -> list[_Group]:
    """The block groups of ``Blocks``, in deck order; in the older form (``older_form``) each
    takes ``Discretization.Horizon``."""
    groups = []
    shared = older_form(deck)
    for name in deck.get("Blocks", dict):
        where = f"Blocks.{name}"
        for key in deck.get(where, dict):
            if key not in ("Block Names", "Material", "Horizon", "Damage Model"):
                raise deck.error(
                    f"{where}.{key}", None, "Block Names, Material, Horizon and Damage Model only", False
                )
        if shared and "Horizon" in deck.get(where, dict):
            raise deck.error(
                f"{where}.Horizon", deck.get(f"{where}.Horizon"), "no block horizon: Discretization.Horizon"
            )
        key = "Discretization.Horizon" if shared else f"{where}.Horizon"
        horizon = _horizon(deck, key)
        if not horizon > 0:
            raise deck.error(key, horizon, "a positive horizon (m)")
        blocks = tuple(deck.get(f"{where}.Block Names", str).split())
        if not blocks:
            raise deck.error(f"{where}.Block Names", "", "the names of the group's blocks")
        groups.append(
            _Group(name, blocks, deck.get(f"{where}.Material", str), horizon, f"{where}.Damage Model")
        )
    if not groups:
        raise deck.error("Blocks", {}, "at least one block group")
    return groups


def _horizon(deck: _Deck, key: str) -> float:
    """A horizon (m): a number, or a string holding one (Peridigm reads both)."""
    value = deck.get(key)
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            raise deck.error(
                key, value, "a number (m): horizons varying in space are not supported"
            ) from None
    return deck.get(key, float)


def _with_default(deck: _Deck, groups: list[_Group], deck_dir: Path) -> list[_Group]:
    """``groups`` with the block name ``default`` replaced by the mesh's blocks that no group
    names (Peridigm's default block); a single group keeps it (it takes every block)."""
    if len(groups) < 2 or not any("default" in g.block_names for g in groups):
        return groups
    named = {b for g in groups for b in g.block_names if b != "default"}
    rest = tuple(b for b in _mesh_blocks(deck, deck_dir) if b not in named)
    return [
        replace(g, block_names=tuple(b for b in g.block_names if b != "default") + rest)
        if "default" in g.block_names
        else g
        for g in groups
    ]


def _mesh_blocks(deck: _Deck, deck_dir: Path) -> list[str]:
    """Names of the blocks of the deck's mesh (an Exodus mesh's, ``block_<id>`` of a text mesh)."""
    kind = deck.get("Discretization.Type", str)
    mesh = deck_dir / deck.get("Discretization.Input Mesh File", str, "")
    if kind not in ("Exodus", "Text File") or not _is_file(mesh):
        raise deck.error("Blocks", "default", "a mesh whose blocks the default block takes")
    if kind == "Exodus":
        return [b.name for b in read_exodus(mesh).blocks]
    return [f"block_{i}" for i in np.unique(read_text_mesh(mesh)[1])]


def _block_materials(deck: _Deck, groups: list[_Group], horizon: float) -> tuple[dict, dict]:
    """``materials`` and ``blocks`` of a deck of several block groups (docs/blocks.md): a block
    per mesh block named in ``Block Names`` (its points are the mesh's node set of that name,
    e.g. ``block_2`` of a text mesh), made of its group's material with its group's damage
    model, with the group's horizon when the groups' horizons differ (``horizon`` is the
    largest: the discretisation's)."""
    materials, blocks, first = {}, {}, None
    for group in groups:
        where = f"Blocks.{group.name}"
        material = _material(deck, group.material) | _damage(deck, group.damage_key)
        key = (material["model"], material.get("surface_correction", "none"))
        if first is None:
            first = (key, group.material)
        elif key != first[0]:
            raise deck.error(
                f"Materials.{group.material}.Material Model",
                deck.get(f"Materials.{group.material}.Material Model", str),
                f"the model and shear correction of Materials.{first[1]} (the blocks of a body share them)",
            )
        damage = deck.get(group.damage_key, str, None)
        name = group.material if damage is None else f"{group.material} with {damage}"
        materials[name] = material
        for block in group.block_names:
            if block in blocks:
                raise deck.error(f"{where}.Block Names", block, "a block in one group only")
            blocks[block] = {"set": block, "material": name}
            if any(g.horizon != horizon for g in groups):
                blocks[block]["horizon_m"] = group.horizon
    return materials, blocks


#: The most points of a PdQuickGrid along one axis (a C int's range).
MAX_GRID_POINTS = 2**31 - 1


def _is_file(path: Path) -> bool:
    """``path.is_file()``, False for a name the system refuses (too long, a NUL in it)."""
    try:
        return path.is_file()
    except (OSError, ValueError):
        return False


def _discretization(deck: _Deck, deck_dir: Path, horizon: float) -> tuple[dict, dict, np.ndarray | None]:
    """Geometry and discretisation sections, and the PdQuickGrid's (nx, ny, nz) (None for a mesh)."""
    kind = deck.get("Discretization.Type", str)
    neighbourhood = deck.get("Discretization.NeighborhoodType", str, "")
    # Peridigm keeps a point without neighbours (it moves freely, touched by contact only)
    discretization = {
        "horizon_m": horizon,
        "partial_volumes": False,
        "points_without_bonds": "warn",
        **_bond_options(deck),
    }
    if kind == "PdQuickGrid":
        where = "Discretization.TensorProduct3DMeshGenerator"
        deck.get(where, dict)
        origin = [deck.get(f"{where}.{a} Origin", float) for a in "XYZ"]
        size = [deck.get(f"{where}.{a} Length", float) for a in "XYZ"]
        counts = [deck.get(f"{where}.Number Points {a}", int) for a in "XYZ"]
        for a, n in zip("XYZ", counts, strict=True):
            if not 1 <= n <= MAX_GRID_POINTS:
                raise deck.error(f"{where}.Number Points {a}", n, f"from 1 to {MAX_GRID_POINTS} points")
        spacing = [s / n for s, n in zip(size, counts, strict=True)]
        if neighbourhood and neighbourhood.lower() != "spherical":
            raise deck.error(
                "Discretization.NeighborhoodType", neighbourhood, "'Spherical', or none for boxes"
            )
        geometry = {"type": "box", "size": size, "origin": origin}
        discretization["spacing"] = spacing
        if not neighbourhood:  # PdQuickGrid's own families: round(horizon / spacing) cells
            discretization["neighbourhood"] = "box"
        return geometry, discretization, np.array(counts)
    if neighbourhood and neighbourhood.lower() != "spherical":
        raise deck.error("Discretization.NeighborhoodType", neighbourhood, "'Spherical' for a mesh")
    if kind not in ("Exodus", "Text File"):
        raise deck.error("Discretization.Type", kind, "one of 'PdQuickGrid', 'Exodus', 'Text File'")
    mesh = deck_dir / deck.get("Discretization.Input Mesh File", str)
    if not _is_file(mesh):
        raise deck.error("Discretization.Input Mesh File", str(mesh), "an existing mesh file")
    geometry = {"type": "exodus" if kind == "Exodus" else "mesh", "file": str(mesh.resolve())}
    return geometry, discretization, None


#: Discretization parameters read.
DISCRETIZATION = {
    "Type",
    "Input Mesh File",
    "NeighborhoodType",
    "TensorProduct3DMeshGenerator",
    "Horizon",
    "Bond Filters",
    "Omit Bonds Between Blocks",
}
#: A Rectangular_Plane bond filter's parameters: deck name (X, Y, Z of a vector) -> case key.
PLANE_FILTER = {
    "Lower_Left_Corner": "corner",
    "Normal": "normal",
    "Bottom_Unit_Vector": "bottom",
}


def _bond_options(deck: _Deck) -> dict:
    """``bond_filters`` of ``Discretization.Bond Filters`` (each "Rectangular_Plane" a
    ``finite_plane``) and ``bonds_between_blocks`` of ``Omit Bonds Between Blocks`` ("All":
    false; "None": true)."""
    for key in deck.get("Discretization", dict):
        if key not in DISCRETIZATION:
            if key == "Compute Element-Horizon Intersections":
                raise deck.error(f"Discretization.{key}", True, PARTIAL_VOLUME_DIFFERS)
            raise deck.error(
                f"Discretization.{key}", None, f"only the parameters {sorted(DISCRETIZATION)}", False
            )
    out = {}
    filters = []
    for name in deck.get("Discretization.Bond Filters", dict, {}):
        where = f"Discretization.Bond Filters.{name}"
        kind = deck.get(f"{where}.Type", str)
        if kind != "Rectangular_Plane":
            raise deck.error(f"{where}.Type", kind, "'Rectangular_Plane' (the bond filter peridyn has)")
        spec = {"type": "finite_plane"}
        for prefix, key in PLANE_FILTER.items():
            spec[key] = [deck.get(f"{where}.{prefix}_{a}", float) for a in "XYZ"]
        spec["bottom_length"] = deck.get(f"{where}.Bottom_Length", float)
        spec["side_length"] = deck.get(f"{where}.Side_Length", float)
        known = {f"{p}_{a}" for p in PLANE_FILTER for a in "XYZ"} | {"Type", "Bottom_Length", "Side_Length"}
        for key in deck.get(where, dict):
            if key not in known:
                raise deck.error(f"{where}.{key}", None, f"only the parameters {sorted(known)}", False)
        filters.append(spec)
    if filters:
        out["bond_filters"] = filters
    omit = deck.get("Discretization.Omit Bonds Between Blocks", str, "None")
    if omit not in ("All", "None"):
        raise deck.error("Discretization.Omit Bonds Between Blocks", omit, "'All' or 'None'")
    if omit == "All":
        if len(deck.get("Blocks", dict)) < 2:
            raise deck.error("Discretization.Omit Bonds Between Blocks", omit, "'None' with one block group")
        out["bonds_between_blocks"] = False
    return out


def _material(deck: _Deck, name: str) -> dict:
    where = f"Materials.{name}"
    deck.get(where, dict)
    model = deck.get(f"{where}.Material Model", str)
    if model in PARTIAL_VOLUME:
        raise deck.error(f"{where}.Material Model", model, PARTIAL_VOLUME_DIFFERS)
    if model == "Elastic Plastic" and deck.get(f"{where}.Disable Plasticity", bool, False):
        model = "Elastic"  # Peridigm's elastic-plastic model without plasticity: its elastic one
    elif model not in MATERIALS:
        lacking = next((f for k, f in LACKING.items() if k in model.lower()), "this material model")
        raise deck.error(
            f"{where}.Material Model", model, f"one of {sorted(MATERIALS)} (peridyn lacks {lacking})"
        )
    density = deck.get(f"{where}.Density", float)
    known = {"Material Model", "Density", "Apply Shear Correction Factor", *ELASTIC_CONSTANTS}
    known |= {"Influence Function", "Plane Stress", "Plane Strain", "Height"}
    known |= IGNORED_MATERIAL
    if deck.get(f"{where}.Material Model", str) == "Elastic Plastic":  # plasticity disabled
        known |= {"Disable Plasticity", "Yield Stress"}
    for key in deck.get(where, dict):
        if key not in known:
            raise deck.error(f"{where}.{key}", None, f"only the parameters {sorted(known)}", False)
    influence = deck.get(f"{where}.Influence Function", str, "One")
    if influence not in INFLUENCE:
        raise deck.error(f"{where}.Influence Function", influence, f"one of {sorted(INFLUENCE)}")
    plane = _plane(deck, name)
    bulk, E, nu = _elastic_constants(deck, where, MATERIALS[model] == "pmb")
    if MATERIALS[model] == "pmb":
        # c = 18 K / (pi delta^4) from K alone: peridyn's PMB has nu = 1/4, so K = E / 1.5; in
        # 2D Peridigm's c = 12 K / (pi h delta^3) is peridyn's 12 kappa / (pi t delta^3) of
        # the plane bulk modulus kappa = K (``PLANE_E``)
        return {"model": "pmb", "E": (PLANE_E[plane[0]] if plane else 1.5) * bulk, "density": density}
    if plane is not None:
        raise deck.error(
            f"{where}.Plane {plane[0].capitalize()}", True, "3D, or the Elastic Bond Based model in 2D"
        )
    material = {"model": MATERIALS[model], "E": E, "nu": nu, "density": density}
    if deck.get(f"{where}.Apply Shear Correction Factor", bool, False):
        if model != "Elastic":
            raise deck.error(
                f"{where}.Apply Shear Correction Factor", True, "false for a Linear LPS material"
            )
        material["surface_correction"] = "shear-factor"
    return material


#: Elastic constants a deck may give, two of them (one, the bulk modulus, for bond-based).
ELASTIC_CONSTANTS = ("Bulk Modulus", "Shear Modulus", "Young's Modulus", "Poisson's Ratio")


def _elastic_constants(deck: _Deck, where: str, bond_based: bool) -> tuple[float, float, float]:
    """(K, E, nu) of the material at ``where`` from the two constants it gives (Pa, Pa, -):
    the bulk and shear moduli, or Young's modulus and Poisson's ratio, as Peridigm reads them
    (a bond-based material: the bulk modulus alone, or E and nu; its E and nu are then unused)."""
    given = {k: deck.get(f"{where}.{k}", float) for k in ELASTIC_CONSTANTS if k in deck.get(where, dict)}
    if bond_based and set(given) == {"Bulk Modulus"}:
        return given["Bulk Modulus"], math.nan, math.nan
    if set(given) == {"Bulk Modulus", "Shear Modulus"}:
        bulk, shear = given["Bulk Modulus"], given["Shear Modulus"]
        # E and nu of the bulk and shear moduli (LPS turns them back into K and mu)
        E = 9.0 * bulk * shear / (3.0 * bulk + shear)
        return bulk, *exact_moduli_pair(
            E, (3.0 * bulk - 2.0 * shear) / (2.0 * (3.0 * bulk + shear)), bulk, shear
        )
    if set(given) == {"Young's Modulus", "Poisson's Ratio"}:
        E, nu = given["Young's Modulus"], given["Poisson's Ratio"]
        return E / (3.0 * (1.0 - 2.0 * nu)), E, nu
    raise deck.error(
        where, sorted(given), "Bulk Modulus and Shear Modulus, or Young's Modulus and Poisson's Ratio"
    )


#: Floats on either side of E and nu searched by ``exact_moduli_pair``.
INVERSE_ULPS = 4


def exact_moduli_pair(E: float, nu: float, bulk: float, shear: float) -> tuple[float, float]:
    """(E, nu) whose bulk and shear moduli, as peridyn's LPS forms them from E and nu
    (``physics.materials.elastic``), are ``bulk`` and ``shear`` to the last bit: the given pair,
    or the nearest such pair within ``INVERSE_ULPS`` floats of each (Peridigm's forces use its
    K and mu themselves; a modulus one bit off is a force one bit off). The given pair when
    none is found."""

    def moved(value: float, steps: int) -> float:
        for _ in range(abs(steps)):
            value = math.nextafter(value, math.copysign(math.inf, steps))
        return value

    steps = sorted(range(-INVERSE_ULPS, INVERSE_ULPS + 1), key=abs)
    for i, j in sorted(((i, j) for i in steps for j in steps), key=lambda ij: abs(ij[0]) + abs(ij[1])):
        e, n = moved(E, i), moved(nu, j)
        if not -1.0 < n < 0.5:  # no moduli there (a shear modulus far below the bulk's: nu near 0.5)
            continue
        if bulk_modulus(e, n) == bulk and shear_modulus(e, n) == shear:
            return e, n
    return E, nu


#: E / K of peridyn's 2D bond-based model whose plane bulk modulus is K: kappa = E / (2 (1 - nu))
#: with nu = 1/3 in plane stress, E / (2 (1 + nu) (1 - 2 nu)) with nu = 1/4 in plane strain.
PLANE_E = {"stress": 4.0 / 3.0, "strain": 1.25}


def _plane(deck: _Deck, name: str) -> tuple[str, float] | None:
    """("stress" or "strain", Height in m) of a 2D material (``Plane Stress`` or ``Plane
    Strain`` true, as Peridigm's ``ElasticBondBasedMaterial``), or None in 3D."""
    where = f"Materials.{name}"
    on = [p for p in ("stress", "strain") if deck.get(f"{where}.Plane {p.capitalize()}", bool, False)]
    if len(on) > 1:
        raise deck.error(f"{where}.Plane Strain", True, "one of Plane Stress and Plane Strain")
    if not on:
        if deck.get(f"{where}.Height", float, None) is not None:
            raise deck.error(
                f"{where}.Height", deck.get(f"{where}.Height"), "a height with Plane Stress/Strain"
            )
        return None
    height = deck.get(f"{where}.Height", float)
    if not height > 0:
        raise deck.error(f"{where}.Height", height, "a positive height (m): the thickness")
    return on[0], height


def _damage(deck: _Deck, key: str) -> dict:
    """``{"damage": {"critical_stretch": s_c}}`` of the block's "Critical Stretch" damage model
    (a bond breaks once (|y| - |xi|) / |xi| exceeds s_c, as in peridyn), or of its "Time
    Dependent Critical Stretch" (s_c a time function, ``_stretch_in_time``), or {} without one."""
    name = deck.get(key, str, None)
    if name is None:
        return {}
    where = f"Damage Models.{name}"
    deck.get(where, dict)
    model = deck.get(f"{where}.Damage Model", str)
    if model == "Initial Damage":
        return {}  # its bonds are broken by the case's pre-cracks (``_initial_damage``)
    if model not in ("Critical Stretch", "Time Dependent Critical Stretch"):
        raise deck.error(
            f"{where}.Damage Model", model, "'Critical Stretch' or 'Time Dependent Critical Stretch'"
        )
    for param in deck.get(where, dict):
        if param not in ("Damage Model", model):
            raise deck.error(f"{where}.{param}", None, f"Damage Model and {model} only", False)
    if model == "Time Dependent Critical Stretch":
        return {"damage": {"critical_stretch": _stretch_in_time(deck, f"{where}.{model}")}}
    stretch = deck.get(f"{where}.Critical Stretch", float)
    if not stretch > 0:
        raise deck.error(f"{where}.Critical Stretch", stretch, "a positive stretch")
    return {"damage": {"critical_stretch": stretch}}


#: Peridigm's time-dependent critical stretch of two values: "if(t <= T){ value = A; } else{
#: value = B; }" (its expression parser's form), with ``<=`` or ``<``.
STEP_IN_TIME = re.compile(
    r"^\s*if\s*\(\s*t\s*(<=|<)\s*(\S+?)\s*\)\s*\\?\{\s*value\s*=\s*(\S+?)\s*;\s*\\?\}"
    r"\s*else\s*\\?\{\s*value\s*=\s*(\S+?)\s*;\s*\\?\}\s*$"
)


def _stretch_in_time(deck: _Deck, key: str) -> dict:
    """A critical stretch in time as a peridyn time function: a number, or the two-valued
    form of ``STEP_IN_TIME`` as a ``step``."""
    text = deck.get(key, str)
    match = STEP_IN_TIME.match(text)
    try:
        if match is None:
            return {"type": "constant", "value": float(text)}
        operator, time, before, after = match.groups()
        step = {"time": float(time), "before": float(before), "after": float(after)}
    except ValueError:
        match = None
    if match is None:
        raise deck.error(key, text.strip(), "a number, or 'if(t <= T){ value = A; } else{ value = B; }'")
    if not (step["before"] > 0 and step["after"] > 0):
        raise deck.error(key, text.strip(), "positive stretches")
    if operator == "<":  # t < T is t <= the float below T
        step["time"] = math.nextafter(step["time"], -math.inf)
    return {"type": "step", **step}


def _solvers(deck: _Deck) -> dict:
    """The deck's ``Solver``, or its sequence ``Solver1``, ``Solver2``: a quasi-static solver
    and then, from its last load step on, a Verlet one with a ``Fixed dt`` (``solver.then``),
    the sequence that peridyn runs."""
    sequence = sorted((k for k in deck.params if re.fullmatch(r"Solver\d+", k)), key=lambda k: int(k[6:]))
    if not sequence:
        return _solver(deck)
    if "Solver" in deck.params:
        raise deck.error("Solver", None, f"one Solver list or the sequence {sequence}, not both", False)
    expected = "two solvers: a QuasiStatic or NOXQuasiStatic one, then a Verlet one"
    if len(sequence) != 2:
        raise deck.error(sequence[-1], None, expected, False)
    first, second = sequence
    solver = _solver(deck, first)
    if solver["type"] != "newton":
        raise deck.error(first, None, expected, False)
    kinds = [k for k, v in deck.get(second, dict).items() if isinstance(v, dict)]
    if kinds != ["Verlet"]:
        raise deck.error(second, kinds, expected)
    initial = deck.get(f"{second}.Initial Time", float, 0.0)
    if initial != solver["time"]:
        raise deck.error(f"{second}.Initial Time", initial, f"{first}'s Final Time, {solver['time']:g} s")
    stage = _verlet(deck, deck.get(f"{second}.Final Time", float), second, initial)
    if "dt" not in stage:
        raise deck.error(f"{second}.Verlet.Fixed dt", None, "a Fixed dt (after a quasi-static solver)", False)
    solver["then"] = {"dt": stage["dt"], "steps": stage["steps"], "prescribed_velocity": "difference"}
    return solver


def _solver(deck: _Deck, name: str = "Solver") -> dict:
    """The solver of the deck's solver list ``name``, from t = 0."""
    if "Time Steps" in deck.get(f"{name}.QuasiStatic", dict, {}):
        raise deck.error(
            f"{name}.QuasiStatic.Time Steps",
            deck.get(f"{name}.QuasiStatic.Time Steps"),
            "Final Time and Number of Load Steps (peridyn's load steps are uniform in time)",
        )
    initial = deck.get(f"{name}.Initial Time", float, 0.0)
    if initial != 0.0:
        raise deck.error(f"{name}.Initial Time", initial, "0 (runs start at t = 0 s)")
    final = deck.get(f"{name}.Final Time", float)
    solver = deck.get(name, dict)
    kinds = [k for k in solver if isinstance(solver[k], dict)]
    if kinds in (["QuasiStatic"], ["NOXQuasiStatic"]):
        return _quasi_static(deck, final, kinds[0], name)
    if kinds == ["Implicit"]:
        return _implicit(deck, final)
    if kinds != ["Verlet"]:
        raise deck.error(
            name,
            kinds,
            "one 'Verlet', 'QuasiStatic', 'NOXQuasiStatic' or 'Implicit' solver list",
        )
    return _verlet(deck, final, name)


#: Implicit parameters read.
IMPLICIT = {"Fixed dt", "Beta", "Gamma", "Absolute Tolerance", "Maximum Solver Iterations"}


def _implicit(deck: _Deck, final: float) -> dict:
    """Peridigm's Implicit solver (Newmark with Newton) as ``newmark``: average acceleration
    (Beta 1/4, Gamma 1/2, the one peridyn has), ``Fixed dt``, floor(final / dt) steps, Newton
    converged on the residual's norm (``Absolute Tolerance``, N), starting from a = 0 as
    Peridigm's does."""
    where = "Solver.Implicit"
    for key in deck.get(where, dict):
        if key not in IMPLICIT:
            raise deck.error(f"{where}.{key}", None, f"only the parameters {sorted(IMPLICIT)}", False)
    for key, value in (("Beta", 0.25), ("Gamma", 0.5)):
        given = deck.get(f"{where}.{key}", float, value)
        if given != value:
            raise deck.error(f"{where}.{key}", given, f"{value} (average acceleration, peridyn's Newmark)")
    dt = deck.get(f"{where}.Fixed dt", float)
    if not dt > 0:
        raise deck.error(f"{where}.Fixed dt", dt, "a positive time step (s)")
    steps = math.floor(final / dt)
    if steps < 1:
        raise deck.error("Solver.Final Time", final, f"at least one step of {dt:g} s")
    tolerance = deck.get(f"{where}.Absolute Tolerance", float)
    if not tolerance > 0:
        raise deck.error(f"{where}.Absolute Tolerance", tolerance, "a positive tolerance (N)")
    iterations = deck.get(f"{where}.Maximum Solver Iterations", int, 10)
    if iterations < 1:
        raise deck.error(f"{where}.Maximum Solver Iterations", iterations, "at least 1")
    return {
        "type": "newmark",
        "dt": dt,
        "steps": steps,
        "absolute_tolerance": tolerance,
        "newton_iterations": iterations,
        "initial_acceleration": "zero",
    }


def _verlet(deck: _Deck, final: float, name: str = "Solver", initial: float = 0.0) -> dict:
    """Peridigm's Verlet solver (the list ``name``, from the time ``initial``, s): its step is
    ``Fixed dt``, or its bond-based stable step (``peridyn.setup.peridigm_step``), times
    ``Safety Factor`` (default 1); floor((final - initial) / dt) steps; the velocity of
    prescribed points as Peridigm reports it."""
    where = f"{name}.Verlet"
    for key in deck.get(where, dict):
        if key not in ("Fixed dt", "Safety Factor"):
            raise deck.error(f"{where}.{key}", None, "only the parameters Fixed dt and Safety Factor", False)
    safety = deck.get(f"{where}.Safety Factor", float, 1.0)
    if not 0 < safety <= 1:
        raise deck.error(
            f"{where}.Safety Factor", safety, "a factor in (0, 1] (above 1 the step is unstable)"
        )
    fixed = deck.get(f"{where}.Fixed dt", float, None)
    if fixed is None:  # Peridigm's stable step times the safety factor, found once the bonds are
        if not final > 0:
            raise deck.error(f"{name}.Final Time", final, "a positive time (s)")
        return {
            "type": "explicit",
            "time": final,
            "safety": safety,
            "step_rule": "peridigm",
            "prescribed_velocity": "difference",
        }
    if not fixed > 0:
        raise deck.error(f"{where}.Fixed dt", fixed, "a positive time step (s)")
    dt = fixed * safety  # Peridigm multiplies a fixed step by the factor too
    steps = math.floor((final - initial) / dt)  # Peridigm's step count
    if steps < 1:
        raise deck.error(f"{name}.Final Time", final, f"at least one step of {dt:g} s after the initial time")
    return {"type": "explicit", "dt": dt, "steps": steps, "prescribed_velocity": "difference"}


#: NOXQuasiStatic's parameters of how Trilinos' NOX finds the equilibrium (its nonlinear solver,
#: line search, preconditioner, Jacobian operator), not of the equilibrium found: not read.
NOX_IGNORED = {"Nonlinear Solver", "Max Age Of Prec", "Direction", "Line Search"}


def _quasi_static(deck: _Deck, final: float, kind: str = "QuasiStatic", name: str = "Solver") -> dict:
    """Peridigm's QuasiStatic (or NOXQuasiStatic) solver (of the list ``name``) as Newton load
    steps to the final time, converged on the absolute residual (N), velocities the change of
    u over a load step's time."""
    where = f"{name}.{kind}"
    nox = kind == "NOXQuasiStatic"
    iterations_key = "Max Solver Iterations" if nox else "Maximum Solver Iterations"
    known = {"Number of Load Steps", "Absolute Tolerance", iterations_key} | (NOX_IGNORED if nox else set())
    for key in deck.get(where, dict):
        if key not in known:
            raise deck.error(f"{where}.{key}", None, f"only the parameters {sorted(known)}", False)
    if not final > 0:
        raise deck.error(f"{name}.Final Time", final, "a positive time (s)")
    steps = deck.get(f"{where}.Number of Load Steps", int)
    iterations = deck.get(f"{where}.{iterations_key}", int, 10)
    tolerance = deck.get(f"{where}.Absolute Tolerance", float)
    for key, value in (("Number of Load Steps", steps), (iterations_key, iterations)):
        if value < 1:
            raise deck.error(f"{where}.{key}", value, "at least 1")
    if not tolerance > 0:
        raise deck.error(f"{where}.Absolute Tolerance", tolerance, "a positive tolerance")
    return {
        "type": "newton",
        "time": final,
        "load_steps": steps,
        "absolute_tolerance": tolerance,
        "newton_iterations": iterations,
    }


def _conditions(deck: _Deck, deck_dir: Path, grid, mesh_sets: bool, first_id: int) -> tuple[dict, list, list]:
    """Node sets, boundary conditions and initial conditions of ``Boundary Conditions``; node
    ids count from ``first_id`` (1, or 0 in the older deck form)."""
    section = deck.get("Boundary Conditions", dict, {})
    definitions = {k: v for k, v in section.items() if not isinstance(v, dict)}
    sets, bcs, ics = {}, [], []
    for name, spec in section.items():
        if not isinstance(spec, dict):
            continue
        where = f"Boundary Conditions.{name}"
        kind = deck.get(f"{where}.Type", str)
        set_name = deck.get(f"{where}.Node Set", str)
        if set_name in definitions:
            if set_name not in sets:
                sets[set_name] = {
                    "type": "points",
                    "indices": _set_indices(
                        deck, f"Boundary Conditions.{set_name}", deck_dir, grid, first_id
                    ),
                }
        elif not mesh_sets:
            raise deck.error(f"{where}.Node Set", set_name, f"a node set of the deck: {sorted(definitions)}")
        axis = deck.get(f"{where}.Coordinate", str)
        if axis not in ("x", "y", "z"):
            raise deck.error(f"{where}.Coordinate", axis, "x, y or z")
        value = _value(deck, f"{where}.Value")
        if kind in INITIAL:
            ics.append({"set": set_name, "kind": INITIAL[kind], "components": axis, "value": value})
        elif kind in BOUNDARY:
            bc = {"set": set_name, "kind": BOUNDARY[kind], "components": axis, "value": value}
            if kind == "Body Force":  # on a prescribed component, the prescribed motion wins
                bc["where_prescribed"] = "yield"
            bcs.append(bc)
        else:
            raise deck.error(f"{where}.Type", kind, f"one of {sorted(INITIAL) + sorted(BOUNDARY)}")
    return sets, bcs, ics


def _initial_damage(deck: _Deck, groups: list[_Group], deck_dir: Path) -> list[dict]:
    """Pre-cracks of the blocks' "Initial Damage" models: each "Exodus Mesh" bond filter a
    ``surface`` (its triangles; bonds crossing them start broken, Peridigm's bond damage 1,
    still counting in the weighted volumes, which Peridigm computes before)."""
    cracks = []
    for group in groups:
        name = deck.get(group.damage_key, str, None)
        where = f"Damage Models.{name}"
        if name is None or deck.get(f"{where}.Damage Model", str) != "Initial Damage":
            continue
        if len(groups) > 1:
            raise deck.error(
                f"{where}.Damage Model", "Initial Damage", "one block group (the pre-cracks cut every block)"
            )
        for key in deck.get(where, dict):
            if key not in ("Damage Model", "Bond Filters"):
                raise deck.error(f"{where}.{key}", None, "Damage Model and Bond Filters only", False)
        for label in deck.get(f"{where}.Bond Filters", dict):
            at = f"{where}.Bond Filters.{label}"
            kind = deck.get(f"{at}.Type", str)
            if kind != "Exodus Mesh":
                raise deck.error(f"{at}.Type", kind, "'Exodus Mesh' (a surface of triangles)")
            path = deck_dir / deck.get(f"{at}.File Name", str)
            if not _is_file(path):
                raise deck.error(f"{at}.File Name", str(path), "an existing Exodus file")
            cracks.append({"type": "surface", "file": str(path.resolve()), "in_weighted_volume": True})
    return cracks


def _contact(deck: _Deck, groups: list[_Group], materials: dict) -> dict:
    """``contact`` of the deck's ``Contact`` section: one "Short Range Force" model between
    every pair of blocks (``General Contact``, or interactions naming every pair), its
    ``Contact Radius`` (m) and ``Spring Constant`` (Pa): Peridigm's short-range constant is
    18 K_s / (pi delta^4), the PMB micromodulus of the bulk modulus K_s, so peridyn's
    ``stiffness_factor`` (a multiple of the micromodulus of the material, K = E / 1.5) is
    1.5 K_s / E. ``Search Radius`` and ``Search Frequency`` say how Peridigm finds the pairs
    (peridyn's list is kept complete), not which; they are not read."""
    where = "Contact"
    for key in deck.get(where, dict):
        if key not in ("Verbose", "Search Radius", "Search Frequency", "Models", "Interactions"):
            raise deck.error(
                f"{where}.{key}", None, "Search Radius, Search Frequency, Models, Interactions", False
            )
    models = deck.get(f"{where}.Models", dict)
    if len(models) != 1:
        raise deck.error(f"{where}.Models", sorted(models), "one contact model")
    (name,) = models
    at = f"{where}.Models.{name}"
    kind = deck.get(f"{at}.Contact Model", str)
    if kind != "Short Range Force":
        raise deck.error(f"{at}.Contact Model", kind, "'Short Range Force'")
    for key in deck.get(at, dict):
        if key not in ("Contact Model", "Contact Radius", "Spring Constant"):
            raise deck.error(f"{at}.{key}", None, "Contact Model, Contact Radius, Spring Constant", False)
    radius, spring = deck.get(f"{at}.Contact Radius", float), deck.get(f"{at}.Spring Constant", float)
    for key, value in (("Contact Radius", radius), ("Spring Constant", spring)):
        if not value > 0:
            raise deck.error(f"{at}.{key}", value, "a positive value")
    blocks = sorted({b for g in groups for b in g.block_names})
    needed = {frozenset((a, b)) for a in blocks for b in blocks}
    for label in deck.get(f"{where}.Interactions", dict):
        at = f"{where}.Interactions.{label}"
        if deck.get(f"{at}.Contact Model", str) != name:
            raise deck.error(f"{at}.Contact Model", deck.get(f"{at}.Contact Model"), repr(name))
        if label == "General Contact":
            needed = set()
        else:
            needed.discard(
                frozenset((deck.get(f"{at}.First Block", str), deck.get(f"{at}.Second Block", str)))
            )
    if needed:
        pairs = sorted(" with ".join(sorted(p)) if len(p) > 1 else f"{min(p)} with itself" for p in needed)
        raise deck.error(
            f"{where}.Interactions", pairs, "contact between every pair of blocks (General Contact)"
        )
    moduli = {m["E"] for m in ([materials] if "model" in materials else materials.values())}
    if len(moduli) > 1:
        raise deck.error(
            where, sorted(moduli), "materials of one Young's modulus (the contact constant's reference)"
        )
    # Peridigm's contact reaches beyond the horizon where the radius does
    return {"radius_m": radius, "stiffness_factor": 1.5 * spring / moduli.pop(), "beyond_horizon": "allow"}


def _lists_node_zero(deck: _Deck) -> bool:
    """True when an inline node set of ``Boundary Conditions`` lists node 0: the deck's ids
    then count from 0 (as the older form's do)."""
    section = deck.get("Boundary Conditions", dict, {})
    for value in section.values():
        words = value.split() if isinstance(value, str) else []
        if words and all(w.isdigit() for w in words) and min(int(w) for w in words) == 0:
            return True
    return False


def _value(deck: _Deck, key: str):
    """A condition's value: a number, or an expression in x, y, z and t (checked now); ``^``
    is a power, as in Peridigm's expression parser."""
    text = deck.get(key, str).replace("^", "**")
    try:
        return float(text)
    except ValueError:
        pass
    try:
        SpaceTime(text)
    except InputError as exc:
        raise deck.error(key, text, f"a number or an expression in x, y, z, t ({exc})") from None
    return {"type": "expression", "text": text}


def _set_indices(deck: _Deck, key: str, deck_dir: Path, grid, first_id: int) -> list[int]:
    """0-based peridyn point indices of a node set given as ids counted from ``first_id``
    (1, or 0 in the older deck form), inline or in a file."""
    counted = f"{first_id}-based node ids"
    text = deck.get(key, str)
    path = deck_dir / text
    if not text.split() or not text.split()[0].isdigit() or _is_file(path):
        if not _is_file(path):
            raise deck.error(key, text, f"{counted}, or a file of them")
        text = path.read_text(encoding="utf-8")
    try:
        ids = np.array([int(t) for t in text.split()], dtype=np.int64)
    except (ValueError, OverflowError):  # not whole numbers, or beyond 64 bits
        raise deck.error(key, text[:80], f"whitespace-separated {counted}") from None
    if len(ids) == 0 or ids.min() < first_id:
        raise deck.error(key, text[:80], f"{counted} (at least one)")
    index = ids - first_id
    if grid is not None:
        nx, ny, nz = (int(n) for n in grid)
        if index.max() >= nx * ny * nz:
            last = nx * ny * nz - 1 + first_id
            raise deck.error(key, int(ids.max()), f"node ids up to {last} (the grid's points)")
        # PdQuickGrid numbers x fastest, peridyn's box z fastest
        i, j, k = index % nx, (index // nx) % ny, index // (nx * ny)
        index = (i * ny + j) * nz + k
    return sorted(int(p) for p in index)


#: Output list parameters read (``Output Format`` and ``Parallel Write`` change how, not what).
OUTPUT = {"Output File Type", "Output Format", "Output Filename", "Output Frequency", "Parallel Write"}
#: Output list parameters of the steps written: deck name -> ``ExodusOutput`` key.
OUTPUT_STEPS = {"Initial Output Step": "first_step", "Final Output Step": "last_step"}


def _output(deck: _Deck, model: str, sums: dict) -> dict:
    """The output section: plots and VTU off, an Exodus file of each output list (``Output``,
    ``Output1``, ``Output2``, ...: the first as ``exodus``, the others ``exodus_more``), each
    with its file, frequency, variables and compute classes."""
    outputs = [k for k in deck.params if k.startswith("Output")]
    out = {"plots": False, "vtu": False}
    files = [_exodus_file(deck, where, model, sums) for where in outputs]
    merged = []
    for where, exodus in zip(outputs, files, strict=True):  # lists of one file: one output
        same = next((m for m in merged if m["file"] == exodus["file"]), None)
        if same is None:
            merged.append(exodus)
            continue
        if same["every"] != exodus["every"]:
            raise deck.error(
                f"{where}.Output Frequency", exodus["every"], f"{same['every']}, as the file's other list"
            )
        for key, field in OUTPUT_STEPS.items():
            if same.get(field) != exodus.get(field):
                raise deck.error(
                    f"{where}.{key}", exodus.get(field), f"{same.get(field)}, as the file's other list"
                )
        same["variables"] += [v for v in exodus["variables"] if v not in same["variables"]]
        same.setdefault("sums", {}).update(exodus.get("sums", {}))
    if merged:
        out["exodus"] = merged[0]
    if len(merged) > 1:
        out["exodus_more"] = merged[1:]
    return out


def _exodus_file(deck: _Deck, where: str, model: str, sums: dict) -> dict:
    """``ExodusOutput`` of one output list: ``<Output Filename>.e``, or of global variables and
    compute classes only a history file, ``.h``, as Peridigm names them."""
    for key in deck.get(where, dict):
        if key not in OUTPUT and key not in OUTPUT_STEPS and key != "Output Variables":
            known = sorted(OUTPUT | set(OUTPUT_STEPS))
            raise deck.error(f"{where}.{key}", None, f"only the parameters {known}", False)
    fmt = deck.get(f"{where}.Output File Type", str, "ExodusII")
    if fmt != "ExodusII":
        raise deck.error(f"{where}.Output File Type", fmt, "ExodusII")
    names = [k for k, on in deck.get(f"{where}.Output Variables", dict).items() if on is True]
    asked_sums = {name: sums[name] for name in names if name in sums}
    names = [name for name in names if name not in sums]
    for name in names:
        if name not in PERIDIGM_VARIABLES:
            raise deck.error(f"{where}.Output Variables.{name}", True, f"one of {sorted(PERIDIGM_VARIABLES)}")
        if not model_class(model).state_based and name in ("Dilatation", "Weighted_Volume"):
            raise deck.error(f"{where}.Output Variables.{name}", True, "a state-based material's variable")
    every = deck.get(f"{where}.Output Frequency", int, 1)
    if every < 1:
        raise deck.error(f"{where}.Output Frequency", every, "at least 1 step")
    history = all(PERIDIGM_VARIABLES[n][0] == "global" for n in names)  # Peridigm's ".h" file
    suffix = ".h" if history else ".e"
    exodus = {"file": deck.get(f"{where}.Output Filename", str) + suffix, "every": every, "variables": names}
    for key, field in OUTPUT_STEPS.items():  # a step is counted across a sequence of solvers
        step = deck.get(f"{where}.{key}", int, None)
        if step is not None and step < 0:
            raise deck.error(f"{where}.{key}", step, "a step >= 0")
        if step is not None:
            exodus[field] = step
    if asked_sums:
        exodus["sums"] = asked_sums
    return exodus


def convert_deck(path) -> dict:
    """The case dict of the Peridigm deck at ``path`` (named after the file's stem)."""
    path = Path(path)
    return deck_case(read_deck(path), path.stem, str(path), path.parent)


def relative_mesh(raw: dict, folder) -> dict:
    """``raw`` (a ``deck_case`` dict) with its mesh file relative to ``folder``, the folder of
    the case file it is written to, so that the case and its mesh move together (node sets are
    written out as point indices: no other file is named). On another drive (Windows), the
    absolute path stays."""
    geometry = raw["geometry"]
    if "file" in geometry:
        try:
            geometry["file"] = Path(os.path.relpath(geometry["file"], Path(folder).resolve())).as_posix()
        except ValueError:
            pass
    return raw


def load_deck(path, overrides=()) -> Case:
    """A Peridigm deck as a validated peridyn ``Case``, ``--set`` overrides applied to the
    translated case (``peridyn.io.case.apply_override``)."""
    raw = convert_deck(path)
    for item in overrides:
        apply_override(raw, item, str(path))
    return validate_case(raw, str(path))


def load_case_or_deck(path, overrides=()) -> Case:
    """``peridyn.io.case.load_case``, or for a Peridigm deck (``is_peridigm_deck``) its
    translation (``load_deck``)."""
    if is_peridigm_deck(path):
        return load_deck(path, overrides)
    return load_case(path, overrides)
