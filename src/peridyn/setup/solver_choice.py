"""The solver of a built case: the time stepper of an explicit or Newmark run (its step,
damping and step count), the equilibrium solve of a static run (one process or MPI ranks), and
what an MPI run refuses before anything is built."""

from __future__ import annotations

import functools
import warnings

import numpy as np

from peridyn.discretization.body import Body
from peridyn.errors import CaseFileError, InputError
from peridyn.io.case import Case
from peridyn.physics.absorbing import layer_damping
from peridyn.setup.build import Setup
from peridyn.setup.peridigm_step import peridigm_stable_step
from peridyn.solvers import ExplicitSolver, relax
from peridyn.solvers.explicit_gpu import GPUExplicitSolver


def check_parallel(case: Case) -> None:
    """Refuse what an MPI run cannot do yet."""
    if case.solver.type not in ("explicit", "modal", "static"):
        raise InputError(
            "an MPI run (mpiexec -n N) is an explicit, static or modal run for now, not a "
            f"{case.solver.type} run"
        )
    if case.solver.type == "modal" and case.solver.eigensolver == "shift-invert":
        raise CaseFileError(case.name, "solver.eigensolver", "shift-invert", "lobpcg or auto in an MPI run")


def step_count(case: Case, solver) -> int:
    """Time steps of a time-stepping run: ``solver.steps``, or ``solver.time`` in steps of dt
    (ceil(time / dt), or floor(time / dt) with ``solver.step_rule: peridigm``)."""
    s = case.solver
    if s.steps is not None:
        return s.steps
    if s.step_rule == "peridigm":  # Peridigm's floor((final - initial) / dt)
        steps = int(np.floor(s.time / solver.dt))
        if steps < 1:
            raise CaseFileError(
                case.name, "solver.time", s.time, f"at least one step of dt = {solver.dt:.4g} s"
            )
        return steps
    return int(np.ceil(s.time / solver.dt - 1e-9))


def explicit_damping(case: Case, body: Body):
    """``solver.damping`` (1/s), plus the absorbing layers' per-point damping when the case
    has them: a number or an (n_points,) array for ``ExplicitSolver``."""
    if case.absorbing is None:
        return case.solver.damping
    a = case.absorbing
    try:
        return case.solver.damping + layer_damping(body.points, a.width, a.damping, a.faces)
    except InputError as exc:
        raise CaseFileError(case.name, "absorbing", a.model_dump(), str(exc)) from None


def time_stepper(case, setup):
    """The solver of an explicit or newmark case (velocity Verlet or implicit Newmark)."""
    if case.solver.type == "newmark":
        return newmark_solver(case, setup)
    s = case.solver
    damping = setup.domain.from_root(explicit_damping, case, setup.whole_body)
    if np.ndim(damping):  # per point: the rank's points
        damping = damping[setup.domain.global_ids]
    peridigm_dt = s.dt is None and s.step_rule == "peridigm"
    solver_class = GPUExplicitSolver if s.backend == "gpu" else ExplicitSolver
    return solver_class(
        setup.model,
        setup.loading,
        dt=s.safety * peridigm_stable_step(case, setup) if peridigm_dt else s.dt,
        safety=s.safety,
        damping=damping,
        damage=setup.damage,
        contact=setup.contact,
        domain=setup.domain,
        prescribed_velocity=s.prescribed_velocity,
        **({"arithmetic": "peridigm"} if _peridigm_arithmetic(case, setup) else {}),
        **({"beyond_bound": "warn"} if peridigm_dt and s.backend == "cpu" else {}),  # as Peridigm runs it
    )


def _peridigm_arithmetic(case, setup) -> bool:
    """True for ``solver.arithmetic: peridigm`` on the CPU in one process, where it runs; on
    the GPU backend or under MPI the run takes peridyn's order of operations, with a warning
    (the results then differ from Peridigm's in their last bits, docs/peridigm.md)."""
    s = case.solver
    if s.arithmetic != "peridigm":
        return False
    if s.backend == "gpu" or setup.domain.halo is not None:
        warnings.warn(
            f"{case.name}: solver.arithmetic peridigm runs on the cpu backend in one process: this "
            "run takes peridyn's order of operations (its last bits differ from Peridigm's)",
            stacklevel=3,
        )
        return False
    return True


def newmark_solver(case, setup):
    """The implicit Newmark solver of a ``newmark`` case."""
    from peridyn.solvers.newmark import NewmarkSolver

    s = case.solver
    return NewmarkSolver(
        setup.model,
        setup.loading,
        dt=s.dt,
        tolerance=s.displacement_tolerance,
        max_iterations=s.newton_iterations,
        damping=s.damping,
        damage=setup.damage,
        linear_solver=s.linear_solver,
        residual_tolerance=s.absolute_tolerance,
        initial_acceleration=s.initial_acceleration,
    )


def static_solver(setup: Setup):
    """The solve of each load step of a static run, called as ``relax``: ``relax`` itself in one
    process; under MPI ``relax`` on the rank's part (the serial iterates bit for bit) when bonds
    break or contact acts, else modified Newton with CG (``distributed_static``)."""
    d = setup.domain
    if d.size == 1:
        return relax
    if setup.damage is not None or setup.contact is not None:
        return functools.partial(relax, domain=d)
    return distributed_static(setup)


def distributed_static(setup: Setup):
    """``relax``'s stand-in under MPI for a linear-elastic body (no damage, no contact): modified
    Newton with CG (``solvers.distributed_static``) on the rank's dofs, its preconditioner built
    once for every load step."""
    from peridyn.linalg.distributed import RankDofs, rank_preconditioner
    from peridyn.solvers.distributed_static import distributed_equilibrium

    dofs = RankDofs(setup.model, setup.domain, setup.loading.constrained)
    precond = rank_preconditioner(dofs)

    def solve(model, loading, time, u0, tolerance, max_iterations, damage, contact):
        return distributed_equilibrium(dofs, precond, loading, time, u0, tolerance, max_iterations)

    return solve
