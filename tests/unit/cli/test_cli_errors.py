"""Every failure of the command line is one line naming what is wrong, and a non-zero exit; with
--json stdout holds one JSON object (docs/user-guide.md, "Errors"; issue 17, item 1)."""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import pytest

from peridyn.cli import main
from peridyn.errors import CaseFileError, Interrupted, PeridynError
from peridyn.io.case import load_case

ROOT = Path(__file__).resolve().parents[3]
BAR = str(ROOT / "cases" / "bar_pulse.yaml")
PLATE = str(ROOT / "cases" / "pmma_plate.yaml")
#: A few explicit steps of the bar without figures: a run of about a second.
SHORT = ["--set", "solver.time=0.3e-6", "--set", "output.plots=false"]


def _call(argv: list[str], capsys) -> tuple[int, str, str]:
    status = main(argv)
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _error_line(err: str, command: str) -> str:
    """The last stderr line, checked to be the error of ``command`` and no traceback before it."""
    assert "Traceback" not in err
    line = err.splitlines()[-1]
    assert line.startswith(f"peridyn {command}: error: "), line
    return line


def test_case_file_error_names_key_value_expected_in_the_line_and_the_json_object(capsys):
    """The JSON object carries the CaseFileError's own key, value, expected and path."""
    override = "material.density=-5"
    with pytest.raises(CaseFileError) as raised:
        load_case(BAR, [override])
    status, out, err = _call(["validate", BAR, "--set", override, "--json"], capsys)
    assert status == 1
    line = _error_line(err, "validate")
    assert line.endswith(str(raised.value))
    exc = raised.value
    expected = {"error": str(exc), "key": exc.key, "value": exc.value, "expected": exc.expected, "path": BAR}
    assert json.loads(out) == expected


def test_without_json_stdout_stays_empty(capsys):
    status, out, err = _call(["validate", BAR, "--set", "material.density=-5"], capsys)
    assert status == 1 and out == "" and len(err.splitlines()) == 1


@pytest.mark.parametrize(
    ("argv", "command", "fields", "shown"),
    [
        (
            ["run", BAR, "--checkpoint-every", "x"],
            "run",
            {"key": "--checkpoint-every", "value": "x", "expected": "a whole number >= 1"},
            "expected a whole number >= 1",
        ),
        (["run"], "run", {"key": "case", "expected": "required"}, "required: case"),
        (["validate", BAR, "--biuld"], "validate", {"value": "--biuld"}, "did you mean '--build'?"),
        (["rn", BAR], "", {"key": "COMMAND", "value": "rn"}, "did you mean 'run'?"),
        (["lamb", "--E", "2e11"], "lamb", {"expected": "required"}, "--nu, --rho"),
        (["run", BAR, "--progress", "--no-progress"], "run", {"key": "--no-progress"}, "not allowed"),
    ],
)
def test_argparse_errors_are_one_line_with_exit_2_and_a_json_object(argv, command, fields, shown, capsys):
    """argparse's own refusals (exit 2, its convention) name the argument and suggest the
    nearest option or command."""
    status, out, err = _call(argv, capsys)
    assert status == 2 and out == "" and len(err.splitlines()) == 1
    line = _error_line(err, command) if command else err.strip()
    assert shown in line and line.endswith(f"(see 'peridyn{' ' + command if command else ''} --help')")
    status, out, err = _call([*argv, "--json"], capsys)
    obj = json.loads(out)
    assert status == 2 and obj["error"] in err and {k: obj.get(k) for k in fields} == fields


@pytest.mark.parametrize("command", ["run", "modal"])
def test_an_output_folder_that_cannot_be_made_names_the_path_and_the_reason(command, tmp_path, capsys):
    """A file where the folder should be: NotADirectoryError, before any step or mode is solved."""
    blocker = tmp_path / "file"
    blocker.write_text("")
    target = blocker / "out"
    case = BAR if command == "run" else PLATE
    status, out, err = _call([command, case, "-o", str(target), *SHORT[2:], "--json"], capsys)
    assert status == 1
    line = _error_line(err, command)
    assert line.endswith(f"{target}: {os.strerror(errno.ENOTDIR)}")
    assert json.loads(out) == {"error": line.split("error: ", 1)[1], "path": str(target)}


