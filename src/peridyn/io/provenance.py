"""Where a result comes from: package version, git commit, case file and its hash, command
line, machine and date, stored with every results file."""

from __future__ import annotations

import hashlib
import platform
import subprocess
import sys
from datetime import UTC, datetime
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path


def package_version() -> str:
    """The installed peridyn's version (``pyproject.toml``), "unknown" if not installed."""
    try:
        return version("peridyn")
    except PackageNotFoundError:
        return "unknown"


def provenance(case_path=None, argv=None, case=None) -> dict:
    """Package version, git commit, case file and its SHA-256, command line, host and date;
    with ``case``, also the validated case (overrides applied) as JSON, which
    ``peridyn plot`` uses to redraw a run."""
    info = {
        "peridyn_version": package_version(),
        "git_commit": _git_commit(),
        "command_line": " ".join(sys.argv if argv is None else argv),
        "python": platform.python_version(),
        "machine": platform.platform(),
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
    }
    if case_path is not None:
        data = Path(case_path).read_bytes()
        info["case_file"] = str(case_path)
        info["case_sha256"] = hashlib.sha256(data).hexdigest()
        info["case_text"] = data.decode("utf-8", errors="replace")
    if case is not None:
        info["case_json"] = case.model_dump_json()
    return info


def _git_commit() -> str:
    try:
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"],
            cwd=Path(__file__).parent,
            capture_output=True,
            text=True,
            timeout=5,
            check=False,
        )
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return out.stdout.strip() or "unknown"
