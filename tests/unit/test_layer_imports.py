"""Importing a layer loads nothing above it (docs/architecture.md, "The layers").

import-linter checks the import statements; this checks what an import really loads, the
package's ``__init__`` included: a script that needs only the kernels (a benchmark, a GPU
backend's comparison) must not pay for, or depend on, the jobs, I/O and solvers above them.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import peridyn

SRC = Path(peridyn.__file__).parents[1]
PYPROJECT = SRC.parent / "pyproject.toml"


def _layers() -> list[set[str]]:
    """The layers contract of pyproject.toml, bottom first, each a set of top-level names."""
    config = tomllib.loads(PYPROJECT.read_text())
    contract = next(c for c in config["tool"]["importlinter"]["contracts"] if c["type"] == "layers")
    return [{name.strip() for name in layer.split("|")} for layer in reversed(contract["layers"])]


LAYERS = _layers()

#: imports every module of a package and prints the top-level peridyn packages then loaded
PROBE = """
import importlib, json, pkgutil, sys
name = sys.argv[1]
package = importlib.import_module(name)
for module in pkgutil.walk_packages(getattr(package, "__path__", []), name + "."):
    importlib.import_module(module.name)
print(json.dumps(sorted({".".join(m.split(".")[:2]) for m in sys.modules if m.startswith("peridyn.")})))
"""


@pytest.mark.parametrize("height", range(len(LAYERS) - 2), ids=lambda h: "|".join(sorted(LAYERS[h])))
def test_a_layer_loads_only_the_layers_below_it(height):
    allowed = set().union(*LAYERS[:height]) | LAYERS[height]
    for name in sorted(LAYERS[height]):
        done = subprocess.run(
            [sys.executable, "-c", PROBE, name],
            capture_output=True,
            text=True,
            env={**os.environ, "PYTHONPATH": str(SRC)},
            timeout=300,
        )
        assert done.returncode == 0, done.stderr
        loaded = set(json.loads(done.stdout.splitlines()[-1]))
        siblings = LAYERS[height] - {name}
        assert loaded <= allowed - siblings, f"{name} loads {sorted(loaded - (allowed - siblings))}"


def test_setup_sits_between_the_jobs_and_the_figures():
    """``peridyn.setup`` (a case to the objects of a run) is the layer right below the jobs that
    run them and above the figures, analyses and solvers it builds for (docs/architecture.md)."""
    names = [sorted(layer) for layer in reversed(LAYERS)]
    assert names[:3] == [["peridyn.cli"], ["peridyn.jobs"], ["peridyn.setup"]]


#: Lines a module of ``peridyn.jobs`` may hold: a job and what only it needs (docs/architecture.md).
JOB_MODULE_LINES = 500


def test_jobs_are_small_and_share_nothing_through_the_run_job():
    """No module of ``peridyn.jobs`` holds more than ``JOB_MODULE_LINES`` lines, and none imports
    from ``jobs/run.py`` anything but the job itself (``run_case``, for the dispatch): what jobs
    share lives in ``peridyn.setup`` or in a module of its own."""
    import ast

    for path in sorted((SRC / "peridyn" / "jobs").glob("*.py")):
        source = path.read_text()
        assert len(source.splitlines()) <= JOB_MODULE_LINES, f"{path.name}: {len(source.splitlines())} lines"
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, ast.ImportFrom) and node.module == "peridyn.jobs.run":
                assert [a.name for a in node.names] == ["run_case"], f"{path.name} imports from jobs.run"
