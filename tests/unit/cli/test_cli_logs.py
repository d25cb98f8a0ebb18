"""Logs fit their reader: a progress bar only on a terminal or when asked, one-line warnings
without source paths, the same output flag everywhere, help text without RST markup (issue 17,
item 8)."""

from __future__ import annotations

import re
import sys
import warnings
from pathlib import Path

import pytest

from peridyn.cli import build_parser, main
from peridyn.cli.logs import progress_bar

ROOT = Path(__file__).resolve().parents[3]
BAR = str(ROOT / "cases" / "bar_pulse.yaml")
PLATE = str(ROOT / "cases" / "pmma_plate.yaml")
#: RST markup: ``literal``, :role:`target`, `link`_.
RST = re.compile(r"``|:[a-z]+:`|`[^`\n]+`_")


def _subparsers():
    parser = build_parser()
    (action,) = parser._subparsers._group_actions
    return parser, action.choices


def test_warnings_are_one_line_without_source_paths(capsys):
    """The body-rounding warning of discretization.geometry (100 mm is no whole number of 3 mm
    cells), printed as peridyn's own line; the previous warning printer is back after main."""
    before = warnings.showwarning
    argv = ["validate", PLATE, "--build", "--set", "discretization.spacing=0.003"]
    assert main(argv) == 0
    assert warnings.showwarning is before
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if "warning" in line.lower()]
    assert lines and all(line.startswith("peridyn: warning: ") for line in lines), err
    assert "the spacing does not divide the body" in lines[0]
    assert ".py" not in err and "UserWarning" not in err


def test_progress_bar_factory_follows_the_flags_and_the_terminal(monkeypatch):
    """A tqdm bar where someone watches (a terminal, or --progress); else a heartbeat log line
    (peridyn.cli.logs.Heartbeat)."""

    def kind(choice):
        bar = progress_bar(choice, "x")(10)
        bar.close()
        return type(bar).__name__

    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    assert kind(None) == "tqdm" and kind(False) == "Heartbeat"
    monkeypatch.setattr(sys.stderr, "isatty", lambda: False)
    assert kind(None) == "Heartbeat" and kind(True) == "tqdm"


@pytest.mark.parametrize("command", ["run", "demo", "fatigue"])
def test_progress_flags_parse_alike(command):
    parser = build_parser()
    case = [] if command == "demo" else [BAR]
    assert parser.parse_args([command, *case]).progress is None
    assert parser.parse_args([command, *case, "--progress"]).progress is True
    assert parser.parse_args([command, *case, "--no-progress"]).progress is False


@pytest.mark.parametrize(("flags", "bar"), [([], False), (["--progress"], True)])
def test_a_redirected_log_has_no_carriage_returns_unless_asked(flags, bar, tmp_path, capsys):
    """stderr captured (not a terminal): no tqdm bar, whose redraws are carriage returns."""
    argv = ["run", BAR, "-o", str(tmp_path), "--set", "solver.time=0.3e-6", "--set", "output.plots=false"]
    assert main([*argv, *flags]) == 0
    err = capsys.readouterr().err
    assert ("\r" in err) is bar
    assert ("step/s" in err or "s/step" in err) is bar


def test_every_output_folder_flag_is_output_or_o():
    """Commands writing a folder spell it --output / -o; study's old --out is hidden."""
    _, commands = _subparsers()
    with_output = []
    for name, sub in commands.items():
        for action in sub._actions:
            if action.dest == "output" and action.help != "==SUPPRESS==":
                assert action.option_strings == ["--output", "-o"], name
                with_output.append(name)
        assert "--out " not in sub.format_help() and "--out," not in sub.format_help()
    assert set(with_output) >= {"run", "demo", "modal", "fatigue", "study"}


def test_study_out_is_a_deprecated_alias_of_output(capsys):
    with pytest.warns(FutureWarning, match="--out is deprecated: use --output"):
        args = build_parser().parse_args(["study", PLATE, "--spacing", "1", "--horizon", "2", "--out", "d"])
    assert args.output == "d"
    argv = ["study", PLATE, "--spacing", "1", "--horizon", "2", "--out", "d", "--series", "x"]
    assert main(argv) == 1  # refused before any run: the warning, then the error
    err = capsys.readouterr().err.splitlines()
    assert err[0] == "peridyn: warning: --out is deprecated: use --output"
    assert err[1].startswith("peridyn study: error: --series = 'x'")


def test_help_texts_are_plain_text():
    parser, commands = _subparsers()
    assert not RST.search(parser.format_help())
    for name, sub in commands.items():
        text = sub.format_help()
        assert not RST.search(text), (name, RST.search(text))
