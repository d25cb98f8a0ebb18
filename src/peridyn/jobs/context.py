"""What one run of a case carries through its steps: the case, where it writes, how it was
started and how it reports progress (``RunContext``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from peridyn.io.case import Case
from peridyn.io.provenance import provenance
from peridyn.setup.recording import RESULTS


@dataclass(frozen=True)
class RunContext:
    """The arguments of one ``run_case`` that its solve, recording and finish share.

    Attributes
    ----------
    case : Case
        The validated case (after ``--set``).
    out : Path
        The output folder.
    case_path : path or None
        The case file, recorded in the provenance (None: a case made in Python).
    start : float
        ``time.perf_counter()`` when the run started, s.
    progress : callable(total) -> bar with update(n) and close(), or None
    checkpoint_every : int or None
        Steps between checkpoints (``<out>/checkpoint.h5``); None: none asked.
    restart : bool
        Continue from ``<out>/checkpoint.h5``.
    command : str or None
        The command line that started the run, for the resume hint of ``Interrupted``.
    """

    case: Case
    out: Path
    case_path: object = None
    start: float = 0.0
    progress: object = None
    checkpoint_every: int | None = None
    restart: bool = False
    command: str | None = None

    @property
    def results(self) -> Path:
        """The run's results file, ``<out>/results.h5``."""
        return self.out / RESULTS

    def provenance(self) -> dict:
        """The provenance of the run's files: the case, its file, the package and machine."""
        return provenance(self.case_path, case=self.case)
