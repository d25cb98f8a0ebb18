"""Peridigm decks and bodies of several blocks under ``mpiexec -n 2`` and ``-n 3 peridyn run``
(docs/peridigm.md): the serial run's Exodus values (``output.exodus`` as a mapping, gathered on
rank 0) and results.h5 bit for bit. WaveInBar (Exodus mesh, named variables every 20 steps),
Compression_3x1x1 (PdQuickGrid box families, ``discretization.neighbourhood: box``) and the
shipped steel-aluminium bar of two blocks (cases/bimaterial_bar.yaml, shortened).

Run with ``PYTHONPATH=src python -m pytest -m mpi -q -p no:cacheprovider`` (NUMBA_NUM_THREADS=1
per rank; each serial run fills numba's cache before the MPI runs).
"""

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from conftest import peridyn_process, results_datasets

from peridyn.io.exodus import read_exodus

pytestmark = pytest.mark.mpi

ROOT = Path(__file__).resolve().parents[2]
DECKS = ROOT / "tests" / "data" / "peridigm"

#: The decks in peridyn's order of operations: Peridigm's (``solver.arithmetic: peridigm``, a
#: serial deck's) runs in one process only, an MPI run takes peridyn's (docs/peridigm.md).
RUNS = {
    "WaveInBar": (DECKS / "WaveInBar.xml", ["solver.arithmetic=peridyn"]),
    "Compression_3x1x1": (DECKS / "Compression_3x1x1.yaml", ["solver.arithmetic=peridyn"]),
    "bimaterial_bar": (ROOT / "cases" / "bimaterial_bar.yaml", ["solver.time=6e-6", "output.plots=false"]),
}


def _run(name: str, out: Path, ranks: int) -> subprocess.CompletedProcess:
    path, sets = RUNS[name]
    argv = ["run", str(path), "-o", str(out), "--no-progress", "--json"]
    for s in sets:
        argv += ["--set", s]
    return peridyn_process(argv, ranks)


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The serial run of each deck or case."""
    if shutil.which("mpiexec") is None:
        pytest.skip("mpiexec not installed (pip install 'peridyn[mpi]')")
    pytest.importorskip("mpi4py")
    base = tmp_path_factory.mktemp("serial")
    for name in RUNS:
        done = _run(name, base / name, 1)
        assert done.returncode == 0, done.stderr
    return base


def _exodus(folder: Path):
    (path,) = folder.glob("*.e")
    return read_exodus(path)


@pytest.mark.bitwise
@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("name", ["WaveInBar", "Compression_3x1x1"])
def test_deck_exodus_output_is_the_serial_one(serial, tmp_path, name, ranks):
    """Every record's time and every nodal, element and global variable as in the serial run,
    bit for bit, but ``Proc_Num``: each point's rank (Peridigm's meaning), 0 in one process,
    here the ranks 0 to n - 1, each owning points. Bit for bit: each rank computes its points with the
    serial operations in the serial order, and the global sums are taken over the whole body in global
    point order on rank 0 (``Domain.reduce``); the kernels are compiled without value-changing fast-math
    flags (``peridyn.kernels.FASTMATH``), so this holds on every CPU."""
    done = _run(name, tmp_path, ranks)
    assert done.returncode == 0, done.stderr
    one, many = _exodus(serial / name), _exodus(tmp_path)
    assert np.array_equal(one.times, many.times) and len(one.times) > 1
    for kind in ("nodal_variables", "element_variables", "global_variables"):
        a, b = getattr(one, kind), getattr(many, kind)
        assert a.keys() == b.keys()
        assert [k for k in a if k != "Proc_Num" and not np.array_equal(a[k], b[k])] == []
    if "Proc_Num" in one.element_variables:
        assert np.all(one.element_variables["Proc_Num"] == 0)
        assert set(np.unique(many.element_variables["Proc_Num"])) == set(range(ranks))


@pytest.mark.bitwise
def test_body_of_two_blocks_is_the_serial_one(serial, tmp_path):
    """cases/bimaterial_bar.yaml (steel and aluminium LPS blocks) on 2 ranks: every dataset of
    results.h5 under final/ and series/ as in the serial run, bit for bit. The bits agree: each rank
    computes its points with the serial operations in the serial order, and the global sums are taken
    over the whole body in global point order on rank 0 (``Domain.reduce``); the kernels are compiled
    without value-changing fast-math flags (``peridyn.kernels.FASTMATH``), so this holds on every
    CPU."""
    done = _run("bimaterial_bar", tmp_path, 2)
    assert done.returncode == 0, done.stderr
    one, many = (
        results_datasets(serial / "bimaterial_bar/results.h5"),
        results_datasets(tmp_path / "results.h5"),
    )
    assert one.keys() == many.keys() and len(one) > 5
    assert [k for k in one if not np.array_equal(one[k], many[k])] == []
