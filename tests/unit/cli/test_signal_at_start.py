"""SIGTERM or SIGHUP while a command starts (before a job notes signals at its safe points)
killed the process with no word: now one line and 128 + the signal."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
#: ``peridyn validate`` of a shipped case, the signal sent to itself as the parser is built.
SIGNALLED_START = """
import os, signal, sys
import peridyn.cli as cli

real = cli.build_parser


def signalled():
    os.kill(os.getpid(), getattr(signal, sys.argv[1]))
    return real()


cli.build_parser = signalled
sys.exit(cli.main(["validate", "cases/bar_pulse.yaml"]))
"""


@pytest.mark.parametrize(("name", "status"), [("SIGHUP", 129), ("SIGTERM", 143)])
def test_a_signal_while_a_command_starts_is_one_line_and_its_status(name, status):
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    done = subprocess.run(
        [sys.executable, "-c", SIGNALLED_START, name],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == status, (done.returncode, done.stderr)
    assert "Traceback" not in done.stderr
    assert done.stderr.strip().splitlines()[-1] == f"peridyn: interrupted ({name}) while starting"


#: A command run as the program (no argv given, as the console script runs it), then a stop
#: signal sent to itself while the interpreter would be closing down.
SIGNALLED_EXIT = """
import os, signal, sys
import peridyn.cli as cli

sys.argv = ["peridyn", "validate", "cases/bar_pulse.yaml"]
status = cli.main()
os.kill(os.getpid(), signal.SIGNAL_NAME)
sys.exit(status)
"""


@pytest.mark.parametrize("name", ["SIGHUP", "SIGTERM"])
def test_a_signal_after_a_command_ends_leaves_its_exit_status(name):
    """A stop signal after the command has finished (the interpreter closing its libraries, a
    second or so after a complete run) killed the process, exit -1 after a complete run (the
    signal fuzz campaign, seed 2): the command's own status stands."""
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    script = SIGNALLED_EXIT.replace("SIGNAL_NAME", name)
    done = subprocess.run([sys.executable, "-c", script], cwd=ROOT, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
