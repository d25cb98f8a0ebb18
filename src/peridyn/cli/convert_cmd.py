"""peridyn convert DECK: write the peridyn case file that a Peridigm input deck (.xml or .yaml)
translates to; peridyn run of that case gives the same results as peridyn run DECK
(docs/peridigm.md lists the deck features read and those refused). Written to a file (-o,
never over an existing file without --overwrite), the case names its mesh relative to the
file's folder; printed, by its absolute path."""

from __future__ import annotations

import sys
from pathlib import Path

import yaml

from peridyn.cli.errors import writing
from peridyn.cli.options import add_common_flags, add_output_flag
from peridyn.errors import CaseFileError, InputError
from peridyn.io.peridigm_case import convert_deck, relative_mesh
from peridyn.io.peridigm_deck import is_peridigm_deck


def register(sub) -> None:
    """Add the ``convert`` subcommand."""
    p = sub.add_parser("convert", help="translate a Peridigm deck to a case file", description=__doc__)
    p.add_argument("deck", help="Peridigm input deck (.xml or .yaml)")
    add_output_flag(p, "case file to write (default: print it on stdout)")
    p.add_argument(
        "--overwrite", action="store_true", help="replace the case file -o names (refused without it)"
    )
    add_common_flags(p)
    p.set_defaults(func=run)


def run(args) -> dict:
    """Translate the deck, check the case validates, write or print it."""
    from peridyn.io.case import validate_case

    if not is_peridigm_deck(args.deck):
        raise CaseFileError(
            args.deck, "<root>", None, "a Peridigm deck: a <ParameterList> or 'Peridigm:' root"
        )
    if args.output is not None and Path(args.output).exists() and not args.overwrite:
        raise InputError(f"-o {args.output!r} exists: pass --overwrite to replace it, or choose another file")
    raw = convert_deck(args.deck)
    validate_case(raw, args.deck)
    if args.output is not None:  # the mesh relative to the case file: they move together
        relative_mesh(raw, Path(args.output).parent)
    text = yaml.safe_dump(raw, sort_keys=False)
    if args.output is None:
        if not args.json:
            sys.stdout.write(text)
    else:
        with writing(args.output):
            Path(args.output).write_text(text, encoding="utf-8")
        if not args.json:
            print(f"case written to {args.output}", file=sys.stderr)
    return {"deck": args.deck, "case": raw}
