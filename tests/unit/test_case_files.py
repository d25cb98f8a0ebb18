"""Case files: validation, overrides and the ten kinds of bad input of the core issue."""

import copy

import numpy as np
import pytest

from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import apply_override, load_case, validate_case
from peridyn.setup.build import build
from peridyn.solvers import ExplicitSolver

GOOD = {
    "name": "tiny",
    "geometry": {"type": "box", "size": [0.006, 0.004, 0.004]},
    "discretization": {"spacing": 1e-3, "horizon": 2.015},
    "material": {"model": "lps", "E": 70e9, "nu": 0.3, "density": 2700},
    "node_sets": {"left": {"type": "face", "face": "x-"}, "right": {"type": "face", "face": "x+"}},
    "boundary_conditions": [
        {"set": "left", "kind": "displacement", "components": "xyz", "value": 0.0},
        {"set": "right", "kind": "force", "components": "x", "value": 10.0},
    ],
    "solver": {"type": "explicit", "steps": 10},
}


def _case(**changes):
    raw = copy.deepcopy(GOOD)
    for key, value in changes.items():
        apply_override(raw, f"{key}={value}")
    return raw


def test_good_case_validates_and_builds():
    setup = build(validate_case(_case()))
    assert setup.body.n_points == 6 * 4 * 4
    assert set(setup.body.node_sets) == {"all", "left", "right"}


def test_override_sets_nested_values():
    raw = _case(**{"discretization.spacing": "0.5e-3", "boundary_conditions.1.value": "20"})
    case = validate_case(raw)
    assert case.discretization.spacing == 0.5e-3
    assert case.boundary_conditions[1].value == 20


