"""``peridyn examples DIR`` copies every shipped case, sweep and gallery input, byte for byte,
laid out so that the sweeps' ``base: ../cases/...`` and the cases' data files resolve."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from peridyn.cli import main
from peridyn.data.examples import example_path
from peridyn.io.case import load_case
from peridyn.jobs.sweep_spec import expand

ROOT = Path(__file__).resolve().parents[3]


def test_examples_copies_the_repository_cases_sweeps_and_gallery(tmp_path, capsys):
    assert main(["examples", str(tmp_path / "ex"), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["folders"] == ["cases", "gallery", "sweeps"]
    ex = tmp_path / "ex"
    for source, copied in [
        *((p, ex / "cases" / p.name) for p in (ROOT / "cases").glob("*.yaml")),
        *((p, ex / "sweeps" / p.name) for p in (ROOT / "sweeps").glob("*.yaml")),
        *((p, ex / "gallery" / p.name) for p in (ROOT / "examples").glob("plot_*.py")),
        (ROOT / "tests/data/peridigm/WaveInBar.g", ex / "gallery/peridigm/WaveInBar.g"),
        (ROOT / "cases/data/paris_synthetic.csv", ex / "cases/data/paris_synthetic.csv"),
    ]:
        assert copied.read_bytes() == source.read_bytes(), copied
    # the copied sweep finds its base case next to it, not in the repository
    sweep = expand(ex / "sweeps" / "demo.yaml", first=1)
    assert sweep.base == (ex / "cases" / "bar_pulse.yaml").resolve()
    assert load_case(ex / "cases" / "sen_fatigue.yaml").name == "sen_fatigue"


def test_examples_refuses_a_folder_with_files(tmp_path, capsys):
    (tmp_path / "keep.txt").write_text("mine")
    assert main(["examples", str(tmp_path)]) != 0
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err == f"peridyn examples: error: {tmp_path} exists and is not an empty folder"
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]


def test_example_path_names_the_folders_on_an_unknown_name():
    assert example_path("cases/bar_pulse.yaml").read_bytes() == (ROOT / "cases/bar_pulse.yaml").read_bytes()
    with pytest.raises(FileNotFoundError, match=r"no example 'cases/nope.yaml'; the examples are in cases"):
        example_path("cases/nope.yaml")
