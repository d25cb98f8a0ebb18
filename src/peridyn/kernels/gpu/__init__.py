"""GPU kernels (NVIDIA Warp): the explicit run's force, bond breaking and velocity-Verlet update,
compiled by Warp for a CUDA device or, with ``PERIDYN_GPU_ON_CPU=1``, for Warp's CPU device (how
the tests run them without a GPU). Warp (``pip install peridyn[gpu]``) is imported on first
use only: the rest of the package runs without it.

Layout (ELL, ``peridyn.kernels.gpu.ell``): bond ``k`` of every point is stored contiguously,
per-bond arrays are (k_max, n_points) with the bond of point ``i`` at ``[k, i]``, the families
padded to the longest ``k_max`` (the padding has ``intact`` 0 and is never read: a point's loop
stops at its bond count). One thread computes one point; at each ``k`` the threads of a warp
read 32 neighbouring entries of every per-bond array, one coalesced load each (docs/gpu.md).

Per-point arrays: ``u``, ``v``, ``a``, ``f`` (n_points, 3); ``count`` (n_points,) int32.
Per-bond arrays: ``nbr`` (k_max, n_points) int32, ``intact`` (k_max, n_points) uint8 and the
coefficients of the kernel's dtype. The kernels compute what the numba kernels of
``peridyn.kernels`` compute, in the same order of operations per bond (``tests/gpu``).
"""

from __future__ import annotations

import functools
import os
import sys

from peridyn.errors import InputError

#: Set to 1 to run the GPU backend's kernels on Warp's CPU device (no GPU needed).
ON_CPU_VARIABLE = "PERIDYN_GPU_ON_CPU"


def on_cpu() -> bool:
    """True when ``PERIDYN_GPU_ON_CPU=1``: the GPU kernels run on Warp's CPU device."""
    return os.environ.get(ON_CPU_VARIABLE, "") == "1"


@functools.cache
def warp():
    """The ``warp`` module, initialised once (quietly); InputError when it is not installed."""
    try:
        import warp as wp
    except ImportError:
        raise InputError(
            'the GPU backend needs NVIDIA Warp: pip install "peridyn[gpu]" (or warp-lang)'
        ) from None
    wp.config.quiet = True  # no banner, and no line per compiled module (stdout may carry JSON)
    if hasattr(wp, "LOG_WARNING"):
        wp.config.log_level = wp.LOG_WARNING
    _init_without_driver_warning(wp)
    return wp


def _init_without_driver_warning(wp) -> None:
    """``wp.init()`` with the process's stderr closed: Warp's native library prints a warning there
    on a machine without the CUDA driver, which :func:`device` reports in its own one-line error."""
    if sys.stderr is not None:
        sys.stderr.flush()
    saved = os.dup(2)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 2)
            wp.init()
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def device() -> str:
    """The Warp device of the GPU backend: ``"cpu"`` with ``PERIDYN_GPU_ON_CPU=1``, else
    ``"cuda:0"``; InputError when neither Warp nor a CUDA device is there."""
    wp = warp()
    if on_cpu():
        return "cpu"
    if wp.get_cuda_device_count() == 0:
        driver, toolkit = wp.get_cuda_driver_version(), wp.get_cuda_toolkit_version()
        if driver is not None and toolkit is not None and driver[0] < toolkit[0]:
            raise InputError(
                f"--backend gpu: the NVIDIA driver supports CUDA {driver[0]}.{driver[1]}, older than "
                f"the CUDA {toolkit[0]}.{toolkit[1]} of this Warp build: update the driver or install "
                f"a warp-lang build for CUDA {driver[0]} (docs/gpu.md)"
            )
        raise InputError(
            f"--backend gpu: no CUDA device found (set {ON_CPU_VARIABLE}=1 to run the GPU kernels "
            "on the CPU, or use --backend cpu)"
        )
    return "cuda:0"


def unavailable() -> str | None:
    """Why the GPU backend cannot run here (the one-line error of :func:`device`), or None when it can."""
    try:
        device()
    except InputError as exc:
        return str(exc)
    return None


def device_description(name: str) -> str:
    """A device's name as Warp reports it, e.g. ``"NVIDIA H200"`` or ``"CPU"``."""
    return str(warp().get_device(name).name)
