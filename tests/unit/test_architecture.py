"""Materials are asked, never named: outside ``peridyn.physics.materials`` no module tests for a
concrete material class, compares a value with a material's registered name or reads a private
attribute of a material model.

Everything stiffness assembly, the tangent, modal analysis and fatigue need from a material
goes through the interface of ``peridyn.physics.materials.base.Model`` (``linearisation()``,
``has_dilatation``, ...), so that a new material is one new module (tests/materials shows
one). The check reads the source with ``ast``: every ``isinstance``/``issubclass`` naming a
material class of peridyn.physics.materials, and every ``<...>model._private`` attribute (or a private
attribute a material sets, on any object but ``self``) is reported with its file and line.
"""

import ast
from pathlib import Path

import peridyn
from peridyn.physics.materials import MODELS, Model

SOURCE = Path(peridyn.__file__).parent
MATERIALS_PACKAGE = SOURCE / "physics" / "materials"


def _material_classes() -> set[str]:
    """Names of the material classes defined in peridyn.physics.materials (Model and its subclasses)."""
    names = set()
    todo = [Model]
    while todo:
        cls = todo.pop()
        todo.extend(cls.__subclasses__())
        if cls.__module__.startswith("peridyn.physics.materials"):
            names.add(cls.__name__)
    return names - {"Model"}


def _private_material_attributes() -> set[str]:
    """Private attributes the material modules set on ``self`` (``self._name = ...``)."""
    names = set()
    for path in MATERIALS_PACKAGE.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if (
                isinstance(node, ast.Attribute)
                and isinstance(node.ctx, ast.Store)
                and isinstance(node.value, ast.Name)
                and node.value.id == "self"
                and node.attr.startswith("_")
                and not node.attr.startswith("__")
            ):
                names.add(node.attr)
    return names


def _outside_materials() -> list[Path]:
    files = sorted(SOURCE.rglob("*.py"))
    return [p for p in files if MATERIALS_PACKAGE not in p.parents]


def _names_in(node: ast.AST) -> set[str]:
    """Class names an isinstance/issubclass second argument mentions (names, attributes, tuples)."""
    found = set()
    for sub in ast.walk(node):
        if isinstance(sub, ast.Name):
            found.add(sub.id)
        elif isinstance(sub, ast.Attribute):
            found.add(sub.attr)
    return found


def _is_model_expression(node: ast.AST) -> bool:
    """A model by its name: ``model``, ``self.model``, ``setup.model``, ``base_model``."""
    if isinstance(node, ast.Name):
        return node.id == "model" or node.id.endswith("_model")
    if isinstance(node, ast.Attribute):
        return node.attr == "model" or node.attr.endswith("_model")
    return False


def test_source_tree_is_found():
    """The scan covers the package's modules (guards against scanning an empty folder)."""
    files = _outside_materials()
    assert len(files) > 50
    assert SOURCE / "linalg" / "stiffness.py" in files
    assert not any(MATERIALS_PACKAGE in p.parents for p in files)
    assert {"LPSModel", "PMBModel"} <= _material_classes()
    assert "_p_coef" in _private_material_attributes()


def test_no_concrete_material_is_tested_for_outside_the_materials_package():
    classes = _material_classes()
    found = []
    for path in _outside_materials():
        for node in ast.walk(ast.parse(path.read_text())):
            if (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Name)
                and node.func.id in ("isinstance", "issubclass")
                and len(node.args) == 2
            ):
                named = _names_in(node.args[1]) & classes
                if named:
                    found.append(
                        f"{path.relative_to(SOURCE)}:{node.lineno}: {node.func.id}(..., {sorted(named)})"
                    )
    assert not found, (
        "code outside peridyn.physics.materials branches on a concrete material; ask the model "
        "through the Model interface instead (linearisation(), has_dilatation, ...):\n" + "\n".join(found)
    )


#: Modules that name materials for what they are, not to branch on what a material can do:
#: the kernel benchmark's rows (a grid of the named materials' kernels) and the Peridigm deck's
#: material types translated to registered names.
NAMING_MODULES = {"jobs/bench.py", "jobs/bench_gpu.py", "io/peridigm_case.py"}


def _compared_names(node: ast.Compare, names: set[str]) -> set[str]:
    """Registered material names among the constants a comparison reads (``x == "pmb"``,
    ``x in ("lps", "linear_lps")``)."""
    found = set()
    for operand in (node.left, *node.comparators):
        items = operand.elts if isinstance(operand, ast.Tuple | ast.List | ast.Set) else [operand]
        found |= {i.value for i in items if isinstance(i, ast.Constant) and i.value in names}
    return found


def test_no_material_name_is_branched_on_outside_the_materials_package():
    """What a material can do (state-based, its Poisson ratio, stable step, dispersion) is asked
    of its class (``peridyn.physics.materials.registry.model_class``), never read off its name."""
    names = {name for name, cls in MODELS.items() if cls.__module__.startswith("peridyn.")}  # shipped
    assert {"pmb", "lps", "linear_lps"} <= names
    found = []
    for path in _outside_materials():
        if path.relative_to(SOURCE).as_posix() in NAMING_MODULES:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Compare) and (named := _compared_names(node, names)):
                found.append(f"{path.relative_to(SOURCE)}:{node.lineno}: {ast.unparse(node)} {sorted(named)}")
    assert not found, (
        "code outside peridyn.physics.materials branches on a material's name; ask its class "
        "(Model.state_based, implied_poisson_ratio, family_stiffness_bound, ...):\n" + "\n".join(found)
    )


def test_no_private_material_attribute_is_read_outside_the_materials_package():
    private = _private_material_attributes()
    found = []
    for path in _outside_materials():
        for node in ast.walk(ast.parse(path.read_text())):
            if not (
                isinstance(node, ast.Attribute)
                and node.attr.startswith("_")
                and not node.attr.startswith("__")
            ):
                continue
            on_self = isinstance(node.value, ast.Name) and node.value.id in ("self", "cls")
            if _is_model_expression(node.value) or (node.attr in private and not on_self):
                found.append(f"{path.relative_to(SOURCE)}:{node.lineno}: {ast.unparse(node)}")
    assert not found, (
        "code outside peridyn.physics.materials reads a private attribute of a material model; "
        "add what it needs to the Model interface (e.g. Model.linearisation()):\n" + "\n".join(found)
    )
