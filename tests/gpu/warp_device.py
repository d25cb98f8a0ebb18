"""Imported by every GPU-backend test module before peridyn: the tests run Warp's kernels on its CPU device
(``PERIDYN_GPU_ON_CPU=1``), or on the GPU when one is there and the variable is not set
(``benchmarks/gpu_check.sh``); they are skipped, with the reason, where Warp is not installed.

Not a ``conftest.py``: a second module named ``conftest`` would shadow ``tests/conftest.py`` for
the test modules that import from it."""

import os
import sys
from pathlib import Path

import pytest

pytest.importorskip("warp", reason="the GPU backend's tests need NVIDIA Warp (pip install -e '.[gpu]')")

if "PERIDYN_GPU_ON_CPU" not in os.environ:
    import warp

    warp.config.quiet = True
    if warp.get_cuda_device_count() == 0:
        os.environ["PERIDYN_GPU_ON_CPU"] = "1"

# the small random families of the numba kernel tests
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "kernels"))
