"""Sphinx extension: the case-file reference, written from the case schema.

At ``builder-inited`` it writes ``docs/case-reference.md``: every key of every section of a case
file with its type, unit, default and description (``peridyn.io.case_schema.reference_rows``,
from the pydantic models' field descriptions), so the page can never disagree with the program.
"""

from __future__ import annotations

from pathlib import Path

INTRO = """# Case-file reference

Every key of a case file, section by section: its type, unit (SI), default ("required" when it
has none) and meaning. A key shown as `<name>` is one you name (a material, a node set, a
sensor); `[]` marks the items of a list. The [user guide](user-guide.md#case-files) shows whole
case files; `peridyn validate CASE.yaml` checks one.

The same schema, as JSON for editors: `peridyn schema -o case.schema.json`, then put
`# yaml-language-server: $schema=case.schema.json` as the first line of a case file, and an
editor with a YAML language server (VS Code's YAML extension, for one) checks and completes it.
"""


def write_reference(app) -> None:
    from peridyn.io.case_schema import reference_rows

    lines = [INTRO]
    for section, rows in reference_rows().items():
        lines += ["", f"## `{section}`" if section else "## Top level", ""]
        lines += ["| key | type | unit | default | description |", "|---|---|---|---|---|"]
        for row in rows:
            cells = [f"`{row.path}`", row.type, row.unit or "-", f"`{row.default}`", row.description]
            lines.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    path = Path(app.srcdir) / "case-reference.md"
    text = "\n".join(lines) + "\n"
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def _cell(text: str) -> str:
    """A table cell: pipes escaped, ``*`` kept literal outside code."""
    return text.replace("|", "\\|")


def setup(app):
    app.connect("builder-inited", write_reference)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
