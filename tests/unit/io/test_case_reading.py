"""Reading a case file: what is not valid UTF-8 YAML, or says a key twice, is one clear error
(issue 17: a traceback, or the last of two keys taken silently, before)."""

from pathlib import Path

import pytest

from peridyn.errors import CaseFileError
from peridyn.io.case import load_case, parse_yaml

ROOT = Path(__file__).resolve().parents[3]
BAR = ROOT / "cases" / "bar_pulse.yaml"


def test_a_key_given_twice_is_refused_with_both_lines(tmp_path):
    text = BAR.read_text()
    twice = text.replace("discretization:\n", "discretization:\n  spacing: 2.0e-3\n", 1)
    assert twice.count("spacing:") >= 2
    path = tmp_path / "twice.yaml"
    path.write_text(twice)
    with pytest.raises(CaseFileError, match=r"key 'spacing' is given twice \(first on line \d+\) at line"):
        load_case(path)


def test_a_merged_anchor_may_still_be_overridden():
    # YAML's merge key: the explicit key wins over the merged one, which is no duplicate
    data = parse_yaml("base: &b {a: 1, b: 2}\nderived:\n  <<: *b\n  b: 3\n")
    assert data["derived"] == {"a": 1, "b": 3}


def test_a_file_that_is_not_utf8_is_named_with_the_byte(tmp_path):
    path = tmp_path / "latin1.yaml"
    path.write_bytes(BAR.read_text().replace("name:", "# caf\u00e9\nname:", 1).encode("latin-1"))
    with pytest.raises(CaseFileError, match=r"UTF-8 text \(byte \d+ is 0xe9\)") as info:
        load_case(path)
    assert "\n" not in str(info.value)


def test_broken_yaml_in_an_override_is_one_line_naming_the_key():
    with pytest.raises(CaseFileError) as info:
        load_case(BAR, ["geometry.size=[0.1,0.01"])
    message = str(info.value)
    assert "geometry.size" in message and "'[0.1,0.01'" in message and "a YAML value" in message
    assert "\n" not in message


def test_broken_yaml_in_a_file_is_one_line_with_its_position(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("name: x\ngeometry: {type: box\n")
    with pytest.raises(CaseFileError, match=r"valid YAML \(.* at line \d+, column \d+\)") as info:
        load_case(path)
    assert "\n" not in str(info.value)


def _alias_bomb(levels: int) -> str:
    """ "Billion laughs": each anchor a list of nine aliases of the one before (9**levels values)."""
    lines = ["l0: &l0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    lines += [f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 9)}]" for i in range(1, levels + 1)]
    return "\n".join(lines) + "\n"


def test_an_alias_bomb_is_refused_before_it_is_expanded(tmp_path):
    """9**12 (3e11) values: a walk over them (the error message's repr, pydantic) would not end in
    hours; counting the composed nodes once each takes milliseconds (the bound of 5 s leaves room
    for a loaded machine). The fuzz test (tests/fuzz) hung on a 9-level bomb before."""
    import time

    path = tmp_path / "bomb.yaml"
    path.write_text(_alias_bomb(12) + BAR.read_text())
    start = time.perf_counter()
    with pytest.raises(CaseFileError, match=r"more than 100000 values once its aliases are expanded") as info:
        load_case(path)
    assert time.perf_counter() - start < 5.0
    assert info.value.key == "<file>" and "\n" not in str(info.value)


def test_a_bomb_in_an_override_is_refused_naming_the_key():
    levels = [f"&l0 [{', '.join(['lol'] * 9)}]"]
    levels += [f"&l{i} [{', '.join([f'*l{i - 1}'] * 9)}]" for i in range(1, 10)]
    with pytest.raises(CaseFileError, match="once its aliases are expanded") as info:
        load_case(BAR, [f"description=[{', '.join(levels)}]"])
    assert info.value.key == "description"


def test_an_alias_inside_its_own_anchor_is_refused():
    """PyYAML registers an anchor before its contents, so `&a [*a]` builds a list holding itself."""
    with pytest.raises(Exception, match="an alias inside its own anchor"):
        parse_yaml("a: &a [1, *a]\n")


def test_aliases_below_the_limit_are_read():
    data = parse_yaml(_alias_bomb(4))  # 9**4 + ... = 7381 values
    assert len(data["l4"]) == 9 and data["l4"][0] is data["l3"]


def test_deep_nesting_is_refused_with_its_position(tmp_path):
    """PyYAML composes each level by recursion: 3000 levels raised a RecursionError (an internal
    error of the CLI) before."""
    from peridyn.io.case import MAX_YAML_DEPTH

    path = tmp_path / "deep.yaml"
    path.write_text("[" * 3000 + "]" * 3000)
    with pytest.raises(CaseFileError, match=rf"nested deeper than {MAX_YAML_DEPTH} levels at line 1, column"):
        load_case(path)
    assert parse_yaml("[" * MAX_YAML_DEPTH + "]" * MAX_YAML_DEPTH) is not None


@pytest.mark.parametrize(
    ("text", "shown"),
    [
        ("!!int abc", "'abc' is not a valid int"),  # int(): ValueError
        ("!!float x", "'x' is not a valid float"),  # float(): ValueError
        ("!!bool maybe", "'maybe' is not a valid bool"),  # PyYAML's table: KeyError
        ("!!timestamp 2001-99", "'2001-99' is not a valid timestamp"),  # no regex match: AttributeError
        ("9" * 5000, "(5000 characters) is not a valid int"),  # Python's 4300-digit limit: ValueError
    ],
)
def test_a_tagged_value_of_the_wrong_type_names_it_and_its_line(tmp_path, text, shown):
    """PyYAML's scalar constructors raised ValueError, KeyError or AttributeError (an internal
    error of the CLI, found by tests/fuzz) for these."""
    path = tmp_path / "tagged.yaml"
    path.write_text(BAR.read_text().replace("name: bar_pulse", f"name: {text}"))
    with pytest.raises(CaseFileError, match=r"at line \d+, column \d+") as info:
        load_case(path)
    assert shown in str(info.value) and "\n" not in str(info.value)
    with pytest.raises(CaseFileError, match="a YAML value") as info:
        load_case(BAR, [f"name={text}"])
    assert shown in str(info.value)


def test_valid_tagged_scalars_are_still_read():
    assert parse_yaml("[!!int 1_000, !!float 2, !!bool yes, 1.5e3]") == [1000, 2.0, True, 1500.0]


def test_the_gpu_backend_is_refused_for_a_solver_other_than_explicit():
    """``solver.backend: gpu`` runs explicit solvers only: a modal case with it is one error
    naming the solver type (docs/gpu.md); an explicit case takes it."""
    with pytest.raises(CaseFileError, match="backend gpu runs explicit solvers only, not modal"):
        load_case(BAR, ["solver.type=modal", "solver.backend=gpu"])
    assert load_case(BAR, ["solver.backend=gpu"]).solver.backend == "gpu"
