"""Sphinx extension: one page per ``peridyn`` command, written from its argument parser.

At ``builder-inited`` it writes ``docs/cli/<command>.md`` (its description and ``--help``) and
``docs/cli/index.md``, so that the pages can never disagree with the program.
"""

from __future__ import annotations

from pathlib import Path


def write_pages(app) -> None:
    from peridyn.cli import build_parser

    parser = build_parser()
    out = Path(app.srcdir) / "cli"
    out.mkdir(exist_ok=True)
    commands = parser.subcommands()
    index = [
        "# Command line",
        "",
        "Every command prints one JSON object on stdout with `--json`, and a failure is one line on",
        "stderr with a non-zero exit status (see the user guide). One page per command:",
        "",
        "```{toctree}",
        ":maxdepth: 1",
        "",
        *commands,
        "```",
        "",
    ]
    _write(out / "index.md", "\n".join(index))
    for name, sub in commands.items():
        summary = sub.description or sub.format_usage()
        text = f"# peridyn {name}\n\n{summary}\n\n```text\n{sub.format_help()}```\n"
        _write(out / f"{name}.md", text)


def _write(path: Path, text: str) -> None:
    """Write ``text`` unless the file already holds it (no rebuild of unchanged pages)."""
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def setup(app):
    app.connect("builder-inited", write_pages)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
