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
