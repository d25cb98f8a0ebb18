"""A finished run is freed by reference counting alone: nothing of it is left for the garbage
collector. A reference cycle among a run's objects (observers holding the gatherer's ``damage``,
the gatherer holding the observers) kept each run's model, bonds and recorder alive until a full
collection, which a process running one case after another rarely reaches: the workers of the
lamb_damage sweep grew by about 180 MB a run at the seed size (issue 21)."""

import gc
from pathlib import Path

import pytest

from peridyn.io.case import load_case
from peridyn.jobs.run import run_case

CASES = Path(__file__).resolve().parents[2] / "cases"


def _peridyn_garbage(case, out) -> set[str]:
    """The classes of peridyn objects that only the cycle collector would free after
    ``run_case(case, out)``."""
    gc.collect()
    gc.disable()
    try:
        run_case(case, out, overwrite=True)
        gc.set_debug(gc.DEBUG_SAVEALL)
        gc.collect()
        return {
            f"{type(o).__module__}.{type(o).__qualname__}"
            for o in gc.garbage
            if type(o).__module__.startswith("peridyn")
        }
    finally:
        gc.set_debug(0)
        gc.garbage.clear()
        gc.enable()


@pytest.mark.parametrize(
    "name, overrides",
    [
        # recorder with sensors, a line and snapshots
        ("bar_pulse.yaml", ["output.plots=false", "solver.time=4e-6"]),
        # bond breaking: the crack-length observer reads the damage index too
        ("plate2d_stretch.yaml", ["output.plots=false", "solver.time=10e-6"]),
    ],
)
def test_a_run_leaves_no_reference_cycle(tmp_path, name, overrides):
    case = load_case(CASES / name, overrides)
    assert _peridyn_garbage(case, tmp_path / "run") == set()
