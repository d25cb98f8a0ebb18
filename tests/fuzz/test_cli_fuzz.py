"""Fuzzing the command line proves "no traceback, no lost data" (issue 17, item 9).

Shipped cases are mutated (tests/fuzz/fuzz_mutations.py: keys deleted, misspelt, retyped, set to
NaN, infinities, huge and tiny values; YAML tags, alias bombs, duplicate keys, broken bytes, odd
files) and so are the command lines (``--set``, numeric options, unknown options, output folders
that cannot be used). Every outcome must be what docs/user-guide.md ("Errors") promises:

- ``peridyn.cli.main`` returns an exit status and never raises;
- success is status 0; a failure is a non-zero status and one error line on stderr,
  ``peridyn[ COMMAND]: error: ...``, never a Python traceback nor the last-resort
  "internal error" of ``peridyn.cli.errors.describe`` (an exception no check anticipated);
- with ``--json`` stdout holds exactly one JSON object (with an "error" key on failure);
  without it a failure leaves stdout empty;
- an earlier run's folder (a real finished run, made first) and a file in the way keep every
  byte: nothing aimed at them without ``--overwrite``/``--restart`` changes them.

``validate`` examples take any shipped case (coarsened to at most 150 000 points so that a valid
mutation is checked in a fraction of a second); ``run`` and ``modal`` examples take a 160-point bar
and are aimed at output folders they must refuse, so no example runs a simulation. The default
test draws 300 examples, the slow one 2 500, both derandomized (the same examples on every run);
a few examples also go through a real ``python -m peridyn`` process.
"""

from __future__ import annotations

import copy
import hashlib
import io
import json
import os
import re
import subprocess
import sys
from collections import Counter
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import pytest
from fuzz_mutations import ROOT, SHIPPED, Example, base_case, dump, examples
from hypothesis import HealthCheck, given, note, settings

from peridyn.cli import main
from peridyn.io.case import validate_case
from peridyn.setup.estimate import estimate_case

#: ``validate`` examples start from the shipped cases coarsened to at most this many points.
MAX_BASE_POINTS = 150_000
#: The error line: the (sub)command, "error:" and a message.
ERROR_LINE = re.compile(r"peridyn(?: [a-z]+)?: error: \S")
#: describe()'s message for an exception no check anticipated (peridyn.cli.errors).
INTERNAL = "internal error: "


def coarsened(raw: dict) -> dict:
    """``raw`` with its spacing doubled until the estimated points are at most MAX_BASE_POINTS."""
    raw = copy.deepcopy(raw)
    while estimate_case(validate_case(raw)).points > MAX_BASE_POINTS:
        d = raw["discretization"]
        d["spacing"] = [2 * s for s in d["spacing"]] if isinstance(d["spacing"], list) else 2 * d["spacing"]
    return raw


@pytest.fixture(scope="module")
def bases() -> dict[str, dict]:
    """Every shipped case, coarsened (name -> mapping)."""
    return {path.stem: coarsened(base_case(path)) for path in SHIPPED}


@pytest.fixture(scope="module")
def tiny() -> dict[str, dict]:
    return {"bar_pulse_tiny": base_case(ROOT / "cases" / "bar_pulse.yaml", tiny=True)}


