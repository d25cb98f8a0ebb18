"""The monitoring job's interrogation runs under MPI (``peridyn.jobs.monitor._run_ranks``) stop
together on a stop signal, on simulated ranks in one process (``ThreadComm``: threads with MPI's
semantics, tests/unit/test_distributed_relax.py).

Fact tested: a SIGTERM noted after an interrogation run ends every rank with ``Interrupted``
before the next run starts; none is left waiting in the next run's first collective, as a rank
would be if only rank 0, which writes the records, looked for the signal (docs/monitoring.md,
"Interrogations, resuming, executors, MPI"). The runs themselves are stand-ins: one collective
each, as every ``run_case`` under MPI begins with one.
"""

import signal
from types import SimpleNamespace

from test_distributed_relax import on_ranks

from peridyn import interrupts
from peridyn.errors import Interrupted
from peridyn.jobs import monitor


def test_a_signal_after_a_run_stops_every_rank_before_the_next(tmp_path, monkeypatch):
    started = []

    def run_case(case, run_dir, base_dir, overwrite, comm):
        comm.barrier()  # every run on several ranks starts with a collective
        started.append((comm.rank, case))
        if comm.rank == 0 and case == "first":
            interrupts._pending.append(signal.SIGTERM)  # the signal arrives as the first run ends
        return {}

    monkeypatch.setattr("peridyn.jobs.run.run_case", run_case)
    monkeypatch.setattr(interrupts, "_pending", [])
    todo = [
        SimpleNamespace(
            run_id=name,
            index=k,
            parameters={},
            case_hash="",
            command="",
            case=name,
            run_dir=str(tmp_path / name),
            base_dir=str(tmp_path),
        )
        for k, name in enumerate(("first", "second"))
    ]

    def rank(comm):
        try:
            monitor._run_ranks(todo, comm, done=lambda record: True)
        except Interrupted as stop:
            return str(stop)
        return None

    outcomes = on_ranks(2, rank)
    assert all(o is not None and "SIGTERM" in o for o in outcomes), outcomes
    assert sorted(started) == [(0, "first"), (1, "first")]
