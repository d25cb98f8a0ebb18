"""peridyn examples DIR: copy the shipped examples (cases, sweeps, the gallery's scripts and
their inputs) into a new folder, to run and edit them outside the installation."""

from __future__ import annotations

from peridyn.cli.options import add_common_flags
from peridyn.errors import InputError


def register(sub) -> None:
    """Add the ``examples`` subcommand."""
    p = sub.add_parser("examples", help="copy the shipped cases, sweeps and gallery", description=__doc__)
    p.add_argument("directory", help="folder to create (it must not hold files yet)")
    add_common_flags(p)
    p.set_defaults(func=run)


def run(args) -> dict:
    """Copy the examples; print where they went and what to run first."""
    from peridyn.data.examples import copy_examples

    try:
        written = copy_examples(args.directory)
    except (FileExistsError, FileNotFoundError) as exc:
        raise InputError(str(exc)) from None
    folders = sorted({p.relative_to(args.directory).parts[0] for p in written})
    if not args.json:
        print(f"examples: {len(written)} files in {args.directory}/ ({', '.join(folders)})")
        print(f"try: cd {args.directory} && peridyn run cases/bar_pulse.yaml")
    return {"directory": str(args.directory), "files": len(written), "folders": folders}
