"""peridyn demo: run the small packaged demo case (a tone burst in a 3D plate) with plots."""

from __future__ import annotations

from importlib.resources import as_file, files

from peridyn.cli.options import add_common_flags, add_output_flag, add_overwrite_flag, add_progress_flags

DEMO_CASE = "demo_plate_burst.yaml"


def register(sub) -> None:
    """Add the ``demo`` subcommand."""
    p = sub.add_parser("demo", help="run the demo case and write its plots", description=__doc__)
    add_output_flag(p, "output folder (default: peridyn-out/demo)", default="peridyn-out/demo")
    add_progress_flags(p)
    add_common_flags(p)
    add_overwrite_flag(p)
    p.set_defaults(func=run)


def run(args) -> dict:
    """Run the demo through ``peridyn run``'s code path."""
    from argparse import Namespace

    from peridyn.cli import run_cmd

    with as_file(files("peridyn.data") / DEMO_CASE) as path:
        ns = Namespace(
            case=str(path),
            overrides=[],
            output=args.output,
            checkpoint_every=None,
            restart=False,
            progress=args.progress,
            overwrite=args.overwrite,
            json=args.json,
            command_line="",  # the demo cannot be restarted: no --restart hint
        )
        return run_cmd.run(ns)
