"""The wheel as a newcomer installs it: built from a copy of the repository, installed in a fresh
virtual environment outside the repository, it copies its examples out and runs a shipped case.

Slow (a wheel build and a venv, then a numba compile): ``python -m pytest -m slow tests/packaging``.
The venv sees this interpreter's packages (``--system-site-packages``) and the wheel installs
with ``--no-deps``, so that nothing is downloaded; its own copy of peridyn comes first.
"""

import json
import os
import shutil
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

import h5py
import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]

#: Not copied to build the wheel: version control, build outputs, run outputs, caches.
IGNORED = shutil.ignore_patterns(
    ".git", "build", "dist", "*.egg-info", "__pycache__", "peridyn-out*", "_build", ".venv", "*.h5"
)

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """The wheel, built from a copy of the repository (the build writes nothing into it)."""
    source = tmp_path_factory.mktemp("source") / "peridyn"
    shutil.copytree(REPO, source, ignore=IGNORED)
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", out, source],
        check=True,
    )
    (path,) = out.glob("peridyn-*.whl")
    return path


@pytest.fixture(scope="module")
def installed(wheel, tmp_path_factory) -> tuple[Path, dict]:
    """A fresh venv outside the repository with the wheel installed: (its bin folder, the
    environment to run it in: no PYTHONPATH pointing at a checkout)."""
    env_dir = tmp_path_factory.mktemp("venv") / "env"
    venv.create(env_dir, system_site_packages=True, with_pip=False)
    bin_dir = env_dir / "bin"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env["PATH"] = f"{bin_dir}{os.pathsep}{env['PATH']}"
    subprocess.run(
        [sys.executable, "-m", "pip", "--python", bin_dir / "python", "install", "--no-deps", "-q", wheel],
        check=True,
        env=env,
    )
    return bin_dir, env


def test_wheel_carries_the_license_citation_and_examples(wheel):
    """LICENSE and CITATION.cff in the metadata; every shipped case, sweep and gallery input."""
    names = zipfile.ZipFile(wheel).namelist()
    licenses = {Path(n).name for n in names if ".dist-info/licenses/" in n}
    assert licenses == {"LICENSE", "CITATION.cff"}
    shipped = {n.split("examples_data/", 1)[1] for n in names if "/examples_data/" in n}
    expected = {f"cases/{p.name}" for p in (REPO / "cases").glob("*.yaml")}
    expected |= {f"sweeps/{p.name}" for p in (REPO / "sweeps").glob("*.yaml")}
    expected |= {f"gallery/{p.name}" for p in (REPO / "examples").glob("plot_*.py")}
    expected |= {
        "gallery/peridigm/WaveInBar.xml",
        "gallery/peridigm/WaveInBar.g",
        "cases/data/paris_synthetic.csv",
    }
    assert expected <= shipped, sorted(expected - shipped)


def test_installed_wheel_copies_its_examples_and_runs_the_bar_pulse(installed, tmp_path):
    """``peridyn examples ex && cd ex && peridyn run cases/bar_pulse.yaml`` outside the
    repository, on a coarse grid (2.5 mm) and 20 us: the run completes and its sensor at
    x = 50 mm sees the pulse, which the bar wave speed sqrt(E / rho) = 5048 m/s brings there at
    9.9 us (the 1-cycle 50 kHz pulse lasts 20 us)."""
    bin_dir, env = installed
    where = subprocess.run(
        [bin_dir / "python", "-c", "import peridyn; print(peridyn.__file__)"],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert Path(where.strip()).is_relative_to(bin_dir.parent), where
    subprocess.run([bin_dir / "peridyn", "examples", "ex"], cwd=tmp_path, env=env, check=True)
    ex = tmp_path / "ex"
    assert (ex / "sweeps" / "demo.yaml").is_file() and (
        ex / "gallery" / "peridigm" / "WaveInBar.xml"
    ).is_file()
    run = subprocess.run(
        [
            bin_dir / "peridyn",
            "run",
            "cases/bar_pulse.yaml",
            "--json",
            "--no-progress",
            "--set",
            "discretization.spacing=2.5e-3",
            "--set",
            "solver.time=20e-6",
            "--set",
            "output.snapshot_times=[]",
            "--set",
            "output.plots=false",
        ],
        cwd=ex,
        env=env,
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    summary = json.loads(run.stdout)
    results = Path(summary["output_dir"])
    if not results.is_absolute():
        results = ex / results
    with h5py.File(results / "results.h5", "r") as f:
        assert f.attrs["status"] == "complete"
        u = f["series/sensor_u/data"][:, 0, 0]  # x displacement at x = 50 mm, m
    assert np.abs(u).max() > 1e-8  # a tenth of the 1 um drive at least


def test_installed_gallery_script_finds_its_inputs_through_the_package(installed, tmp_path):
    """The modal gallery example (as a downloaded script or notebook runs it) outside the
    repository: it loads its case through ``peridyn.data.examples`` and prints the free PMMA
    plate's modes, six rigid ones at 0 Hz first."""
    bin_dir, env = installed
    subprocess.run([bin_dir / "peridyn", "examples", "ex"], cwd=tmp_path, env=env, check=True)
    script = tmp_path / "ex" / "gallery" / "plot_05_modal.py"
    run = subprocess.run(
        [bin_dir / "python", script],
        cwd=tmp_path,
        env={**env, "MPLBACKEND": "Agg"},
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "peridyn-out" / "gallery" / "modal" / "results.h5").is_file()
    rigid = [line.split(":")[1].strip() for line in run.stdout.splitlines() if "rigid" in line]
    assert rigid == ["0.0 Hz"] * 6


#: Runs the code cells of a notebook in order in one namespace, as one kernel runs them (no Jupyter
#: kernel is installed here): its argument is the .ipynb file.
RUN_CELLS = """
import json, sys
cells = json.load(open(sys.argv[1], encoding="utf-8"))["cells"]
scope = {"__name__": "__main__"}
for number, cell in enumerate(cells):
    if cell["cell_type"] == "code":
        exec(compile("".join(cell["source"]), f"cell {number}", "exec"), scope)
"""


def test_installed_gallery_notebook_runs_outside_the_repository(installed, tmp_path):
    """The modal gallery example as the docs offer it for download: converted to a notebook by
    sphinx-gallery's own converter (as the docs build writes it, configuration comments
    removed), its code cells run in order by the wheel's interpreter outside the repository;
    it finds its case through the package and prints the free PMMA plate's six rigid modes at
    0 Hz."""
    from sphinx_gallery.notebook import python_to_jupyter_cli

    bin_dir, env = installed
    subprocess.run([bin_dir / "peridyn", "examples", "ex"], cwd=tmp_path, env=env, check=True)
    script = tmp_path / "ex" / "gallery" / "plot_05_modal.py"
    python_to_jupyter_cli([str(script)], sphinx_gallery_conf={"remove_config_comments": True})
    notebook = script.with_suffix(".ipynb")
    cells = json.loads(notebook.read_text())["cells"]
    assert sum(cell["cell_type"] == "code" for cell in cells) >= 2  # text and code alternate
    downloaded = tmp_path / "downloads" / notebook.name  # where a browser puts it
    downloaded.parent.mkdir()
    shutil.move(notebook, downloaded)
    run = subprocess.run(
        [bin_dir / "python", "-c", RUN_CELLS, downloaded],
        cwd=downloaded.parent,
        env={**env, "MPLBACKEND": "Agg"},
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    rigid = [line.split(":")[1].strip() for line in run.stdout.splitlines() if "rigid" in line]
    assert rigid == ["0.0 Hz"] * 6
