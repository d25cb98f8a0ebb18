"""The identity of a validated case: its JSON text and SHA-256, which a checkpoint records (a
restart must continue the same case) and a sweep names its runs by."""

from __future__ import annotations

import hashlib
import json

from peridyn.io.case import Case


def case_identity(case: Case, run_length: bool = False) -> tuple[str, str]:
    """The validated case (after ``--set``) as JSON text without its output folder and, unless
    ``run_length`` (a sweep's runs differ by it), without its run length (``solver.steps``,
    ``solver.time``: a restart may extend a run), and the SHA-256 of that text."""
    data = case.model_dump(mode="json")
    if not run_length:
        for key in ("steps", "time"):
            data["solver"].pop(key, None)
    data["output"].pop("directory", None)
    text = json.dumps(data, sort_keys=True)
    return text, hashlib.sha256(text.encode()).hexdigest()
