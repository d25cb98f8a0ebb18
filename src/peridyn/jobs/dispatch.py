"""The one dispatch from a job's name to the function that runs it: ``peridyn run``, ``peridyn
modal``, ``peridyn fatigue`` and the runs of a sweep (its ``command``) all start their job here.
Within a run, the case's ``solver.type`` picks the solver (``jobs.run``)."""

from __future__ import annotations

from peridyn.errors import InputError

#: The jobs of a case, by name: ``run`` (the case's solver: explicit, static, Newton, Newmark or
#: modal), ``modal`` (a run whose case has ``solver.type: modal``), ``fatigue``.
JOBS = ("run", "modal", "fatigue")


def job_function(job: str):
    """The function that runs ``job`` (one of :data:`JOBS`), its module imported on first use:
    ``jobs.run.run_case`` for run and modal, ``jobs.fatigue.run_fatigue_case`` for fatigue.

    Raises
    ------
    InputError
        An unknown job.
    """
    if job == "fatigue":
        from peridyn.jobs.fatigue import run_fatigue_case

        return run_fatigue_case
    if job not in JOBS:
        raise InputError(f"a job is one of {', '.join(JOBS)}, not {job!r}")
    from peridyn.jobs.run import run_case

    return run_case


def run_job(job: str, case, output_dir=None, **options) -> dict:
    """Run the validated ``case`` as ``job`` (one of :data:`JOBS`) into ``output_dir``; returns
    its summary. ``options``: the keyword arguments of the job's function (``job_function``).

    Raises
    ------
    InputError
        An unknown job, or a modal job of a case whose solver is not modal.
    """
    run = job_function(job)
    if job == "modal" and case.solver.type != "modal":
        raise InputError(f"a modal job needs solver.type: modal, not {case.solver.type!r}")
    return run(case, output_dir, **options)
