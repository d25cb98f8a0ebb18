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


def check_materials(case, body) -> None:
    """Refuse, as the model's construction in a run would, a material parameter the material
    cannot take on ``body`` (a PMB material's nu: ``Model.check_nu``), naming its key."""
    from peridyn.errors import CaseFileError, InputError
    from peridyn.physics.materials.registry import model_class

    for key, material in case.block_materials().items():
        key = key if key == "material" else f"materials.{key}"
        try:
            model_class(material.model).check_nu(material.nu, body.dim, body.plane)
        except InputError as exc:
            raise CaseFileError(case.name, f"{key}.nu", material.nu, str(exc).split(": ", 1)[1]) from None


def check_without_bonds(case, base_dir) -> dict:
    """The estimated points, bonds, peak bytes and (explicit) stable step of ``case``, after
    building its points, node sets, actuators and loads (no bonds); raises on any problem."""
    from types import SimpleNamespace

    import numpy as np

    from peridyn.errors import CaseFileError
    from peridyn.jobs.run import explicit_damping, step_count
    from peridyn.setup.build import add_actuators, build_body, build_loading, check_loading, check_placements
    from peridyn.setup.estimate import check_memory
    from peridyn.setup.run_checks import check_run_plan
    from peridyn.setup.stable_step import estimated_stable_step
    from peridyn.solvers.explicit import damped_stable_step

    est = check_memory(case, None, base_dir)
    body = build_body(case, base_dir)
    check_placements(case, body)
    check_materials(case, body)
    body, actuation = add_actuators(case, body)
    loading = build_loading(case, body, actuation)
    check_loading(case, loading)
    if case.solver.type == "modal":
        from peridyn.setup.eigensolver import check_mode_count

        check_mode_count(case, body.dim, bool(loading.constrained.any()))
    found = {"points": est.points, "estimated_bonds": est.bonds, "estimated_peak_bytes": est.peak_bytes}
    found["storage"] = est.storage
    if case.solver.type == "explicit":
        damping = float(np.max(explicit_damping(case, body)))
        stable = damped_stable_step(estimated_stable_step(case, base_dir), damping)
        if case.solver.dt is not None and case.solver.dt > stable:
            raise CaseFileError(
                case.name,
                "solver.dt",
                case.solver.dt,
                f"at most the estimated stable step {stable:.4g} s (validate --build gives the "
                "model's own bound), or leave dt unset",
            )
        dt = case.solver.dt if case.solver.dt is not None else case.solver.safety * stable
        check_run_plan(case, dt, step_count(case, SimpleNamespace(dt=dt)))
        found["estimated_stable_dt_s"] = stable
    return found
