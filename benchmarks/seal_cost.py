"""Cost of the whole-file check of a results file (``peridyn.io.seal``) against the per-dataset
checksums it makes unnecessary to read: a results file of about 1 GB (450 records of 100 000
points), sealed when its writer closes it, checked by its seal, then without its seal by the probe
(``peridyn.io.hdf5_probe``). Run from the repository root: ``python benchmarks/seal_cost.py``."""

import os
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

from peridyn.io import hdf5_probe, integrity, seal
from peridyn.io.hdf5 import HDF5Writer

POINTS, BLOCKS, RECORDS = 100_000, 45, 10


def seconds(call) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def main() -> None:
    path = Path(tempfile.mkdtemp()) / "results.h5"
    records = np.random.default_rng(0).random((RECORDS, POINTS, 3))
    h5 = HDF5Writer(path, np.zeros((POINTS, 3)), np.ones(POINTS), {}, flush_every=None)
    h5.create_series("field_u", (POINTS, 3))
    for block in range(BLOCKS):
        steps = list(range(block * RECORDS, (block + 1) * RECORDS))
        h5.append_block("field_u", steps, [s * 1e-7 for s in steps], records)
    h5.close()
    seal.unseal(path)
    sealing = seconds(lambda: seal.seal(path))  # what closing adds
    size = os.path.getsize(path)
    seal._checked.clear()  # as in a new process
    by_seal = seconds(lambda: seal.check(path))

    def per_dataset():
        with h5py.File(path, "r") as f:
            integrity.verify_file(f, str(path))

    datasets = seconds(per_dataset)
    seal.unseal(path)
    seal._checked.clear()
    probe = seconds(lambda: seal.check(path))
    print(
        f"{size / 1e9:.2f} GB: sealing {sealing:.2f} s, check by the seal {by_seal:.2f} s, "
        f"per-dataset checksums {datasets:.2f} s, probe without a seal {probe:.2f} s "
        f"(limit {hdf5_probe.time_limit(size):.0f} s); load {os.getloadavg()[0]:.1f}"
    )
    path.unlink()


if __name__ == "__main__":
    main()
