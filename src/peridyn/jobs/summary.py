"""The keys every job summary shares (run, modal, fatigue, study, sweep and monitor).

The schema of the summaries, these keys and each kind's own, is the table of docs/user-guide.md,
"Summaries and results files"; ``peridyn.io.hdf5.SCHEMA_VERSION`` numbers it.
"""

from __future__ import annotations

import resource
import time
from pathlib import Path

from peridyn.io.hdf5 import SCHEMA_VERSION
from peridyn.physics.damage import damage_field

#: The job kinds: the ``kind`` of their summaries.
KINDS = ("run", "modal", "fatigue", "study", "sweep", "monitor")


def finish_summary(summary: dict, kind: str, out: Path, start: float, plots=()) -> dict:
    """Add the common keys to a job's ``summary`` (in place) and return it.

    Parameters
    ----------
    summary : dict
        The job's own keys.
    kind : one of :data:`KINDS`
    out : Path
        The job's output folder.
    start : float
        ``time.perf_counter()`` when the job started, s.
    plots : sequence of path
        The figures the job drew (none when ``output.plots`` is off).
    """
    if kind not in KINDS:
        raise ValueError(f"summary kind must be one of {KINDS}, got {kind!r}")
    summary.update(
        schema_version=SCHEMA_VERSION,
        kind=kind,
        output_dir=str(out),
        plots=[str(p) for p in plots],
        seconds=time.perf_counter() - start,
        peak_memory_bytes=peak_memory_bytes(),
    )
    return summary


def peak_memory_bytes() -> int:
    """Peak resident memory of this process so far, bytes (Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def base_summary(setup) -> dict:
    """Points, directed bonds, broken bonds and largest damage of the whole body of a built case
    ``setup`` (``setup.build.Setup``; collective): the first keys of a run's summary."""
    d = setup.domain
    n = d.n_owned
    phi = damage_field(setup.model)
    bonds, broken = setup.bonds.owned_bond_counts(n)  # bond lists or lattice
    return {
        "points": setup.whole_body.n_points,
        "bonds": d.count(bonds),
        "broken_bonds": d.count(broken),
        "max_damage": float(d.max(phi[:n].max())),
        "storage": setup.storage,
    }
