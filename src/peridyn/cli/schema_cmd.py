"""peridyn schema: print the JSON schema of a case file (every key with its type, default,
description and unit), for editors that check and complete YAML against a schema."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from peridyn.cli.errors import writing
from peridyn.cli.options import add_output_flag


def register(sub) -> None:
    """Add the ``schema`` subcommand."""
    p = sub.add_parser("schema", help="print the JSON schema of a case file", description=__doc__)
    add_output_flag(p, "write it to this file instead of stdout (e.g. case.schema.json)")
    p.set_defaults(func=run, json=False)


def run(args) -> dict:
    """Print (or write) the schema; the summary names where it went."""
    from peridyn.io.case_schema import case_json_schema

    text = json.dumps(case_json_schema(), indent=1) + "\n"
    if args.output is None:
        with writing("<stdout>"):
            sys.stdout.write(text)
        return {"output": None}
    with writing(args.output):
        Path(args.output).write_text(text)
    return {"output": args.output}
