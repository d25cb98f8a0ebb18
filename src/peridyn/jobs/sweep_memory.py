"""The memory a sweep needs, checked before any of its runs starts: the largest run's
estimated peak times the runs held at once (``check_sweep_memory``)."""

from __future__ import annotations

import numpy as np

from peridyn.discretization.geometry import memory_limit
from peridyn.errors import InputError
from peridyn.jobs.sweep_spec import Sweep
from peridyn.setup.estimate import estimate_case

#: The jobs whose memory a sweep estimates before it starts (``setup.estimate``), by command
#: (None: the case's solver type); bloch runs build no body of the case's size.
SWEEP_JOBS = {"run": None, "modal": "modal", "fatigue": "fatigue"}


def check_sweep_memory(sweep: Sweep, workers: int) -> None:
    """Refuse, before any run starts, a sweep whose ``workers`` runs at once would not fit in
    memory: the largest run's peak (``setup.estimate.estimate_case``) times the runs held at once,
    against ``geometry.memory_limit``.

    Raises
    ------
    InputError
        Naming the largest run, its peak, the runs at once and the bytes available.
    """
    if sweep.spec.command not in SWEEP_JOBS or not sweep.runs:
        return
    job = SWEEP_JOBS[sweep.spec.command]
    peaks = [estimate_case(run.case, sweep.base.parent, job).peak_bytes for run in sweep.runs]
    largest = int(np.argmax(peaks))
    at_once = min(workers, len(sweep.runs))
    needed, available = peaks[largest] * at_once, memory_limit()
    if needed > available:
        run = sweep.runs[largest]
        raise InputError(
            f"{sweep.path}: run {run.index} ({run.parameters}) needs ~{peaks[largest] / 1e9:.3g} GB; "
            f"{at_once} at once need ~{needed / 1e9:.3g} GB, more than the {available / 1e9:.3g} GB "
            "available: fewer --workers, or a coarser discretization.spacing"
        )
