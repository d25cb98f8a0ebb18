"""peridyn validate CASE.yaml: check a case file or a Peridigm deck (and build its body) without
running."""

from __future__ import annotations

from pathlib import Path

from peridyn.cli.options import add_case_arguments, add_common_flags
from peridyn.io.peridigm_case import load_case_or_deck


def register(sub) -> None:
    """Add the ``validate`` subcommand."""
    p = sub.add_parser("validate", help="check a case file", description=__doc__)
    add_case_arguments(p)
    p.add_argument(
        "--build",
        action="store_true",
        help="also build the body, bonds and model (finds isolated points, bad sets)",
    )
    add_common_flags(p)
    p.set_defaults(func=run)


def run(args) -> dict:
    """Validate all that needs no bonds (memory, regions, placements, loads, signals, the
    time step against its estimate); with --build also construct the bonds and model and
    check the time step against the model's own bound."""
    from peridyn.setup.checks import check_without_bonds

    case = load_case_or_deck(args.case, args.overrides)
    summary = {"case": case.name, "valid": True, **check_without_bonds(case, Path(args.case).parent)}
    if args.build:
        from peridyn.setup.build import build
        from peridyn.solvers import ExplicitSolver

        setup = build(case, Path(args.case).parent)
        summary.update(points=setup.body.n_points, bonds=setup.bonds.n_bonds)
        if case.solver.type == "explicit":
            solver = ExplicitSolver(setup.model, setup.loading, dt=case.solver.dt, safety=case.solver.safety)
            summary.update(dt_s=solver.dt, stable_dt_s=solver.stable_dt)
    if not args.json:
        print(
            f"{args.case}: valid"
            + "".join(
                f", {k} {v:.4g}" if isinstance(v, float) else f", {k} {v}"
                for k, v in summary.items()
                if k not in ("case", "valid")
            )
        )
    return summary
