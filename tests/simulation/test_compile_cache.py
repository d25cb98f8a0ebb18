"""A run whose process compiled the kernels afresh and one whose process loaded them from
numba's on-disk cache give the same results bit for bit.

With reassociation among the kernels' fast-math flags they did not (last-bit differences,
~1e-18 m in the bar's displacements): numba optimises a parallel loop's body once more when
it stores the kernel in its cache, and the reassociated sums rounded differently. A sweep's
serial dataset (kernels compiled in the sweep's process) then differed from its process-pool
dataset (kernels loaded by the workers), as did a run and its restart. See
``peridyn.kernels.FASTMATH``.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

import peridyn

ROOT = Path(__file__).resolve().parents[2]
SRC = str(Path(peridyn.__file__).parents[1])
#: The steel bar of cases/bar_pulse.yaml, coarse (1280 points) and short (19 steps).
BAR = ["discretization.spacing=2.5e-3", "solver.time=3e-6"]


def _run(case, out, cache, sets):
    argv = [sys.executable, "-m", "peridyn", "run", str(ROOT / "cases" / case), "-o", str(out)]
    for item in ("output.plots=false", "output.snapshot_times=[]", *sets):
        argv += ["--set", item]
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": SRC}
    done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr


def _arrays(path):
    arrays = {}

    def keep(name, obj):
        if isinstance(obj, h5py.Dataset):
            arrays[name] = obj[()]

    with h5py.File(path) as f:
        f.visititems(keep)
    return arrays


@pytest.mark.bitwise
@pytest.mark.parametrize(
    ("case", "sets"),
    [
        # LPS, float64 length-form kernels, 3D
        ("bar_pulse.yaml", BAR),
        # LPS, float32 cancellation-free kernels
        ("bar_pulse.yaml", [*BAR, "solver.dtype=float32"]),
        # PMB
        ("bar_pulse.yaml", [*BAR, "material.model=pmb", "material.nu=0.25"]),
    ],
    ids=["lps-float64", "lps-float32", "pmb"],
)
def test_fresh_and_cached_kernels_give_the_same_run(tmp_path, case, sets):
    """A run in a process that compiles the kernels (an empty numba cache) and one in a process that
    loads them from that cache write the same floating-point datasets bit for bit: compiled without
    value-changing fast-math flags (``peridyn.kernels.FASTMATH``), a kernel performs the IEEE operations
    in its written order however it was built, on every CPU."""
    cache = tmp_path / "numba-cache"  # empty: the first run compiles and stores every kernel
    _run(case, tmp_path / "fresh", cache, sets)
    _run(case, tmp_path / "cached", cache, sets)
    fresh, cached = _arrays(tmp_path / "fresh" / "results.h5"), _arrays(tmp_path / "cached" / "results.h5")
    assert fresh.keys() == cached.keys()
    floats = [name for name, a in fresh.items() if np.asarray(a).dtype.kind == "f"]
    assert any(name.startswith("series/") for name in floats)
    for name in floats:
        np.testing.assert_array_equal(fresh[name], cached[name], err_msg=name)
