"""Latency and bandwidth of point-to-point messages between two ranks (the scaling model's
alpha and beta on this machine), by ping-pong of float64 buffers as the halo sends them.

    mpiexec -n 2 python benchmarks/mpi_pingpong.py            # prints JSON on rank 0

Latency: half the mean round trip of an 8-byte message; bandwidth: bytes / (half the mean
round trip - latency) of 4 MiB messages (about a 125 000-point halo's u on a 2D cut). Best
of five rounds (the machine is shared: the best is the least disturbed).
"""

from __future__ import annotations

import json
import time

import numpy as np
from mpi4py import MPI


def half_round_trip(comm, nbytes: int, repeats: int) -> float:
    """Mean one-way time, s, of ``repeats`` ping-pongs of ``nbytes`` between ranks 0 and 1."""
    buf = np.zeros(max(nbytes // 8, 1))
    other = 1 - comm.rank
    comm.Barrier()
    start = time.perf_counter()
    for _ in range(repeats):
        if comm.rank == 0:
            comm.Send(buf, dest=other, tag=1)
            comm.Recv(buf, source=other, tag=1)
        else:
            comm.Recv(buf, source=other, tag=1)
            comm.Send(buf, dest=other, tag=1)
    return (time.perf_counter() - start) / (2 * repeats)


def main() -> None:
    comm = MPI.COMM_WORLD
    if comm.size != 2:
        raise SystemExit("run with mpiexec -n 2")
    big = 4 * 2**20
    latency = min(half_round_trip(comm, 8, 2000) for _ in range(5))
    transfer = min(half_round_trip(comm, big, 50) for _ in range(5))
    if comm.rank == 0:
        print(
            json.dumps(
                {"latency_s": latency, "bandwidth_bytes_per_s": big / max(transfer - latency, 1e-12)},
                indent=1,
            )
        )


if __name__ == "__main__":
    main()
