"""The case file described for people and editors (peridyn.io.case_schema): every key of every
section has a description, the physical ones their SI unit, and ``peridyn schema`` prints the
JSON schema that editors read."""

from __future__ import annotations

import inspect
import json

import pytest

from peridyn.cli import main
from peridyn.io import case
from peridyn.io.case_schema import case_json_schema, case_unit, reference_rows

SECTIONS = [c for _, c in inspect.getmembers(case, inspect.isclass) if issubclass(c, case.Strict)]
SECTIONS.remove(case.Strict)


@pytest.mark.parametrize("section", SECTIONS, ids=lambda c: c.__name__)
def test_every_key_has_a_description(section):
    undescribed = [name for name, field in section.model_fields.items() if not field.description]
    assert not undescribed, f"{section.__name__}: {undescribed}"


def test_the_reference_lists_every_key_of_every_section_once_per_place():
    """Every field of every section reached from Case appears in the reference; the paths are
    unique."""
    rows = [row for section in reference_rows().values() for row in section]
    paths = [row.path for row in rows]
    assert len(paths) == len(set(paths))
    listed = {(p.rsplit(".", 1)[-1]) for p in paths}
    assert listed >= {name for section in SECTIONS for name in section.model_fields}
    by_path = {row.path: row for row in rows}
    assert by_path["material.E"].unit == "Pa" and by_path["material.E"].default == "required"
    assert by_path["solver.linear_solver"].type == 'one of "auto", "lu", "cg"'
    assert by_path["solver.linear_solver"].default == '"auto"'
    assert by_path["output.lines.<name>.points"].type == "integer"
    assert by_path["precracks[].origin"].unit == "m"


@pytest.mark.parametrize(
    ("path", "unit"),
    [
        ("material.E", "Pa"),
        ("materials.steel.density", "kg/m^3"),
        ("geometry.size[0]", "m"),
        ("solver.time", "s"),
        ("solver.damping", "1/s"),
        ("discretization.horizon", None),  # a multiple of the spacing
        ("no.such.key", None),
    ],
)
def test_case_unit(path, unit):
    assert case_unit(path) == unit


def test_schema_command_prints_the_json_schema(capsys, tmp_path):
    assert main(["schema"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == case_json_schema()
    assert printed["$defs"]["Material"]["properties"]["E"]["unit"] == "Pa"
    assert set(printed["required"]) == {"name", "geometry", "discretization", "solver"}
    assert main(["schema", "-o", str(tmp_path / "case.schema.json")]) == 0
    assert json.loads((tmp_path / "case.schema.json").read_text()) == printed