def test_yaml_file_with_exponent_floats(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text(
        "name: t\ngeometry: {type: box, size: [6e-3, 4e-3, 4e-3]}\n"
        "discretization: {spacing: 1e-3, horizon: 2.015}\n"
        "material: {model: pmb, E: 70e9, density: 2700}\n"
        "initial_conditions: [{set: all, kind: velocity, components: x, value: 1}]\n"
        "solver: {steps: 5}\n"
    )
    case = load_case(path, ["material.E=71e9"])
    assert case.material.E == 71e9 and case.geometry.size[0] == 6e-3


# -- the ten kinds of bad input named by the core issue, each with a clear message -------------


def test_unknown_key_suggests_the_right_one():
    raw = _case()
    raw["material"]["densty"] = 1.0
    with pytest.raises(CaseFileError, match=r"material\.densty.*did you mean 'density'"):
        validate_case(raw)


def test_negative_spacing():
    with pytest.raises(CaseFileError, match=r"discretization\.spacing.*greater than 0"):
        validate_case(_case(**{"discretization.spacing": "-1e-3"}))


def test_horizon_below_spacing_isolates_points():
    """Issue 17: a horizon below the spacing is refused when the case is read (in spacings
    or in metres), not when the bonds are searched."""
    with pytest.raises(CaseFileError, match=r"discretization.*horizon = 0.4 spacings: at least 1"):
        validate_case(_case(**{"discretization.horizon": "0.4", "discretization.partial_volumes": "false"}))
    raw = _case()
    raw["discretization"] = {"spacing": 1e-3, "horizon_m": 0.9e-3}
    with pytest.raises(CaseFileError, match=r"horizon_m = 0.0009 m is below the spacing 0.001 m"):
        validate_case(raw)


def test_nan_coordinates_in_mesh(tmp_path):
    mesh = tmp_path / "m.txt"
    mesh.write_text("0 0 0 1 1e-9\nnan 0 0 1 1e-9\n")
    raw = _case()
    raw["geometry"] = {"type": "mesh", "file": str(mesh)}
    raw["discretization"] = {"horizon_m": 2e-3}
    raw["node_sets"] = {}
    raw["boundary_conditions"] = []
    raw["initial_conditions"] = [{"set": "all", "kind": "velocity", "value": 1.0}]
    with pytest.raises(InputError, match="line 2"):
        build(validate_case(raw))


def test_empty_node_set():
    raw = _case()
    raw["node_sets"]["nowhere"] = {"type": "box", "min": [1, 1, 1], "max": [2, 2, 2]}
    with pytest.raises(CaseFileError, match=r"node_sets\.nowhere.*at least one point"):
        build(validate_case(raw))


def test_unstable_time_step():
    setup = build(validate_case(_case()))
    with pytest.raises(InputError, match="exceeds the stable step"):
        ExplicitSolver(setup.model, setup.loading, dt=1e-3)


def test_missing_mesh_file():
    raw = _case()
    raw["geometry"] = {"type": "mesh", "file": "/no/such/mesh.txt"}
    with pytest.raises(InputError, match="mesh.txt"):
        build(validate_case(raw))


def test_wrong_column_count_in_mesh(tmp_path):
    mesh = tmp_path / "m.txt"
    mesh.write_text("0 0 0 1 1e-9\n0 0 1e-3 1\n")
    raw = _case()
    raw["geometry"] = {"type": "mesh", "file": str(mesh)}
    with pytest.raises(InputError, match=r"line 2.*4.*5"):
        build(validate_case(raw))


def test_unknown_material_model():
    """The registry's names are listed (the shipped ones and the test-only conical)."""
    with pytest.raises(
        CaseFileError,
        match=r"material\.model = 'neo-hooke': unknown material model .*'lps', 'pmb'\]",
    ) as err:
        validate_case(_case(**{"material.model": "neo-hooke"}))
    assert err.value.key == "material.model"


def test_overlapping_incompatible_boundary_conditions():
    raw = _case()
    raw["boundary_conditions"].append({"set": "all", "kind": "velocity", "components": "x", "value": 1.0})
    with pytest.raises(InputError, match="prescribe the same component"):
        build(validate_case(raw))


# -- more ------------------------------------------------------------------------------------


def test_steps_and_time_conflict():
    with pytest.raises(CaseFileError, match="steps or time, not both"):
        validate_case(_case(**{"solver.time": "1e-6"}))


def test_unknown_set_in_boundary_condition():
    raw = _case()
    raw["boundary_conditions"][0]["set"] = "lefft"
    with pytest.raises(CaseFileError, match="did you mean 'left'"):
        validate_case(raw)


def test_force_on_a_prescribed_component():
    raw = _case()
    raw["boundary_conditions"][1]["set"] = "left"
    with pytest.raises(InputError, match="prescribed motion and an applied force"):
        build(validate_case(raw))


def test_missing_file(tmp_path):
    with pytest.raises(CaseFileError, match="existing YAML"):
        load_case(tmp_path / "none.yaml")


def test_nothing_moves():
    raw = _case()
    raw["boundary_conditions"] = []
    with pytest.raises(CaseFileError, match="nothing would move"):
        build(validate_case(raw))


def test_pmb_refuses_another_poisson_ratio():
    """Issue 17: a bond-based PMB material has nu = 1/4 in 3D; another nu is an error, not a
    warning; its own ratio (to 1e-3) or no nu at all is accepted."""
    raw = _case(**{"material.model": "pmb", "material.nu": "0.29"})
    with pytest.raises(InputError, match=r"nu = 0.29: .*Poisson ratio 0.25 .*omit nu or use lps"):
        build(validate_case(raw))
    assert (
        build(validate_case(_case(**{"material.model": "pmb", "material.nu": "0.2501"}))).model.name == "pmb"
    )
    raw = _case(**{"material.model": "pmb"})
    del raw["material"]["nu"]
    assert build(validate_case(raw)).model.name == "pmb"


def test_override_index_out_of_range():
    with pytest.raises(CaseFileError, match="list index"):
        _case(**{"boundary_conditions.5.value": "1"})


def test_stable_step_is_the_silling_askari_bound_for_pmb():
    """For PMB the stable step is sqrt(2 rho / sum_j C_ij V_j) (Silling and Askari 2005)."""
    setup = build(validate_case(_case(**{"material.model": "pmb", "material.nu": "0.25"})))
    m, b = setup.model, setup.bonds
    per_point = np.add.reduceat(m.bond_stiffness / b.length, b.offsets[:-1])
    expected = np.min(np.sqrt(2 * m.density / per_point))
    assert m.critical_time_step() == pytest.approx(expected, rel=1e-12)


def test_override_takes_the_index_as_the_errors_write_it():
    """Error messages name list items ``boundary_conditions[1]``; ``--set`` accepts that form."""
    case = validate_case(_case(**{"boundary_conditions[1].value": "20"}))
    assert case.boundary_conditions[1].value == 20


RECTANGLE = {
    **GOOD,
    "geometry": {"type": "rectangle", "size": [0.006, 0.004], "thickness": 1e-3},
    "material": {"model": "pmb", "E": 70e9, "density": 2700},
    "boundary_conditions": [{"set": "right", "kind": "force", "components": "x", "value": 10.0}],
}


@pytest.mark.parametrize("components", ["z", "xz", ["y", "z"]])
def test_a_z_component_on_a_2d_body_is_refused(components):
    """Issue 17 (no silent acceptance): a 2D body moves in x and y; a written-out z is a mistake
    that used to be dropped without a word."""
    raw = copy.deepcopy(RECTANGLE)
    raw["boundary_conditions"][0]["components"] = components
    with pytest.raises(CaseFileError) as caught:
        validate_case(raw)
    assert caught.value.key == "boundary_conditions[0].components"
    assert str(caught.value).endswith("names z, but a 2D body has components x and y only")


def test_the_default_components_of_a_2d_body_are_x_and_y():
    raw = copy.deepcopy(RECTANGLE)
    del raw["boundary_conditions"][0]["components"]
    assert validate_case(raw).boundary_conditions[0].components == "xyz"


@pytest.mark.parametrize("components, problem", [("q", "unknown component 'q'"), (["x", "x"], "distinct")])
def test_bad_components_name_their_key(components, problem):
    raw = _case()
    raw["boundary_conditions"][1]["components"] = components
    with pytest.raises(CaseFileError, match=rf"^<case>: boundary_conditions\[1\]\.components: .*{problem}"):
        validate_case(raw)


def test_a_check_across_keys_does_not_print_the_whole_case():
    """The node-set check runs on the whole case; its message names the key, not the case dict."""
    raw = _case(**{"boundary_conditions.0.set": "lefft"})
    with pytest.raises(CaseFileError) as caught:
        validate_case(raw)
    assert caught.value.key == "boundary_conditions[0].set"
    assert str(caught.value).startswith("<case>: boundary_conditions[0].set: unknown node set 'lefft'")
    assert "geometry" not in str(caught.value)


@pytest.mark.parametrize("value", [".nan", ".inf", "-.inf"])
def test_a_non_finite_boundary_value_is_refused(value):
    """A NaN load reached the solver before (found by tests/fuzz); InitialConditionSpec already
    asked for a finite value."""
    with pytest.raises(CaseFileError, match=r"boundary_conditions\[1\]\.value") as info:
        validate_case(_case(**{"boundary_conditions.1.value": value}))
    assert info.value.key == "boundary_conditions[1].value" and "finite" in info.value.expected


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("boundary_conditions.1.value", "abc"),
        ("discretization.spacing", "abc"),
        ("discretization.spacing", "[1, x]"),
    ],
)
def test_a_key_of_union_type_is_named_without_pydantic_s_member_names(key, value):
    """pydantic locates a union's failure at ("spacing", "constrained-float"): the key named was
    discretization.spacing.constrained-float before."""
    with pytest.raises(CaseFileError) as info:
        validate_case(_case(**{key: value}))
    assert info.value.key == key.replace(".1.", "[1].")
    assert all(f"{info.value.key}." not in line for line in str(info.value).splitlines())


def test_a_check_of_the_whole_case_names_its_key_not_the_whole_case():
    """The Case-level checks (node sets, contact, analysis, absorbing) report at the root: the
    error gave key "<root>" and the whole case as value (found by tests/fuzz)."""
    raw = _case()
    raw["boundary_conditions"][1]["set"] = "rihgt"
    with pytest.raises(CaseFileError) as info:
        validate_case(raw)
    exc = info.value
    assert (exc.key, exc.value) == ("boundary_conditions[1].set", None)
    assert exc.expected.startswith("unknown node set 'rihgt' (did you mean 'right'?)")
    assert "'geometry'" not in str(exc) and "boundary_conditions[1].set: unknown node set" in str(exc)
