"""The checks of a case before anything of its size is allocated: its memory estimate and, on
its points, node sets, actuators and loads (no bonds yet), its placements, material
parameters, loads, the modal modes asked and the explicit time step against its estimate
(``check_without_bonds``: what ``peridyn validate`` reports). ``run_case``, the fatigue job and
the command line call ``check_memory`` before they build."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from peridyn.errors import CaseFileError, InputError
from peridyn.physics.materials.registry import model_class
from peridyn.setup.build import add_actuators, build_body, build_loading, check_loading, check_placements
from peridyn.setup.eigensolver import check_mode_count
from peridyn.setup.estimate import check_memory
from peridyn.setup.run_checks import check_run_plan
from peridyn.setup.solver_choice import explicit_damping, step_count
from peridyn.setup.stable_step import estimated_stable_step
from peridyn.solvers.explicit import damped_stable_step


def check_materials(case, body) -> None:
    """Refuse, as the model's construction in a run would, a material parameter the material
    cannot take on ``body`` (a PMB material's nu: ``Model.check_nu``), naming its key."""
    for key, material in case.block_materials().items():
        key = key if key == "material" else f"materials.{key}"
        try:
            model_class(material.model).check_nu(material.nu, body.dim, body.plane)
        except InputError as exc:
            raise CaseFileError(case.name, f"{key}.nu", material.nu, str(exc).split(": ", 1)[1]) from None


def check_without_bonds(case, base_dir) -> dict:
    """The estimated points, bonds, peak bytes and (explicit) stable step of ``case``, after
    building its points, node sets, actuators and loads (no bonds); raises on any problem."""
    est = check_memory(case, None, base_dir)
    body = build_body(case, base_dir)
    check_placements(case, body)
    check_materials(case, body)
    body, actuation = add_actuators(case, body)
    loading = build_loading(case, body, actuation)
    check_loading(case, loading)
    if case.solver.type == "modal":
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
