"""peridyn validate CASE.yaml: check a case file (and build its body) without running."""

from __future__ import annotations

from pathlib import Path

from peridyn.cli.options import add_case_arguments, add_common_flags
from peridyn.io.case import load_case


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
    """Validate; with --build also construct the discretisation and check the time step."""
    case = load_case(args.case, args.overrides)
    summary = {"case": case.name, "valid": True}
    if args.build:
        from peridyn.jobs.build import build
        from peridyn.solvers import ExplicitSolver

        setup = build(case, Path(args.case).parent)
        summary.update(points=setup.body.n_points, bonds=setup.bonds.n_bonds)
        if case.solver.type == "explicit":
            solver = ExplicitSolver(setup.model, setup.loading, dt=case.solver.dt, safety=case.solver.safety)
            summary.update(dt_s=solver.dt, stable_dt_s=solver.stable_dt)
    if not args.json:
        print(
            f"{args.case}: valid"
            + "".join(f", {k} {v}" for k, v in summary.items() if k not in ("case", "valid"))
        )
    return summary