def _call(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        status = main(argv)
    assert isinstance(status, int), f"main returned {status!r}"
    return status, out.getvalue(), err.getvalue()


def _fingerprint(paths: list[Path]) -> dict[str, str]:
    """sha256 of every file under ``paths`` (files or folders), by path; not ``run.log``, the
    folder's journal, to which every job, a refused one too, appends (docs/user-guide.md)."""
    files = [
        f
        for p in paths
        for f in ([p] if p.is_file() else sorted(p.rglob("*")))
        if f.is_file() and f.name != "run.log"
    ]
    return {str(f): hashlib.sha256(f.read_bytes()).hexdigest() for f in files}


@pytest.fixture(scope="module")
def workspace(tmp_path_factory, tiny):
    """The paths examples use, with a real finished run of the tiny case in ``finished`` (with
    its checkpoint, so that ``--restart`` examples meet one)."""
    root = tmp_path_factory.mktemp("fuzz")
    case = root / "tiny.yaml"
    case.write_bytes(dump(tiny["bar_pulse_tiny"]))
    finished = root / "finished"
    status, _, err = _call(
        ["run", str(case), "-o", str(finished), "--checkpoint-every", "2", "--no-progress"]
    )
    assert status == 0, err
    blocker = root / "blocker"
    blocker.write_text("a file where a folder is expected\n")
    (root / "folder").mkdir()
    paths = {
        "finished": str(finished),
        "file": str(blocker),
        "below_file": str(blocker / "out"),
        "uncreatable": "/proc/peridyn-fuzz/out",
        "missing": str(root / "missing.yaml"),
        "folder": str(root / "folder"),
        "devnull": os.devnull,
        "empty_name": "",
    }
    return root, paths, [finished, blocker]


def check_outcome(status: int, out: str, err: str, as_json: bool) -> str:
    """Assert the promised shape of an outcome; returns "ok" or "error"."""
    assert "Traceback" not in err, err
    lines = err.splitlines()
    # every stderr line is one of peridyn's own: the run header, a one-line warning, the error
    assert all(line.startswith("peridyn") for line in lines), err
    if status == 0:
        assert not any(ERROR_LINE.match(line) for line in lines), err
        if as_json:
            assert isinstance(json.loads(out), dict)
        return "ok"
    assert lines, f"status {status} with nothing on stderr"
    assert ERROR_LINE.match(lines[-1]), lines[-1]
    assert INTERNAL not in lines[-1], lines[-1]
    assert sum(bool(ERROR_LINE.match(line)) for line in lines) == 1, err
    if as_json:
        assert out.count("\n") == 1, out
        obj = json.loads(out)
        assert isinstance(obj, dict) and obj["error"] and lines[-1].endswith(obj["error"]), (out, lines[-1])
    else:
        assert out == "", out
    return "error"


def fuzz(n_examples: int, bases, tiny, workspace, monkeypatch) -> Counter:
    """Run ``n_examples`` drawn examples in-process; the tally of their outcomes."""
    root, paths, protected = workspace
    before = _fingerprint(protected)
    case_file = root / "case.yaml"
    cwd = root / "cwd"
    cwd.mkdir(exist_ok=True)
    monkeypatch.chdir(cwd)  # a command that wrongly writes to the working folder is seen
    tally = Counter()

    @settings(
        max_examples=n_examples,
        deadline=None,
        derandomize=True,
        database=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
    )
    @given(example=examples(bases, tiny))
    def one(example: Example):
        if example.case_bytes is not None:
            case_file.write_bytes(example.case_bytes)
        argv = example.argv(case_file, paths)
        note(f"argv: {argv}\ndone: {example.done}")
        status, out, err = _call(argv)
        note(f"status {status}\nstdout: {out}\nstderr: {err}")
        outcome = check_outcome(status, out, err, example.as_json)
        tally["examples"] += 1
        tally[outcome] += 1
        tally[f"{' '.join(argv[:1] + [o for o in argv[2:3] if o == '--build'])}: {outcome}"] += 1
        assert _fingerprint(protected) == before, "an earlier run's files changed"
        assert not any(cwd.iterdir()), f"written to the working folder: {list(cwd.iterdir())}"

    one()
    print(
        f"\nfuzz: {tally['examples']} examples, {tally['ok']} succeeded, {tally['error']} errored "
        f"cleanly, 0 tracebacks, 0 internal errors; {len(before)} files of an earlier run unchanged\n"
        + ", ".join(f"{k} {v}" for k, v in sorted(tally.items()) if ":" in k)
    )
    return tally


def test_fuzzed_cases_and_command_lines_end_cleanly(bases, tiny, workspace, monkeypatch):
    """300 examples (about 15 s on 2 cores)."""
    tally = fuzz(300, bases, tiny, workspace, monkeypatch)
    assert tally["examples"] == tally["ok"] + tally["error"] > 0


@pytest.mark.slow
def test_fuzzed_cases_and_command_lines_end_cleanly_many(bases, tiny, workspace, monkeypatch):
    """2 500 examples (issue 17 acceptance: >= 2000)."""
    tally = fuzz(2500, bases, tiny, workspace, monkeypatch)
    assert tally["examples"] == tally["ok"] + tally["error"] >= 2000


def _in_a_process(argv: list[str], cwd: Path) -> tuple[int, str, str]:
    """``python -m peridyn ARGV`` in a new interpreter that imports this checkout."""
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT / "src"), os.environ.get("PYTHONPATH")])),
    }
    done = subprocess.run(
        [sys.executable, "-m", "peridyn", *argv],
        capture_output=True,
        cwd=cwd,
        env=env,
        timeout=300,
        encoding="utf-8",
        errors="replace",
    )
    return done.returncode, done.stdout, done.stderr


def fuzz_processes(n_examples: int, bases, tiny, workspace, monkeypatch) -> int:
    """``n_examples`` drawn examples through a real process each: its exit status is the status
    main() returns for the same command line, and its output has the same shape."""
    root, paths, protected = workspace
    before = _fingerprint(protected)
    case_file = root / "process_case.yaml"
    cwd = root / "process_cwd"
    cwd.mkdir(exist_ok=True)
    monkeypatch.chdir(cwd)
    count = 0

    @settings(
        max_examples=n_examples,
        deadline=None,
        derandomize=True,
        database=None,
        suppress_health_check=list(HealthCheck),
    )
    @given(example=examples(bases, tiny))
    def one(example: Example):
        nonlocal count
        if example.case_bytes is not None:
            case_file.write_bytes(example.case_bytes)
        argv = example.argv(case_file, paths)
        status, out, err = _in_a_process(argv, cwd)
        note(f"argv: {argv}\nstatus {status}\nstdout: {out}\nstderr: {err}")
        check_outcome(status, out, err, example.as_json)
        assert status == _call(argv)[0]
        assert _fingerprint(protected) == before, "an earlier run's files changed"
        assert not any(cwd.iterdir()), f"written to the working folder: {list(cwd.iterdir())}"
        count += 1

    one()
    print(f"\nfuzz: {count} examples through python -m peridyn, 0 tracebacks")
    return count


def test_fuzzed_command_lines_in_a_process_end_cleanly(bases, tiny, workspace, monkeypatch):
    """5 examples (about 10 s): the exit status and stderr of a real process."""
    assert fuzz_processes(5, bases, tiny, workspace, monkeypatch) == 5


@pytest.mark.slow
def test_fuzzed_command_lines_in_a_process_end_cleanly_many(bases, tiny, workspace, monkeypatch):
    assert fuzz_processes(60, bases, tiny, workspace, monkeypatch) == 60