def test_a_full_disk_while_writing_results_names_the_file(tmp_path, monkeypatch, capsys):
    """ENOSPC raised by the results writer (simulated: the writer is replaced by one that fails as
    a full disk does; tests/unit/cli/test_cli_signals.py has a real one)."""
    import peridyn.io.recorder as recorder

    def full_disk(path, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(recorder, "HDF5Writer", full_disk)
    status, _, err = _call(["run", BAR, "-o", str(tmp_path), *SHORT], capsys)
    assert status == 1
    assert _error_line(err, "run").endswith(f"{tmp_path / 'results.h5'}: No space left on device")


def test_a_full_device_for_a_plot_names_the_file(capsys):
    """/dev/full fails every write with ENOSPC: a real full disk, found when the PNG is flushed."""
    argv = ["lamb", "--E", "2e11", "--nu", "0.3", "--rho", "7800", "--thickness", "0.002", "--freq", "1e5"]
    status, _, err = _call([*argv, "--plot", "/dev/full"], capsys)
    assert status == 1
    assert _error_line(err, "lamb").endswith("/dev/full: No space left on device")


def test_an_hdf5_failure_names_the_file_and_the_reason():
    """h5py reports a failed write as an OSError without a filename; the path and the reason are
    read from HDF5's text (the text of a real ENOSPC from h5py 3, abridged)."""
    from peridyn.cli.errors import describe

    exc = OSError(
        errno.ENOSPC,
        "Can't synchronously write data (file write failed: time = Tue Nov 24 14:29:51 2026; , "
        "filename = '/x/results.h5', file descriptor = 3, errno = 28, error message = "
        "'No space left on device', buf = 0x1, total write size = 416896, offset = 65536)",
    )
    assert describe(exc) == ("/x/results.h5: No space left on device (Can't synchronously write data)", 1)


def test_run_prints_a_modal_summary(tmp_path, capsys):
    """`peridyn run` of a modal case prints the modes (a modal summary has no steps)."""
    from peridyn.io.results import Results

    argv = [
        "run",
        PLATE,
        "-o",
        str(tmp_path),
        "--set",
        "discretization.spacing=0.005",
        "--set",
        "solver.modes=8",
    ]
    status, out, err = _call([*argv, "--set", "output.plots=false"], capsys)
    assert status == 0, err
    summary = Results(tmp_path / "results.h5").summary()
    assert summary["kind"] == "modal"
    for mode in summary["modes"]:
        assert f"{mode['frequency_hz']:12.2f} Hz  {mode['label']}" in out
    assert out.splitlines()[-1] == f"results written to {tmp_path}"


def _fail_in_build(monkeypatch, exc: BaseException) -> None:
    """Make the body's construction raise ``exc`` (as a bond search or an allocation would)."""
    import peridyn.jobs.run

    def build(*args, **kwargs):
        raise exc

    monkeypatch.setattr(peridyn.jobs.run, "build", build)


def test_ctrl_c_outside_the_step_loop_is_one_line_and_exit_130(monkeypatch, capsys):
    _fail_in_build(monkeypatch, KeyboardInterrupt())
    status, out, err = _call(["run", BAR, "--json"], capsys)
    assert status == 130 and err.splitlines()[-1] == "peridyn run: interrupted"
    assert json.loads(out) == {"error": "interrupted"}


def test_ctrl_c_inside_a_numba_kernel_is_an_interruption(monkeypatch, capsys):
    """numba turns a KeyboardInterrupt in a kernel into SystemError("... returned a result with an
    exception set") chained to it."""
    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise SystemError("CPUDispatcher(<function f>) returned a result with an exception set")  # noqa: B904
    except SystemError as exc:
        wrapped = exc
    _fail_in_build(monkeypatch, wrapped)
    status, _, err = _call(["run", BAR], capsys)
    assert status == 130 and err.splitlines()[-1] == "peridyn run: interrupted"


@pytest.mark.parametrize("signal_name", ["SIGINT", "SIGTERM"])
def test_an_interrupted_run_exits_with_its_signal_status(signal_name, monkeypatch, capsys):
    exc = Interrupted(signal_name, 17, "peridyn run bar.yaml --restart")
    _fail_in_build(monkeypatch, exc)
    status, out, err = _call(["run", BAR, "--json"], capsys)
    assert status == exc.exit_code == Interrupted.EXIT_CODES[signal_name]
    assert err.splitlines()[-1] == f"peridyn run: {exc}"
    assert json.loads(out) == {"error": str(exc), "step": 17, "resume": exc.resume}


def test_out_of_memory_suggests_a_coarser_spacing(monkeypatch, capsys):
    _fail_in_build(monkeypatch, MemoryError("Unable to allocate 894. GiB for an array with shape (1, 3)"))
    status, _, err = _call(["run", BAR], capsys)
    assert status == 1
    line = _error_line(err, "run")
    assert "out of memory (Unable to allocate 894. GiB" in line and "coarser discretization.spacing" in line


def test_an_internal_error_is_one_line_and_exit_2(monkeypatch, capsys):
    _fail_in_build(monkeypatch, ZeroDivisionError("float division by zero"))
    status, _, err = _call(["run", BAR], capsys)
    assert status == 2
    assert _error_line(err, "run").endswith(
        "internal error: ZeroDivisionError: float division by zero (run with --debug for the traceback)"
    )


@pytest.mark.parametrize("flag_first", [True, False])
def test_debug_shows_the_traceback_before_the_line(flag_first, monkeypatch, capsys):
    _fail_in_build(monkeypatch, PeridynError("bad input"))
    argv = ["--debug", "run", BAR] if flag_first else ["run", BAR, "--debug"]
    status, _, err = _call(argv, capsys)
    assert status == 1
    assert "Traceback (most recent call last)" in err and "raise exc" in err
    assert err.splitlines()[-1] == "peridyn run: error: bad input"


def test_a_multi_line_message_is_joined_on_one_line(monkeypatch, capsys):
    _fail_in_build(monkeypatch, PeridynError("first line\n  second line\n"))
    status, _, err = _call(["run", BAR], capsys)
    assert status == 1 and err.splitlines()[-1] == "peridyn run: error: first line; second line"


def test_the_json_error_object_is_strict_json_for_a_nan_value(capsys):
    """NaN has no strict-JSON number (RFC 8259): the value is given as its repr."""

    def refuse(name):
        raise ValueError(f"{name} is not strict JSON")

    status, out, _ = _call(["validate", BAR, "--set", "material.density=.nan", "--json"], capsys)
    obj = json.loads(out, parse_constant=refuse)
    assert status == 1 and obj["key"] == "material.density" and obj["value"] == "nan"
