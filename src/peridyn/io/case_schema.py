"""The case file's schema for people and editors: the JSON schema of :class:`peridyn.io.case.Case`
(every key with its type, default, description and ``unit``), the rows of the case-file reference
that the documentation generates from it, and the unit of a key path.

``peridyn schema`` prints the JSON schema; an editor with a YAML language server checks and
completes a case file that names it in its first line
(``# yaml-language-server: $schema=case.schema.json``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass

from peridyn.io.case import Case


def case_json_schema() -> dict:
    """The JSON schema (draft 2020-12) of a case file, ``unit`` on every key that has one."""
    schema = Case.model_json_schema()
    schema["title"] = "peridyn case file"
    return schema


@dataclass(frozen=True)
class KeyRow:
    """One key of the case-file reference: its dotted ``path`` (``<name>`` for a key the user
    names, ``[]`` for a list item), ``type`` in words, ``unit`` ("" without one), ``default`` as
    JSON text ("required" without one) and ``description``."""

    path: str
    type: str
    unit: str
    default: str
    description: str


def reference_rows() -> dict[str, list[KeyRow]]:
    """The keys of every section, by section path (``""`` the top level, ``"material"``,
    ``"output.lines.<name>"``, ...), in the order the schema gives them."""
    schema = case_json_schema()
    sections: dict[str, list[KeyRow]] = {}
    _walk(schema, schema, "", sections)
    return sections


def case_unit(path: str) -> str | None:
    """The unit of the case key ``path`` (``material.E``: Pa; ``materials.steel.density``:
    kg/m^3; list indices such as ``geometry.size[0]`` are ignored), None for a key without one
    or not in the schema."""
    wanted = path.split("[", 1)[0]
    for rows in reference_rows().values():
        for row in rows:
            if _matches(row.path, wanted):
                return row.unit or None
    return None


def _matches(pattern: str, path: str) -> bool:
    parts, given = pattern.replace("[]", "").split("."), path.split(".")
    return len(parts) == len(given) and all(
        p == g or p == "<name>" for p, g in zip(parts, given, strict=True)
    )


def _walk(schema: dict, node: dict, prefix: str, sections: dict) -> None:
    rows = sections.setdefault(prefix, [])
    required = set(node.get("required", ()))
    for key, prop in node.get("properties", {}).items():
        path = f"{prefix}.{key}" if prefix else key
        default = "required" if key in required else json.dumps(prop.get("default"))
        rows.append(
            KeyRow(path, _type(schema, prop), prop.get("unit", ""), default, prop.get("description", ""))
        )
        for suffix, section in _sections(schema, prop):
            _walk(schema, section, path + suffix, sections)


def _sections(schema: dict, prop: dict) -> list[tuple[str, dict]]:
    """The object schemas reached from a property: itself (""), its items ("[]") or its
    values (".<name>"), each once."""
    found = []
    for option in prop.get("anyOf", [prop]):
        for suffix, inner in (
            ("", option),
            ("[]", option.get("items")),
            (".<name>", option.get("additionalProperties")),
        ):
            if isinstance(inner, dict) and "$ref" in inner:
                target = _resolve(schema, inner)
                if "properties" in target and all(target is not t for _, t in found):
                    found.append((suffix, target))
    return found


def _resolve(schema: dict, node: dict) -> dict:
    return schema["$defs"][node["$ref"].rsplit("/", 1)[-1]] if "$ref" in node else node


def _type(schema: dict, prop: dict) -> str:
    """A property's type in words: ``number``, ``list of number``, ``one of "lu", "cg"``,
    ``Material`` (a section), joined with ``or``."""
    if "anyOf" in prop:
        words = [_type(schema, option) for option in prop["anyOf"]]
        return " or ".join(w for w in dict.fromkeys(words) if w != "null") + (
            " or null" if "null" in words else ""
        )
    if "$ref" in prop:
        return (
            prop["$ref"].rsplit("/", 1)[-1]
            if "properties" in _resolve(schema, prop)
            else _type(schema, _resolve(schema, prop))
        )
    if "enum" in prop or "const" in prop:
        return "one of " + ", ".join(json.dumps(v) for v in prop.get("enum", [prop.get("const")]))
    kind = prop.get("type", "any")
    if kind == "array":
        items = prop.get("items") or (prop.get("prefixItems") or [{}])[0]
        return f"list of {_type(schema, items)}"
    if kind == "object":
        values = prop.get("additionalProperties")
        return f"mapping of name to {_type(schema, values)}" if isinstance(values, dict) else "mapping"
    return kind
