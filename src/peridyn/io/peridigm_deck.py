"""Peridigm input decks in: the XML form (a Teuchos ``<ParameterList>`` of typed
``<Parameter name type value>``) and the YAML form (a root ``Peridigm:`` mapping), read into
one nested dict of the deck's parameters (``read_deck``).

XML types: ``string``, ``double``, ``int``, ``bool`` (``true``/``false``, any case); a
``<ParameterList name>`` is a nested dict. A list given twice in one list, an unknown
type or a value that does not read as its type is a ``CaseFileError`` naming the parameter; a
parameter repeated in its list must repeat its value (Peridigm's own decks do so).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import yaml

from peridyn.errors import CaseFileError
from peridyn.io.case import parse_yaml, yaml_problem
from peridyn.io.text_file import read_input_text

#: Suffixes of the XML deck form (any other deck is read as YAML).
XML_SUFFIXES = (".xml",)


def _bool(text: str) -> bool:
    low = text.strip().lower()
    if low not in ("true", "false"):
        raise ValueError(text)
    return low == "true"


#: Teuchos parameter types read, with their converters.
XML_TYPES = {"string": str, "double": float, "int": int, "bool": _bool}


def is_peridigm_deck(path) -> bool:
    """True for a file whose root is a ``<ParameterList>`` (XML) or a ``Peridigm:`` mapping (YAML)."""
    path = Path(path)
    try:
        text = read_input_text(path, "Peridigm deck")
    except CaseFileError:  # not a readable text file: load_case says why
        return False
    if path.suffix.lower() in XML_SUFFIXES:
        return "<ParameterList" in text
    head = [line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")]
    return bool(head) and head[0].rstrip() == "Peridigm:"


def read_deck(path) -> dict:
    """The parameters of a Peridigm deck as a nested dict (name -> value or dict).

    Raises
    ------
    CaseFileError
        An unreadable file, malformed XML or YAML, or a parameter that does not read as its type.
    """
    path = Path(path)
    text = read_input_text(path, "Peridigm deck (.xml or .yaml)")
    if path.suffix.lower() in XML_SUFFIXES:
        return _read_xml(text, str(path))
    try:
        raw = parse_yaml(text)
    except yaml.YAMLError as exc:
        raise CaseFileError(str(path), "<file>", None, f"valid YAML ({yaml_problem(exc)})") from None
    if not isinstance(raw, dict) or set(raw) != {"Peridigm"} or not isinstance(raw["Peridigm"], dict):
        raise CaseFileError(str(path), "<root>", None, "one mapping 'Peridigm:' holding the deck")
    return raw["Peridigm"]


def _read_xml(text: str, source: str) -> dict:
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise CaseFileError(source, "<file>", None, f"well-formed XML ({exc})") from None
    if root.tag != "ParameterList":
        raise CaseFileError(source, "<root>", root.tag, "a <ParameterList> root element")
    return _parameter_list(root, source, "")


def _parameter_list(element, source: str, where: str) -> dict:
    out = {}
    for child in element:
        name = child.get("name")
        key = f"{where}.{name}" if where else str(name)
        if child.tag not in ("Parameter", "ParameterList"):
            raise CaseFileError(source, key, child.tag, "a <Parameter> or <ParameterList> element")
        if name is None:
            raise CaseFileError(source, where or "<root>", child.tag, "a name attribute on every element")
        if child.tag == "ParameterList":
            if name in out:
                raise CaseFileError(source, key, None, "a list given once in its list", has_value=False)
            out[name] = _parameter_list(child, source, key)
            continue
        kind, value = child.get("type"), child.get("value")
        if kind not in XML_TYPES:
            raise CaseFileError(source, f"{key} (type)", kind, f"one of the types {sorted(XML_TYPES)}")
        if value is None:
            raise CaseFileError(source, key, None, "a value attribute", has_value=False)
        try:
            parsed = XML_TYPES[kind](value)
        except ValueError:
            raise CaseFileError(source, key, value, f"a value of type {kind}") from None
        if name in out and out[name] != parsed:  # Peridigm's decks repeat some, with one value
            raise CaseFileError(source, key, value, f"the value it has above ({out[name]!r})")
        out[name] = parsed
    return out
