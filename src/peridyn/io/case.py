"""Case files: YAML validated with pydantic, SI units, unknown keys refused.

``load_case(path, overrides)`` reads a file, applies ``--set key.path=value``
overrides and returns a :class:`Case`. Every problem is reported as a
:class:`~peridyn.errors.CaseFileError` naming the key path, the value and what
was expected (with "did you mean" for misspelt keys).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
import yaml
from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    model_validator,
)

from peridyn.discretization.bonds import horizon_metres
from peridyn.errors import CaseFileError, InputError, did_you_mean
from peridyn.io.exodus_write import PERIDIGM_VARIABLES
from peridyn.io.text_file import read_input_text
from peridyn.physics.loads import parse_components
from peridyn.physics.materials.base import Model, ParameterError
from peridyn.physics.materials.registry import MODELS, model_class

#: Deepest nesting of collections a YAML text may have (a case nests 5 levels; PyYAML composes
#: each level by recursion, so a deeper text would exhaust Python's recursion limit).
MAX_YAML_DEPTH = 64
#: Most values a YAML text may hold with its aliases expanded (a shipped case holds about 300; an
#: alias bomb, "billion laughs", holds 9**9 from a few lines and would hang whatever walks it).
MAX_YAML_VALUES = 100_000


class _Loader(yaml.SafeLoader):
    """SafeLoader that also reads ``1e3`` and ``150.0e3`` as floats (YAML 1.2 style; plain
    PyYAML would take them for strings) and refuses a key given twice in one mapping (PyYAML
    keeps the last silently). Keys merged in with ``<<: *anchor`` may be overridden. A text
    nested deeper than ``MAX_YAML_DEPTH``, whose aliases expand to more than ``MAX_YAML_VALUES``
    values, or with an alias inside its own anchor is refused before it is constructed."""

    def __init__(self, stream):
        super().__init__(stream)
        self._depth = 0

    def compose_node(self, parent, index):
        if self._depth >= MAX_YAML_DEPTH:
            raise yaml.composer.ComposerError(
                None,
                None,
                f"collections nested deeper than {MAX_YAML_DEPTH} levels",
                self.peek_event().start_mark,
            )
        self._depth += 1
        try:
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def construct_document(self, node):
        if _expanded_size(node, {}) > MAX_YAML_VALUES:
            raise yaml.constructor.ConstructorError(
                None,
                None,
                f"more than {MAX_YAML_VALUES} values once its aliases are expanded, or an alias "
                "inside its own anchor",
                node.start_mark,
            )
        return super().construct_document(node)

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            first_line = {}
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue
                key = self.construct_object(key_node, deep=deep)
                try:
                    earlier = first_line.setdefault(key, key_node.start_mark.line + 1)
                except TypeError:  # an unhashable key: PyYAML's own error follows
                    continue
                if earlier != key_node.start_mark.line + 1:
                    raise yaml.constructor.ConstructorError(
                        None,
                        None,
                        f"key {key!r} is given twice (first on line {earlier})",
                        key_node.start_mark,
                    )
        return super().construct_mapping(node, deep=deep)


def _checked_scalar(construct):
    """PyYAML's constructor ``construct`` of a scalar type, whose failure on a value it cannot read
    (``!!int abc``: ValueError; ``!!bool maybe``: KeyError; ``!!timestamp x``: AttributeError; an
    integer of more than 4300 digits: ValueError) is a YAML error at that value."""

    def checked(loader, node):
        try:
            return construct(loader, node)
        except (ValueError, KeyError, AttributeError):
            kind, text = node.tag.rsplit(":", 1)[-1], str(node.value)
            shown = repr(text) if len(text) <= 40 else f"{text[:37]!r}... ({len(text)} characters)"
            raise yaml.constructor.ConstructorError(
                None, None, f"{shown} is not a valid {kind}", node.start_mark
            ) from None

    return checked


for _kind in ("int", "float", "bool", "timestamp"):
    _tag = f"tag:yaml.org,2002:{_kind}"
    _Loader.add_constructor(_tag, _checked_scalar(_Loader.yaml_constructors[_tag]))


def _expanded_size(node: yaml.Node, sizes: dict) -> int:
    """Values in ``node`` with every alias expanded, counted once per node (an alias is the same
    node object as its anchor); above ``MAX_YAML_VALUES`` for a node within itself."""
    if id(node) in sizes:
        return sizes[id(node)]
    sizes[id(node)] = MAX_YAML_VALUES + 1  # while counting: an alias to it is a cycle
    if isinstance(node, yaml.SequenceNode):
        children = node.value
    elif isinstance(node, yaml.MappingNode):
        children = [child for pair in node.value for child in pair]
    else:
        children = []
    total = 1
    for child in children:
        total += _expanded_size(child, sizes)
        if total > MAX_YAML_VALUES:
            break
    sizes[id(node)] = total
    return total


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(
        r"""^(?:[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?(?:[eE][-+]?[0-9]+)
    |[-+]?(?:[0-9][0-9_]*)\.[0-9_]*
    |[-+]?\.[0-9_]+(?:[eE][-+]?[0-9]+)?
    |[-+]?\.(?:inf|Inf|INF)
    |\.(?:nan|NaN|NAN))$""",
        re.X,
    ),
    list("-+0123456789."),
)


def parse_yaml(text: str):
    """Parse YAML text with floats read as in YAML 1.2 (``1e-3``, ``68.9e9``)."""
    return yaml.load(text, Loader=_Loader)


def yaml_problem(exc: yaml.YAMLError) -> str:
    """One line saying what is wrong with some YAML and where (line and column, 1-based)."""
    problem = getattr(exc, "problem", None) or getattr(exc, "context", None) or str(exc)
    mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
    where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
    return " ".join(f"{problem}{where}".split())


def _not_a_bool(value):
    """Refuse ``true``/``false`` where a number is expected (pydantic would read them as 1 and 0)."""
    if isinstance(value, bool):
        raise ValueError(f"a number, not {str(value).lower()}")
    return value


NotBool = BeforeValidator(_not_a_bool)


def _folder_name(name: str) -> str:
    """Refuse a case name that is not one folder name (it names the run's output folder)."""
    if not name.strip() or name in (".", "..") or any(c in name for c in "/\\\0"):
        raise ValueError(
            f"a folder name (the output folder is peridyn-out/<name>): not empty, '.' or '..', "
            f"without '/', '\\' or NUL, got {name!r}"
        )
    return name


Positive = Annotated[float, NotBool, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, NotBool, Field(ge=0, allow_inf_nan=False)]
Finite = Annotated[float, NotBool, Field(allow_inf_nan=False)]
Index = Annotated[int, NotBool]
Vector3 = Annotated[list[Finite], Field(min_length=2, max_length=3)]


def described(default, description: str, unit: str | None = None):
    """A case key's default (``...``: required), description and unit (SI, UDUNITS spelling; None
    for a number without one or a word), as the case-file reference and the JSON schema show them
    (``peridyn.io.case_schema``)."""
    return Field(default, description=description, json_schema_extra={"unit": unit} if unit else None)


class Strict(BaseModel):
    """Base of every section: unknown keys are errors."""

    model_config = ConfigDict(extra="forbid")


class Geometry(Strict):
    """The body's shape. ``box``: size [lx, ly, lz]; ``plate``: size [length, width, thickness]
    and ``layers``; ``rectangle`` (2D): size [lx, ly], ``thickness``, ``plane``;
    ``mesh``: a Peridigm-style text mesh ``file`` (x y z block_id volume); ``exodus``: an
    Exodus II mesh ``file`` (a point per element; its blocks, node sets and side sets become
    node sets, see ``peridyn.io.exodus``)."""

    type: Literal["box", "plate", "rectangle", "mesh", "exodus"] = described(
        ..., "shape of the body: box, plate, rectangle (2D), mesh (text mesh file) or exodus (Exodus II mesh)"
    )
    size: list[Positive] | None = described(
        None,
        "lengths along x, y (and z): box [lx, ly, lz], plate [length, width, thickness], rectangle [lx, ly]",
        "m",
    )
    origin: Vector3 | None = described(
        None, "corner of the body with the smallest coordinates (default: the origin)", "m"
    )
    layers: Annotated[int, NotBool, Field(ge=1)] | None = described(
        None, "plate: points through the thickness"
    )
    layer_placement: Literal["cell", "surface"] = described(
        "cell", "plate: layers at cell centres (cell) or with the outer layers on the surfaces (surface)"
    )
    thickness: Positive | None = described(None, "rectangle or 2D mesh: out-of-plane thickness", "m")
    plane: Literal["stress", "strain"] = described("stress", "rectangle: plane stress or plane strain")
    file: str | None = described(None, "mesh or exodus: the mesh file, relative to the case file")
    dimension: Literal[2, 3] = described(3, "mesh: 2 or 3 dimensions")

    @model_validator(mode="after")
    def _complete(self):
        need = {"box": 3, "plate": 3, "rectangle": 2}
        if self.type in need and (self.size is None or len(self.size) != need[self.type]):
            raise ValueError(f"a {self.type} needs size with {need[self.type]} values (m)")
        if self.type == "plate" and self.layers is None:
            raise ValueError("a plate needs the number of layers through its thickness")
        if self.type == "rectangle" and self.thickness is None:
            raise ValueError("a rectangle (2D) needs its thickness (m)")
        if self.is_mesh and not self.file:
            raise ValueError(f"a {self.type} geometry needs the mesh file")
        if self.is_mesh and self.dimension == 2 and self.thickness is None:
            raise ValueError(f"a 2D {self.type} geometry needs its thickness (m)")
        return self

    @property
    def is_mesh(self) -> bool:
        """Points read from a mesh file (text or Exodus) rather than made on a grid."""
        return self.type in ("mesh", "exodus")

    @property
    def dim(self) -> int:
        """2 for a rectangle or a 2D mesh, else 3."""
        return 2 if self.type == "rectangle" or (self.type == "mesh" and self.dimension == 2) else 3


class BondFilter(Strict):
    """Bonds meeting a finite plane leave the families (``finite_plane``: Peridigm's
    "Rectangular_Plane" bond filter, ``peridyn.discretization.bonds.crossing_finite_plane``):
    the plane through ``corner`` (m) of ``normal``, ``bottom_length`` (m) along ``bottom`` and
    ``side_length`` (m) along bottom x normal; a bond touching it at an end counts."""

    type: Literal["finite_plane"] = described("finite_plane", "the filter's shape: a finite plane")
    corner: Vector3 = described(..., "a corner of the plane", "m")
    normal: Vector3 = described(..., "the plane's normal")
    bottom: Vector3 = described(..., "direction of the plane's bottom edge from the corner")
    bottom_length: Positive = described(..., "length of the bottom edge", "m")
    side_length: Positive = described(..., "length of the side edge, along bottom x normal", "m")


class Discretization(Strict):
    """Spacing (m, one value or one per axis for a box), horizon as a multiple of the spacing
    (``horizon``) or in metres (``horizon_m``), influence function, partial volumes and the
    storage of the bonds."""

    spacing: Positive | list[Positive] | None = described(
        None, "grid spacing: one value, or one per axis for a box", "m"
    )
    horizon: Positive | None = described(
        None, "horizon as a multiple of the spacing (give this or horizon_m)"
    )
    horizon_m: Positive | None = described(None, "horizon in metres (give this or horizon)", "m")
    influence: Literal["constant", "inverse", "gaussian", "conical"] = described(
        "constant", "influence function of the bonds"
    )
    partial_volumes: bool = described(
        True, "weigh bonds near the horizon's edge by the share of the neighbour's cell inside it"
    )
    neighbourhood: Literal["sphere", "box"] = described(
        "sphere",
        "sphere: |xi| <= horizon; box (a box geometry, no partial volumes): the points within "
        "round(horizon / spacing) cells along each axis, Peridigm's PdQuickGrid families",
    )
    storage: Literal["bonds", "lattice", "auto"] = described(
        "bonds",
        "how the bonds are stored: bonds (bond lists, every case), lattice (one stencil and a broken bit "
        "per bond: grid bodies of explicit runs) or auto (lattice where the case allows it)",
    )
    bond_filters: list[BondFilter] = described(
        [], "bonds taken out of the families (Peridigm's bond filters; a pre-crack breaks them instead)"
    )
    bonds_between_blocks: bool = described(
        True, "false: no bond joins two blocks (Peridigm's Omit Bonds Between Blocks: All)"
    )
    points_without_bonds: Literal["refuse", "warn"] = described(
        "refuse",
        "a point with no neighbour within the horizon (e.g. a horizon below the spacing): refused, or "
        "kept with a warning naming the points (it then moves freely, touched by contact only: "
        "Peridigm decks)",
    )

    def horizon_metres(self, spacing: float) -> float:
        """The horizon (m) on a grid of ``spacing`` (m): ``horizon_m``, or ``horizon`` spacings."""
        return horizon_metres(self.horizon_m, self.horizon, spacing)

    @model_validator(mode="after")
    def _one_horizon(self):
        if (self.horizon is None) == (self.horizon_m is None):
            raise ValueError("give exactly one of horizon (multiple of the spacing) or horizon_m")
        if self.points_without_bonds == "warn":
            return self  # the points without neighbours are named when the bonds are found
        if self.neighbourhood == "box" and self.horizon_m is not None:
            check_box_horizon(self.horizon_m, self.spacing)
        else:
            check_horizon(self.horizon, self.horizon_m, self.spacing)
        return self


def check_horizon(horizon: float | None, horizon_m: float | None, spacing) -> None:
    """Refuse a horizon (in spacings, or ``horizon_m`` in m) below the ``spacing`` (m, one value,
    a list, or None for a mesh), where a point has no neighbours along the axes (ValueError)."""
    if horizon is not None and horizon < 1:
        raise ValueError(
            f"horizon = {horizon:g} spacings: at least 1 (below the spacing a point "
            "has no neighbours along the axes)"
        )
    spacing = max(spacing) if isinstance(spacing, list) else spacing
    if horizon_m is not None and spacing is not None and horizon_m < spacing:
        raise ValueError(
            f"horizon_m = {horizon_m:g} m is below the spacing {spacing:g} m: "
            "at least the spacing (else a point has no neighbours along the axes)"
        )


def box_cells(horizon, spacing):
    """Cells a box neighbourhood reaches along an axis of ``spacing`` (m; a number or an array of
    the axes' spacings): round(horizon / spacing), halves up."""
    return np.floor(horizon / spacing + 0.5)


def check_box_horizon(horizon_m: float, spacing) -> None:
    """Refuse the horizon (m) of a box neighbourhood (``box_cells`` along each axis) that reaches
    no cell along any axis of the ``spacing`` (m, one value or a list; Peridigm's older
    BondBreakingInitialVelocity deck reaches along y only) (ValueError)."""
    spacing = min(spacing) if isinstance(spacing, list) else spacing
    if spacing is not None and box_cells(horizon_m, spacing) < 1:
        raise ValueError(
            f"horizon_m = {horizon_m:g} m reaches no cell of a box neighbourhood: at least half "
            f"the smallest spacing {spacing:g} m"
        )


class Damage(Strict):
    """Bond failure: ``critical_stretch``, ``fracture_energy`` (J/m^2) or
    ``critical_bond_stress`` (Pa; bond stress E s, see ``peridyn.physics.damage``), and node sets
    where bonds never break."""

    critical_stretch: Positive | dict | None = described(
        None,
        "bonds break above this stretch (give one of the three criteria); a number, or a time function "
        "mapping (a body of one material): s_c(t), Peridigm's Time Dependent Critical Stretch",
    )
    fracture_energy: Positive | None = described(
        None, "critical energy release rate, from which the critical stretch follows", "J/m^2"
    )
    critical_bond_stress: Positive | None = described(None, "bonds break above this bond stress E s", "Pa")
    no_damage_sets: list[str] = described([], "node sets whose bonds never break")

    @model_validator(mode="after")
    def _one(self):
        given = [self.critical_stretch, self.fracture_energy, self.critical_bond_stress]
        if sum(v is not None for v in given) != 1:
            raise ValueError("give exactly one of critical_stretch, fracture_energy or critical_bond_stress")
        return self


def _registered_material(name: str) -> str:
    """``name`` if a material is registered under it, else ValueError listing the registered ones."""
    try:
        model_class(name)
    except InputError as exc:
        raise ValueError(str(exc)) from None
    return name


def _registered_names(schema: dict) -> None:
    """The JSON schema of ``material.model``: the names registered when it is generated."""
    schema["enum"] = sorted(MODELS)


class Material(Strict):
    """Material model, elastic constants (Pa, kg/m^3) and optional damage. What a model takes
    (nu required or implied, its surface corrections) is checked by its class
    (``Model.check_parameters``)."""

    model: Annotated[str, AfterValidator(_registered_material)] = Field(
        ...,
        description="material model, a registered material: pmb (bond-based), lps (state-based), "
        "linear_lps, or one a plugin registers (peridyn.physics.materials.registry)",
        json_schema_extra=_registered_names,
    )
    E: Positive = described(..., "Young's modulus", "Pa")
    nu: Annotated[float, NotBool, Field(gt=-1, lt=0.5)] | None = described(
        None, "Poisson's ratio (pmb: fixed by the model, 1/4 in 3D)"
    )
    density: Positive = described(..., "mass density", "kg/m^3")
    surface_correction: str = described(
        "none",
        "surface correction of the stiffness near free surfaces: none, or one the model takes "
        "(pmb: energy; lps, linear_lps: shear-factor, energy)",
    )
    damage: Damage | None = described(None, "bond failure (none: bonds never break)")


class Region(Strict):
    """A region of points: box (min, max), sphere (center, radius), cylinder (center, radius,
    axis), face (face, depth), layer (index), points (0-based ``indices``), or all."""

    type: Literal["box", "sphere", "cylinder", "face", "layer", "points", "all"] = described(
        ..., "kind of region"
    )
    min: Vector3 | None = described(None, "box: lowest corner", "m")
    max: Vector3 | None = described(None, "box: highest corner", "m")
    center: Vector3 | None = described(None, "sphere or cylinder: centre", "m")
    radius: Positive | None = described(None, "sphere or cylinder: radius", "m")
    axis: Literal["x", "y", "z"] = described("z", "cylinder: axis direction")
    face: Literal["x-", "x+", "y-", "y+", "z-", "z+"] | None = described(None, "face: which face of the body")
    depth: Positive | None = described(None, "face: depth into the body (default: one spacing)", "m")
    index: Index | None = described(
        None, "layer: index of the layer through the thickness (negative from the top)"
    )
    indices: Annotated[list[Annotated[int, NotBool, Field(ge=0)]], Field(min_length=1)] | None = described(
        None, "points: 0-based point indices"
    )

    @model_validator(mode="after")
    def _complete(self):
        needs = {
            "points": ("indices",),
            "box": ("min", "max"),
            "sphere": ("center", "radius"),
            "cylinder": ("center", "radius"),
            "face": ("face",),
            "layer": ("index",),
        }
        missing = [k for k in needs.get(self.type, ()) if getattr(self, k) is None]
        if missing:
            raise ValueError(f"a {self.type} region needs {', '.join(missing)}")
        return self


class Block(Strict):
    """One block of a body made of several materials (``Case.blocks``, docs/blocks.md): the points
    of ``region`` or of the node set ``set`` (exactly one of them), made of ``material``, a name
    in ``Case.materials``, with its own horizon (``horizon`` in spacings or ``horizon_m``; at most
    one; default the discretization's). Every point of the body lies in exactly one block."""

    material: str = described(..., "name of the block's material in materials")
    region: Region | None = described(None, "the block's points (give this or set)")
    set: str | None = described(None, "node set holding the block's points (give this or region)")
    horizon: Positive | None = described(
        None, "the block's horizon as a multiple of the spacing (default: the discretization's)"
    )
    horizon_m: Positive | None = described(None, "the block's horizon in metres", "m")

    def horizon_metres(self, spacing: float, default: float) -> float:
        """The block's horizon (m) on a grid of ``spacing`` (m); ``default`` (m) without one."""
        if self.horizon is None and self.horizon_m is None:
            return default
        return horizon_metres(self.horizon_m, self.horizon, spacing)

    @model_validator(mode="after")
    def _one_selection(self):
        if (self.region is None) == (self.set is None):
            raise ValueError("give exactly one of region or set (the points of the block)")
        if self.horizon is not None and self.horizon_m is not None:
            raise ValueError("give at most one of horizon (multiple of the spacing) or horizon_m")
        check_horizon(self.horizon, None, None)
        return self


#: A bond's two ends in the x-y plane, [x_a, y_a, x_b, y_b], or in space, [x_a, y_a, z_a, x_b, y_b, z_b] (m).
BondEnds = Annotated[list[Finite], Field(min_length=4, max_length=6)]


class Precrack(Strict):
    """Bonds crossing a planar rectangle (origin, edge_u, edge_v; 3D), a segment (start, end;
    2D) or a surface (``file``: an Exodus mesh of triangles, e.g. shells, relative to the case
    file; Peridigm's "Exodus Mesh" bond filter of an initial damage model) are cut; or the
    bonds listed by their ends' positions (``pairs``, ``tolerance``: in the x-y plane, in a plate
    the bonds between two columns of points, e.g. a plane-stress model's broken bonds; or in
    space, the bonds between two points, e.g. a 3D model's broken bonds)."""

    type: Literal["rectangle", "segment", "surface", "bonds"] = described(
        ..., "rectangle (3D), segment (2D), surface (the triangles of a mesh file) or bonds (listed)"
    )
    file: str | None = described(None, "surface: the mesh file of the crack's triangles")
    in_weighted_volume: bool = described(
        False,
        "the cut bonds still count in LPS's weighted volumes (Peridigm's initial damage); false: the "
        "family is the intact bonds",
    )
    origin: Vector3 | None = described(None, "rectangle: one corner", "m")
    edge_u: Vector3 | None = described(None, "rectangle: first edge from the origin", "m")
    edge_v: Vector3 | None = described(None, "rectangle: second edge from the origin", "m")
    start: Vector3 | None = described(None, "segment: first end", "m")
    end: Vector3 | None = described(None, "segment: second end", "m")
    pairs: Annotated[list[BondEnds], Field(min_length=1)] | None = described(
        None,
        "bonds: each bond's ends in the x-y plane, [x_a, y_a, x_b, y_b] (every pair of layers of a plate), "
        "or in space, [x_a, y_a, z_a, x_b, y_b, z_b]",
        "m",
    )
    tolerance: Positive | None = described(
        None,
        "bonds: how near, in the pairs' plane or space, a point lies to a listed end (under half a spacing)",
        "m",
    )

    @model_validator(mode="after")
    def _complete(self):
        keys = {
            "rectangle": ("origin", "edge_u", "edge_v"),
            "segment": ("start", "end"),
            "surface": ("file",),
            "bonds": ("pairs", "tolerance"),
        }[self.type]
        missing = [k for k in keys if getattr(self, k) is None]
        if missing:
            raise ValueError(f"a {self.type} pre-crack needs {', '.join(missing)}")
        if self.pairs is not None and {len(p) for p in self.pairs} not in ({4}, {6}):
            raise ValueError("bonds pairs are all [x_a, y_a, x_b, y_b] or all [x_a, y_a, z_a, x_b, y_b, z_b]")
        return self


class BoundaryConditionSpec(Strict):
    """A condition on node set ``set``: kind, components ("x", "xy", ...) and a value
    (a number, a time function mapping, see ``peridyn.physics.timefunctions.from_spec``, or
    ``{type: expression, text: ...}``, an expression in x, y, z and t evaluated on the set's
    points, see ``peridyn.physics.expressions``). ``where_prescribed`` (a force): ``error`` if
    another condition prescribes the motion of one of its components, or ``yield``: the prescribed
    motion wins, the force still counting in the point's acceleration (Peridigm's convention)."""

    set: str = described(..., "node set the condition acts on")
    kind: Literal["displacement", "velocity", "force", "body_force"] = described(
        ...,
        "prescribed displacement (m), velocity (m/s), force (N, shared by the set's points) or body force "
        "(N/m^3)",
    )
    components: str | list[str] = described(
        "xyz", "components it acts on: x, y, z or a combination such as xy"
    )
    value: Finite | dict = described(
        0.0,
        "a number, a time function mapping ({type: tone_burst, ...}) or {type: expression, text: ...} in "
        "x, y, z and t; unit of the kind",
    )
    where_prescribed: Literal["error", "yield"] = described(
        "error",
        "a force where another condition prescribes the motion: error, or yield (the prescribed motion "
        "wins, Peridigm's convention)",
    )


class InitialConditionSpec(Strict):
    """Initial displacement (m) or velocity (m/s) of node set ``set``: a number or
    ``{type: expression, text: ...}`` in x, y, z (and t = 0)."""

    set: str = described(..., "node set the condition acts on")
    kind: Literal["displacement", "velocity"] = described(..., "initial displacement (m) or velocity (m/s)")
    components: str | list[str] = described("xyz", "components it sets: x, y, z or a combination")
    value: Finite | dict = described(
        0.0, "a number or {type: expression, text: ...} in x, y, z (t = 0); unit of the kind"
    )


class Actuator(Strict):
    """A surface-bonded PZT patch: ``pzt_radial`` (Patra et al. 2018: radial in-plane displacement, zero at
    the centre, ``amplitude`` on the perimeter) or ``pin_force`` (outward line forces of
    ``line_force`` N/m along the edges); driven by the time function ``signal``."""

    type: Literal["pzt_radial", "pin_force"] = described(
        ...,
        "pzt_radial: radial in-plane displacement, zero at the centre and amplitude on the perimeter; "
        "pin_force: outward line forces along the edges",
    )
    center: Annotated[list[Finite], Field(min_length=2, max_length=2)] = described(
        ..., "centre of the patch in the plate's plane (x, y)", "m"
    )
    size: Positive = described(..., "side of a square patch or diameter of a circular one", "m")
    shape: Literal["square", "circular"] = described("square", "shape of the patch")
    layer: Index | None = described(-1, "layer of points the patch drives (-1: the top)")
    amplitude: Positive = described(1e-6, "pzt_radial: displacement amplitude on the perimeter", "m")
    line_force: Positive = described(1.0, "pin_force: force per length along the edges", "N/m")
    signal: dict = described(
        ..., "time function of the drive, e.g. {type: tone_burst, frequency: 150e3, cycles: 3.5}"
    )


class PZTSensor(Strict):
    """A PZT patch used as a sensor: the mean in-plane strain (eps_xx + eps_yy) under it."""

    center: Annotated[list[Finite], Field(min_length=2, max_length=2)] = described(
        ..., "centre of the patch in the plate's plane (x, y)", "m"
    )
    size: Positive = described(..., "side of a square patch or diameter of a circular one", "m")
    shape: Literal["square", "circular"] = described("square", "shape of the patch")
    layer: Index = described(-1, "layer of points under the patch (-1: the top)")


class FKAnalysis(Strict):
    """Frequency-wavenumber analysis of a line probe: wavenumbers of the named modes at
    ``frequency`` (default: the first actuator's centre frequency), each read from one
    displacement component."""

    line: str = described(..., "name of the line probe (output.lines) analysed")
    frequency: Positive | None = described(
        None, "frequency of the wavenumbers read (default: the first actuator's centre frequency)", "Hz"
    )
    components: dict[str, Literal["x", "y", "z"]] = described(
        {"S0": "x", "A0": "z"}, "displacement component read for each named mode"
    )
    window: Literal["hann", "none"] = described("hann", "window along time and space before the transform")
    pad: Annotated[float, NotBool, Field(ge=1)] = described(2.0, "zero padding factor of the transform")
    tolerance: Annotated[float, NotBool, Field(gt=0, lt=1)] = described(
        0.2, "relative wavenumber difference accepted against Rayleigh-Lamb theory"
    )


class KxKyAnalysis(Strict):
    """(kx, ky) maps of a plane probe at chosen frequencies, with ring radii per mode."""

    plane: str = described(..., "name of the plane probe (output.planes) analysed")
    frequencies: list[Positive] = described(..., "frequencies of the maps", "Hz")
    component: Literal["x", "y", "z"] = described("z", "displacement component mapped")


class Analysis(Strict):
    """Post-processing run after the simulation."""

    fk: FKAnalysis | None = described(None, "frequency-wavenumber analysis of a line probe")
    kxky: KxKyAnalysis | None = described(None, "wavenumber maps of a plane probe")


class ExplicitStage(Strict):
    """An explicit (velocity Verlet) stage run after a ``newton`` solver's last load step, from
    its state (u, and the velocity of its last load step), as Peridigm runs a sequence of
    solvers: ``steps`` steps of ``dt`` from the newton solver's ``time``, the loads' time
    functions read on; its steps numbered on from the load steps, its first state (the
    stage's start) one step after the last load step."""

    dt: Positive = described(..., "time step", "s")
    steps: Annotated[int, NotBool, Field(ge=1)] = described(..., "number of time steps")
    prescribed_velocity: Literal["rate", "difference"] = described(
        "rate", "the reported velocity of a DOF with a prescribed displacement (as the explicit solver's)"
    )


class Solver(Strict):
    """``explicit``: ``steps`` or ``time`` (s), optional ``dt`` (s; default safety x stable),
    damping (1/s), kernel dtype; ``static``: adaptive dynamic relaxation with ``tolerance``,
    ``max_iterations`` and ``load_steps`` (the loads at t = 1 s, ramped linearly in steps);
    ``modal``: the ``modes`` lowest free-vibration modes (zero displacement conditions fix
    their dofs; free-free otherwise); ``newton``: Newton-Raphson equilibrium with ``tolerance``
    (relative residual), ``load_steps`` (the loads at t = ``time``, default 1 s, ramped),
    ``newton_iterations`` per solve and ``breaking_rounds`` (re-equilibrations per step after
    bonds break), then optionally an explicit stage (``then``, ``ExplicitStage``); ``newmark``:
    implicit dynamics (average acceleration) with ``steps`` or ``time``, ``dt`` (s, required),
    ``displacement_tolerance`` (m, Newton increment; Martowicz: 0.1 nm), ``newton_iterations``
    and ``damping``; both take ``linear_solver`` (``auto``, ``lu`` or ``cg``)."""

    type: Literal["explicit", "static", "modal", "newton", "newmark"] = described(
        "explicit",
        "explicit dynamics, static (dynamic relaxation), modal, newton (implicit statics) or newmark "
        "(implicit dynamics)",
    )
    modes: Annotated[int, NotBool, Field(ge=1)] = described(12, "modal: number of lowest modes computed")
    steps: Annotated[int, NotBool, Field(ge=1)] | None = described(
        None, "explicit, newmark: number of time steps (give this or time)"
    )
    time: Positive | None = described(
        None,
        "explicit, newmark: simulated time (give this or steps); newton: the time at which the loads are "
        "applied (default 1 s)",
        "s",
    )
    dt: Positive | None = described(
        None, "time step (explicit default: safety times the stable step; newmark: required)", "s"
    )
    safety: Annotated[float, NotBool, Field(gt=0, le=1)] = described(
        0.8, "explicit: fraction of the stable time step used when dt is not given"
    )
    damping: NonNegative = described(0.0, "mass-proportional damping coefficient", "1/s")
    dtype: Literal["float64", "float32"] = described(
        "float64", "explicit: floating-point type of the force kernels"
    )
    tolerance: Positive = described(1e-6, "static, newton: relative residual at convergence")
    max_iterations: Annotated[int, NotBool, Field(ge=1)] = described(
        200_000, "static: most dynamic-relaxation iterations per load step"
    )
    load_steps: Annotated[int, NotBool, Field(ge=1)] = described(
        1, "static, newton: steps of the linear load ramp"
    )
    newton_iterations: Annotated[int, NotBool, Field(ge=1)] = described(
        30, "newton, newmark: most Newton iterations per step"
    )
    breaking_rounds: Annotated[int, NotBool, Field(ge=1)] = described(
        100, "newton: most re-equilibrations per step after bonds break"
    )
    displacement_tolerance: Positive = described(1e-10, "newmark: Newton increment at convergence", "m")
    absolute_tolerance: Positive | None = described(
        None,
        "newton: converged when the residual force's norm is below it, instead of the relative tolerance; "
        "newmark: instead of displacement_tolerance (Peridigm's Absolute Tolerance)",
        "N",
    )
    linear_solver: Literal["auto", "lu", "cg"] = described(
        "auto",
        "newton, newmark: lu (sparse LU, refused when its estimated factor exceeds the memory), cg "
        "(conjugate gradients on the matrix-free tangent, AMG-preconditioned) or auto (lu while the "
        "estimated factor stays under 256 MiB, cg beyond: large 3D bodies)",
    )
    initial_acceleration: Literal["balance", "zero"] = described(
        "balance", "newmark: the acceleration at t = 0, balance (of the initial forces) or zero (Peridigm's)"
    )
    prescribed_velocity: Literal["rate", "difference"] = described(
        "rate",
        "explicit: the reported velocity of a DOF with a prescribed displacement: rate (its time "
        "function's derivative) or difference (Peridigm's)",
    )
    step_rule: Literal["peridyn", "peridigm"] = described(
        "peridyn",
        "explicit: peridyn's (the model's stable step; ceil(time / dt) steps) or Peridigm's time step "
        "conventions (bond-based stable step; floor(time / dt) steps)",
    )
    arithmetic: Literal["peridyn", "peridigm"] = described(
        "peridyn",
        "explicit: peridyn's order of operations, or Peridigm's (deformed positions x + u formed "
        "first, its LPS force loop, a = f / rho: its last bits; cpu backend, one process; "
        "docs/peridigm.md)",
    )
    eigensolver: Literal["auto", "shift-invert", "lobpcg"] = described(
        "auto",
        "modal: shift-invert (factorised), lobpcg (matrix-free) or auto (by the estimated factor size)",
    )
    then: ExplicitStage | None = described(
        None, "newton: an explicit stage run after the last load step, from its state"
    )
    backend: Literal["cpu", "gpu"] = described(
        "cpu",
        "explicit: where the time loop runs, cpu (numba kernels) or gpu (a CUDA device through NVIDIA Warp, "
        "the gpu extra)",
    )

    @model_validator(mode="after")
    def _backend(self):
        if self.backend == "gpu" and self.type != "explicit":
            raise ValueError(f"backend gpu runs explicit solvers only, not {self.type}: use backend cpu")
        if self.then is not None and self.type != "newton":
            raise ValueError(f"then: an explicit stage follows a newton solver, not {self.type}")
        if self.arithmetic == "peridigm" and self.type != "explicit":
            raise ValueError(f"arithmetic peridigm is an explicit solver's, not {self.type}'s")
        return self

    @model_validator(mode="after")
    def _newmark(self):
        if self.type == "newmark":
            if (self.steps is None) == (self.time is None):
                raise ValueError("a newmark run needs exactly one of steps or time (s)")
            if self.dt is None:
                raise ValueError(
                    "a newmark run needs dt (s): the implicit step is not bounded "
                    "by the explicit stable step, so no default is taken"
                )
        return self

    @model_validator(mode="after")
    def _duration(self):
        if self.type == "explicit" and self.steps is not None and self.time is not None:
            raise ValueError("give steps or time, not both (they would conflict)")
        if self.type == "explicit" and self.steps is None and self.time is None:
            raise ValueError("an explicit run needs steps or time (s)")
        return self


class LineSpec(Strict):
    """A line probe from ``start`` to ``end`` (m) sampled at ``points`` points."""

    start: Vector3 = described(..., "first end of the line", "m")
    end: Vector3 = described(..., "last end of the line", "m")
    points: Annotated[int, NotBool, Field(ge=2)] = described(..., "sample points along the line")

    @model_validator(mode="after")
    def _length(self):
        if len(self.start) == len(self.end) and self.start == self.end:
            raise ValueError(f"start and end are the same point {self.start}: a line probe needs a length")
        return self


class SetSum(Strict):
    """A global output variable: the sum (``calculation``: or the largest or smallest value,
    per component) of the output variable ``variable`` (``PERIDIGM_VARIABLES``) over node set
    ``set`` (Peridigm's "Block_Data" and "Node_Set_Data" compute classes)."""

    variable: str = described(..., "Peridigm's name of the variable (any output variable)")
    set: str = described(..., "node set or block it is taken over")
    calculation: Literal["sum", "maximum", "minimum"] = described(
        "sum", "sum, maximum or minimum over the set"
    )

    @model_validator(mode="after")
    def _known(self):
        if self.variable not in PERIDIGM_VARIABLES:
            raise ValueError(
                f"variable: unknown output variable {self.variable!r}; known: {sorted(PERIDIGM_VARIABLES)}"
            )
        return self


class ExodusOutput(Strict):
    """Exodus II output as Peridigm writes it: the ``variables`` named as Peridigm names them
    (``peridyn.io.exodus_write.PERIDIGM_VARIABLES``) and the global ``sums`` (name ->
    ``SetSum``) in ``file`` (in the output folder), at every ``every``-th step from step 0;
    ``point_order``: the body's (``peridyn``) or ``grid`` (x fastest, then y, then z, as
    Peridigm numbers a PdQuickGrid); ``three_d``: a 2D body written with three coordinates and
    vector components (z = 0), as Peridigm writes it."""

    file: Annotated[str, Field(pattern=r"^[^/\\]+$")] = described(
        "results.e", "Exodus file name in the output folder"
    )
    every: Annotated[int, NotBool, Field(ge=1)] = described(1, "write every this many steps, from step 0")
    variables: list[str] = described(
        ..., "Peridigm's names of the variables written (may be empty with sums)"
    )
    sums: dict[str, SetSum] = described(
        {}, "global variables: name -> a sum, maximum or minimum of a variable over a node set or block"
    )
    point_order: Literal["peridyn", "grid"] = described(
        "peridyn", "the body's point order, or grid (x fastest, then y, then z, as Peridigm numbers a grid)"
    )
    three_d: bool = described(False, "a 2D body written with three coordinates and components (z = 0)")
    first_step: Annotated[int, NotBool, Field(ge=0)] = described(
        0, "the first step written (Peridigm's Initial Output Step)"
    )
    last_step: Annotated[int, NotBool, Field(ge=0)] | None = described(
        None, "the last step written (Peridigm's Final Output Step; default: the run's last)"
    )

    @model_validator(mode="after")
    def _known(self):
        if self.last_step is not None and self.last_step < self.first_step:
            raise ValueError(f"last_step {self.last_step}: at least first_step {self.first_step}")
        if not self.variables and not self.sums:
            raise ValueError("variables: at least one variable or sum to write")
        for name in self.variables:
            if name not in PERIDIGM_VARIABLES:
                raise ValueError(
                    f"variables: unknown output variable {name!r}{did_you_mean(name, PERIDIGM_VARIABLES)}; "
                    f"known: {sorted(PERIDIGM_VARIABLES)}"
                )
        return self


class Output(Strict):
    """Where and what to write (folder default: ``peridyn-out/<case name>``); ``exodus``: also
    write the snapshots as Exodus II, ``results.e`` (``peridyn.io.exodus_write``), or, given
    as a mapping, Peridigm's named variables (``ExodusOutput``)."""

    directory: str | None = described(None, "output folder (default: peridyn-out/<case name>)")
    every: Annotated[int, NotBool, Field(ge=1)] = described(
        1, "record the probe series every this many steps"
    )
    snapshot_every: Annotated[int, NotBool, Field(ge=1)] | None = described(
        None, "write a whole-field snapshot every this many steps"
    )
    snapshot_times: list[NonNegative] = described([], "times of the whole-field snapshots", "s")
    sensors: dict[str, Vector3] = described({}, "point sensors: name -> position", "m")
    lines: dict[str, LineSpec] = described({}, "line probes: name -> start, end and points")
    planes: dict[str, str] = described({}, "plane probes: name -> layer (e.g. top)")
    pzt_sensors: dict[str, PZTSensor] = described(
        {}, "PZT sensors: name -> patch; their signal is the mean in-plane strain under the patch"
    )
    series_dtype: Literal["float64", "float32"] = described(
        "float64", "floating-point type of the stored line, plane and field series"
    )
    vtu: bool = described(True, "write VTU snapshots for ParaView")
    vtu_compression: Literal["none", "zlib"] = described(
        "none", "compression of the VTU snapshots' data: none (written 8 times as fast) or zlib"
    )
    exodus: bool | ExodusOutput = described(
        False, "also write the snapshots as Exodus II (results.e), or Peridigm's named variables"
    )
    exodus_more: list[ExodusOutput] = described(
        [], "more Exodus files of named variables (Peridigm's Output1, Output2, ...), each at its frequency"
    )
    plots: bool = described(True, "draw the run's figures")
    stress: bool = described(False, "per-point partial stress in the final fields and VTU snapshots")
    strain: bool = described(False, "per-point Green-Lagrange strain in the final fields and VTU snapshots")

    @model_validator(mode="after")
    def _more_files(self):
        if self.exodus_more and isinstance(self.exodus, bool):
            raise ValueError("exodus_more: give exodus as a mapping (file, every, variables) too")
        files = [e.file for e in [self.exodus, *self.exodus_more] if not isinstance(e, bool)]
        if len(set(files)) != len(files):
            raise ValueError(f"exodus and exodus_more: one file each, got {files}")
        return self


class ContactSpec(Strict):
    """Short-range contact forces between unbonded points (``peridyn.physics.contact``): contact
    distance as a multiple of the spacing (``radius``) or in metres (``radius_m``), and the
    short-range constant as a multiple of the PMB micromodulus (``stiffness_factor``,
    Peridigm's 15 by default)."""

    radius: Positive | None = described(
        None, "contact distance as a multiple of the spacing (give this or radius_m)"
    )
    radius_m: Positive | None = described(None, "contact distance in metres", "m")
    stiffness_factor: Positive = described(15.0, "short-range constant as a multiple of the PMB micromodulus")
    beyond_horizon: Literal["refuse", "allow"] = described(
        "refuse",
        "a contact distance above the horizon: refused, or allowed (Peridigm's decks; one process)",
    )

    @model_validator(mode="after")
    def _one_radius(self):
        if (self.radius is None) == (self.radius_m is None):
            raise ValueError("give exactly one of radius (multiple of the spacing) or radius_m")
        return self


class Case(Strict):
    """A whole simulation case. ``name`` is a folder name (the default output folder is
    ``peridyn-out/<name>``): not empty, not ``.`` or ``..``, without a path separator or NUL."""

    name: Annotated[str, AfterValidator(_folder_name)] = described(
        ..., "name of the case (the default output folder peridyn-out/<name>)"
    )
    description: str = described("", "one line saying what the case is")
    geometry: Geometry = described(..., "the body's shape")
    discretization: Discretization = described(..., "grid spacing, horizon and bond options")
    material: Material | None = described(None, "the material of a one-material body")
    materials: dict[str, Material] = described({}, "materials by name, for a body of several blocks")
    blocks: dict[str, Block] = described({}, "blocks by name: their points and material")
    removals: list[Region] = described([], "regions whose points are removed (holes, notches)")
    node_sets: dict[str, Region] = described({}, "named sets of points, used by the conditions and outputs")
    precracks: list[Precrack] = described([], "cuts through which no bond passes")
    actuators: dict[str, Actuator] = described({}, "PZT actuators by name")
    boundary_conditions: list[BoundaryConditionSpec] = described(
        [], "prescribed displacements, velocities and forces"
    )
    initial_conditions: list[InitialConditionSpec] = described([], "initial displacements and velocities")
    solver: Solver = described(..., "the solver and its settings")
    output: Output = described(Output(), "what is written and where")
    analysis: Analysis | None = described(None, "Lamb-wave analyses after the run")
    contact: ContactSpec | None = described(None, "short-range contact forces")
    fatigue: Fatigue | None = described(None, "remaining-life fatigue (peridyn fatigue)")
    absorbing: AbsorbingSpec | None = described(None, "absorbing boundary layers")

    @model_validator(mode="after")
    def _box_neighbourhood(self):
        d = self.discretization
        if d.neighbourhood == "box" and (self.geometry.type != "box" or d.partial_volumes):
            raise ValueError(
                "discretization.neighbourhood: a box neighbourhood needs a box geometry and "
                "partial_volumes: false"
            )
        return self

    @model_validator(mode="after")
    def _materials(self):
        if self.blocks and self.material is not None:
            raise ValueError(
                "blocks: give either material (one material for the whole body) or materials "
                "and blocks (docs/blocks.md), not both"
            )
        if not self.blocks:
            if self.materials:
                raise ValueError("materials: named materials are used by blocks; give blocks too")
            if self.material is None:
                raise ValueError("material: a required key that is missing (or give materials and blocks)")
            return self
        for name, block in self.blocks.items():
            if block.material not in self.materials:
                raise ValueError(
                    f"blocks.{name}.material: unknown material {block.material!r}"
                    f"{did_you_mean(block.material, self.materials)}; defined: {sorted(self.materials)}"
                )
        unused = sorted(set(self.materials) - {b.material for b in self.blocks.values()})
        if unused:
            raise ValueError(f"materials.{unused[0]}: no block is made of it")
        first_name, first = next(iter(self.materials.items()))
        for name, mat in self.materials.items():
            for key in ("model", "surface_correction"):
                if getattr(mat, key) != getattr(first, key):
                    raise ValueError(
                        f"materials.{name}.{key}: {getattr(mat, key)!r}, but materials.{first_name} has "
                        f"{getattr(first, key)!r}: the blocks of a body share one model and surface "
                        "correction (docs/blocks.md)"
                    )
        for name, block in self.blocks.items():
            try:
                check_horizon(None, block.horizon_m, self.discretization.spacing)
            except ValueError as exc:
                raise ValueError(f"blocks.{name}.horizon_m: {exc}") from None
        for key in ("contact", "fatigue", "analysis"):
            if getattr(self, key) is not None:
                raise ValueError(f"{key}: not available for a body of several blocks (yet); use one material")
        return self

    @model_validator(mode="after")
    def _material_parameters(self):
        for name, mat in self.block_materials().items():
            where = name if self.material is not None else f"materials.{name}"
            try:
                model_class(mat.model).check_parameters(
                    E=mat.E, density=mat.density, nu=mat.nu, surface_correction=mat.surface_correction
                )
            except ParameterError as exc:
                raise ValueError(f"{where}.{exc.key}: {exc}") from None
            except InputError as exc:
                raise ValueError(f"{where}: {exc}") from None
        return self

    def material_class(self) -> type[Model]:
        """The registered class of the case's material model (one model for every block)."""
        return model_class(next(iter(self.block_materials().values())).model)

    def block_materials(self) -> dict[str, Material]:
        """Every material of the case by the key it is given under: ``{"material": material}``
        for one material, else ``materials``."""
        return {"material": self.material} if self.material is not None else dict(self.materials)

    @model_validator(mode="after")
    def _absorbing_solver(self):
        if self.absorbing is not None and self.solver.type != "explicit":
            raise ValueError(
                f"absorbing: layers damp the explicit solver only, not the "
                f"{self.solver.type} solver (use solver.type explicit)"
            )
        return self

    @model_validator(mode="after")
    def _components(self):
        for name in ("boundary_conditions", "initial_conditions"):
            for i, condition in enumerate(getattr(self, name)):
                try:
                    components = parse_components(condition.components)
                except InputError as exc:
                    raise ValueError(f"{name}[{i}].components: {exc}") from None
                # the default "xyz" means x and y on a 2D body; a z written out is a mistake
                if self.geometry.dim == 2 and 2 in components and "components" in condition.model_fields_set:
                    raise ValueError(
                        f"{name}[{i}].components: {condition.components!r} names z, but a 2D body has "
                        "components x and y only"
                    )
        return self

    def set_references(self) -> list[tuple[str, str]]:
        """(key, node set name) of every node set the case refers to."""
        used = [(f"boundary_conditions[{i}].set", bc.set) for i, bc in enumerate(self.boundary_conditions)]
        used += [(f"initial_conditions[{i}].set", ic.set) for i, ic in enumerate(self.initial_conditions)]
        used += [(f"output.planes.{k}", v) for k, v in self.output.planes.items()]
        if not isinstance(self.output.exodus, bool):
            used += [(f"output.exodus.sums.{k}.set", v.set) for k, v in self.output.exodus.sums.items()]
        for n, more in enumerate(self.output.exodus_more):
            used += [(f"output.exodus_more[{n}].sums.{k}.set", v.set) for k, v in more.sums.items()]
        used += [(f"blocks.{k}.set", b.set) for k, b in self.blocks.items() if b.set is not None]
        for key, mat in self.block_materials().items():
            if key != "material":
                key = f"materials.{key}"
            if mat.damage:
                used += [(f"{key}.damage.no_damage_sets", s) for s in mat.damage.no_damage_sets]
        return used

    @model_validator(mode="after")
    def _sets_exist(self):
        clash = set(self.actuators) & (set(self.node_sets) | {"all"})
        if clash:
            raise ValueError(f"actuators: name {sorted(clash)[0]!r} is already a node set")
        known = set(self.node_sets) | {"all"} | set(self.actuators)
        in_file = self.geometry.is_mesh  # its sets are known once the mesh is read
        for where, name in self.set_references():
            if name not in known and not in_file:
                raise ValueError(
                    f"{where}: unknown node set {name!r}{did_you_mean(name, known)}; defined: {sorted(known)}"
                )
        if self.contact is not None and self.solver.type not in ("explicit", "static"):
            raise ValueError(
                f"contact: the {self.solver.type} solver has no contact forces; "
                "contact works with solver.type explicit or static"
            )
        a = self.analysis
        if a is not None and self.geometry.type != "plate":
            raise ValueError("analysis: Lamb-wave analyses need a plate geometry")
        if a is not None and a.fk is not None and a.fk.line not in self.output.lines:
            raise ValueError(
                f"analysis.fk.line: {a.fk.line!r} is not one of output.lines {sorted(self.output.lines)}"
            )
        if a is not None and a.kxky is not None and a.kxky.plane not in self.output.planes:
            raise ValueError(
                f"analysis.kxky.plane: {a.kxky.plane!r} is not one of output.planes "
                f"{sorted(self.output.planes)}"
            )
        if a is not None and a.fk is not None and a.fk.frequency is None and not self.actuators:
            raise ValueError("analysis.fk.frequency: give it, or an actuator whose signal has one")
        return self


def load_case(path, overrides=()) -> Case:
    """Read, override and validate a case file.

    Parameters
    ----------
    path : str or Path
    overrides : sequence of "key.path=value"
        Applied before validation; values are parsed as YAML (``1e-3``, ``true``, ``[1, 2]``).
    """
    path = Path(path)
    raw = read_yaml_mapping(path, "YAML case file")
    for item in overrides:
        apply_override(raw, item, str(path))
    return validate_case(raw, str(path))


def read_yaml_mapping(path: Path, what: str, root: str = "a mapping of sections") -> dict:
    """The mapping a YAML input file (a case, sweep or monitoring file: ``what``) holds.

    Raises
    ------
    CaseFileError
        Missing, unreadable or oversized file, bad YAML, or a root that is not a mapping
        (``root`` says what it should be).
    """
    text = read_input_text(path, what)
    try:
        raw = parse_yaml(text)
    except yaml.YAMLError as exc:
        raise CaseFileError(str(path), "<file>", None, f"valid YAML ({yaml_problem(exc)})") from None
    if not isinstance(raw, dict):
        raise CaseFileError(str(path), "<root>", raw, root)
    return raw


def first_problem(exc: ValidationError, source: str) -> CaseFileError:
    """The one-line error of a file validated by a model other than :class:`Case` (a sweep or
    monitoring file): its first problem, named by its key, and how many more there are."""
    err = exc.errors()[0]
    key = ".".join(str(p) for p in err["loc"] if not str(p).startswith("function-")) or "<root>"
    more = f" (and {len(exc.errors()) - 1} more problems)" if len(exc.errors()) > 1 else ""
    value = None if err["type"] == "missing" else err.get("input")
    return CaseFileError(source, key, value, err["msg"].removeprefix("Value error, ") + more)


def validate_case(raw: dict, source: str = "<case>") -> Case:
    """Validate a case given as a dictionary (e.g. built in Python)."""
    try:
        return Case.model_validate(raw)
    except ValidationError as exc:
        raise _case_error(exc, source) from None


def apply_override(raw: dict, item: str, source: str = "<case>") -> None:
    """Set ``key.path=value`` in the nested dict ``raw`` (list items by index: ``a.0.b``, or
    ``a[0].b`` as the error messages write it)."""
    if "=" not in item:
        raise CaseFileError(source, item, None, "an override of the form key.path=value")
    key, text = item.split("=", 1)
    try:
        value = parse_yaml(text)
    except yaml.YAMLError as exc:
        raise CaseFileError(source, key.strip(), text, f"a YAML value ({yaml_problem(exc)})") from None
    parts = re.sub(r"\[(-?\d+)\]", r".\1", key.strip()).split(".")
    node = raw
    for depth, part in enumerate(parts[:-1]):
        node = _child(node, part, source, ".".join(parts[: depth + 1]))
    last = parts[-1]
    if isinstance(node, list):
        node[_index(node, last, source, key)] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise CaseFileError(source, key, node, "a mapping or a list to set a key in")


def _child(node, part: str, source: str, where: str):
    if isinstance(node, list):
        return node[_index(node, part, source, where)]
    if not isinstance(node, dict):
        raise CaseFileError(source, where, node, "a mapping")
    return node.setdefault(part, {})


def _index(node: list, part: str, source: str, where: str) -> int:
    if not part.lstrip("-").isdigit() or not -len(node) <= int(part) < len(node):
        raise CaseFileError(source, where, part, f"a list index below {len(node)}")
    return int(part)


def _case_error(exc: ValidationError, source: str) -> CaseFileError:
    lines = []
    first = None
    for err in exc.errors():
        loc = _key_path(err["loc"])
        value = err.get("input")
        if err["type"] == "extra_forbidden":
            allowed = _allowed_keys(err["loc"])
            expected = f"no such key{did_you_mean(str(err['loc'][-1]), allowed)}; allowed: {allowed}"
        elif err["type"] == "missing":
            expected, value = "a required key that is missing", None
        else:
            expected = err["msg"].removeprefix("Value error, ")
        has_value = True
        if not loc and (named := _LEADING_KEY.fullmatch(expected)):  # a check of the whole case:
            loc, value, expected, has_value = named["key"], None, named["rest"], False  # no value
        if first is None:
            first = (loc, value, expected, has_value)
        lines.append((f"{loc} = {value!r}: " if has_value else f"{loc}: ") + expected if loc else expected)
    error = CaseFileError(source, first[0] or "<root>", first[1], first[2], has_value=first[3])
    if len(lines) > 1:
        error.args = (f"{source}: {len(lines)} problems:\n  " + "\n  ".join(lines),)
    return error


#: A message of a check of the whole case that names its key first ("absorbing: layers damp ...").
_LEADING_KEY = re.compile(r"(?P<key>[A-Za-z_][\w.\[\]]*): (?P<rest>.*)", re.S)
#: The names pydantic gives the members of a union in an error's location (``value: float | dict``
#: fails at ``("value", "float")`` and ``("value", "dict[any,any]")``): not keys of the case.
_UNION_MEMBERS = {
    "float",
    "int",
    "str",
    "bool",
    "constrained-float",
    "constrained-int",
    "function-after",
    "literal",
}


def _key_path(loc) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif "[" in str(part) or part in _UNION_MEMBERS:
            continue
        else:
            out += f".{part}" if out else str(part)
    return out


def _allowed_keys(loc) -> list[str]:
    model: type[BaseModel] = Case
    for part in loc[:-1]:
        if isinstance(part, int):
            continue
        field = model.model_fields.get(str(part))
        if field is None:
            break
        inner = _model_in(field.annotation)
        if inner is None:
            break
        model = inner
    return sorted(model.model_fields)


def _model_in(annotation):
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in getattr(annotation, "__args__", ()):
        found = _model_in(arg)
        if found is not None:
            return found
    return None


class FatigueBlock(Strict):
    """``steps`` fatigue steps of 1 / ``tau`` cycles each (the thesis's linear cycle mapping)."""

    steps: Annotated[int, NotBool, Field(ge=1)] = described(..., "fatigue steps in this block")
    tau: Positive = described(..., "fatigue step as a fraction of a cycle: each step is 1 / tau cycles")


class FatigueTip(Strict):
    """Crack tip: farthest coordinate along ``axis``, in the ``sense`` the crack grows ("+" or
    "-"), whose points through ``depth_axis`` all have damage >= ``damage`` (thesis: 0.385);
    crack length measured from ``start`` (m, e.g. a notch root), by default from the body's edge
    the crack grows from (``fatigue.tip.crack_tip``)."""

    axis: Literal["x", "y", "z"] = described("x", "axis along which the crack grows")
    depth_axis: Literal["x", "y", "z"] = described("z", "axis through the thickness")
    damage: Annotated[float, NotBool, Field(gt=0, le=1)] = described(
        0.385, "damage from which a point counts as cracked"
    )
    start: float | None = described(
        None, "where the crack length is measured from (default: the edge the crack grows from)", "m"
    )
    sense: Literal["+", "-"] = described("+", "direction in which the crack grows along axis")


class CrackPlane(Strict):
    """A plane that confines the fatigue crack: only bonds whose ends lie strictly on opposite
    sides of the plane normal to ``axis`` at ``at`` (m) may break, so the crack is a clean cut
    along it (e.g. a mode-I crack from a notch on the plane)."""

    axis: Literal["x", "y", "z"] = described(..., "normal of the plane")
    at: Finite = described(..., "coordinate of the plane along axis", "m")


class FatigueModal(Strict):
    """Free-free modal analyses before and after the fatigue run: ``modes`` modes, rigid included."""

    modes: Annotated[int, NotBool, Field(ge=7)] = described(12, "modes computed, rigid ones included")


class ParisSpecimen(Strict):
    """Single-edge-notch geometry for K_I = sigma sqrt(pi a) F(a/b) (thesis eqs. 7.12-7.13):
    ``stress`` (Pa, maximum remote stress) and ``width`` b (m); see the fields for the fit."""

    stress: Positive = described(..., "maximum remote stress", "Pa")
    width: Positive = described(..., "specimen width b", "m")
    fit_range: tuple[Positive, Positive] | None = described(
        None, "crack lengths whose growth rates enter the Paris fit (default: every rate)", "m"
    )
    stop_length: Positive | None = described(
        None, "stop once the crack is this long (default: run every step)", "m"
    )
    k: Literal["eq_7_12", "compliance"] = described(
        "eq_7_12",
        "stress intensity range from the single-edge-notch formula (eq_7_12) or from the compliance of "
        "the modelled specimen",
    )

    @model_validator(mode="after")
    def _range(self):
        if self.fit_range is not None and self.fit_range[0] >= self.fit_range[1]:
            raise ValueError(
                f"paris.fit_range must be [shortest, longest] crack length (m), got {list(self.fit_range)}"
            )
        return self


class Fatigue(Strict):
    """Remaining-life fatigue (Freimanis 2019 ch. 7): phase I (A_I, m_I, eps_inf), phase II
    (A_II, m_II; A_II given at ``A_II_horizon`` m and scaled to the case's horizon by eq. 7.15),
    phi_c, load ratio R in [-1, 1), the boundary conditions' value at ``max_load_time`` (s) as the
    maximum load, cycle ``mapping`` blocks (``adaptive``: cut a step where the next bond breaks),
    no-damage node sets, an optional ``crack_plane`` that confines the breaking, crack ``tip``,
    linear ``solver`` and optional ``modal_after``."""

    A_I: Positive = described(..., "phase I (crack nucleation) life constant")
    m_I: Positive = described(..., "phase I exponent")
    eps_inf: NonNegative = described(..., "phase I fatigue limit of the cyclic bond strain")
    A_II: Positive = described(..., "phase II (crack growth) life constant")
    m_II: Positive = described(..., "phase II exponent")
    A_II_horizon: Positive | None = described(
        None, "horizon at which A_II is given; it is scaled to the case's horizon", "m"
    )
    phi_c: Annotated[float, NotBool, Field(gt=0, le=1)] = described(
        0.385, "damage of a point at the crack tip"
    )
    load_ratio: Annotated[float, NotBool, Field(ge=-1, lt=1)] = described(
        0.0, "load ratio R of the cycles, in [-1, 1)"
    )
    max_load_time: NonNegative = described(
        1.0, "time at which the boundary conditions give the maximum load", "s"
    )
    mapping: Annotated[list[FatigueBlock], Field(min_length=1)] = described(
        ..., "blocks of fatigue steps and their cycle mapping"
    )
    adaptive: bool = described(False, "cut a step where the next bond breaks")
    no_damage_sets: list[str] = described([], "node sets whose bonds never break")
    crack_plane: CrackPlane | None = described(
        None, "only the bonds that cross this plane may break (default: any bond)"
    )
    tip: FatigueTip = described(FatigueTip(), "how the crack tip and length are found")
    solver: Literal["auto", "amg", "direct", "cg"] = described("auto", "linear solver of the static steps")
    modal_after: FatigueModal | None = described(None, "free-free modal analyses before and after the cycles")
    paris: ParisSpecimen | None = described(None, "single-edge-notch specimen for the Paris-law fit")

    @model_validator(mode="after")
    def _axes(self):
        if self.tip.axis == self.tip.depth_axis:
            raise ValueError("tip.axis and tip.depth_axis must differ")
        if self.paris is not None and (self.tip.start is not None or self.tip.sense != "+"):
            raise ValueError(
                "fatigue.paris measures the crack from the low edge of tip.axis (a "
                "single edge notch): leave tip.start and tip.sense at their defaults"
            )
        return self


class AbsorbingSpec(Strict):
    """Absorbing boundary layers (``peridyn.physics.absorbing``): mass-proportional damping growing as
    the cube of the depth into a layer ``width`` m wide along each of ``faces``, from 0 at its
    inner edge to ``damping`` (1/s) on the face; added to ``solver.damping``."""

    width: Positive = described(..., "width of each layer", "m")
    damping: Positive = described(..., "damping on the face", "1/s")
    faces: Annotated[list[Literal["x-", "x+", "y-", "y+", "z-", "z+"]], Field(min_length=1)] = described(
        ["x-", "x+", "y-", "y+"], "faces with a layer"
    )


Case.model_rebuild()
