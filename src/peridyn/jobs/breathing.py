"""Breathing-crack comparison: one case run as given, without its cracks, and without contact.

``python -m peridyn.jobs.breathing CASE.yaml OUT.png [SENSOR]`` runs the three variants of an
explicit case with pre-cracks and a ``contact`` block, prints each sensor's second-harmonic
ratio A2/A1 and draws their spectra (``peridyn.plotting.spectra``). The drive frequency is
the first boundary condition's tone-burst frequency.
"""

from __future__ import annotations

import sys

import numpy as np

from peridyn.errors import InputError
from peridyn.io.case import Case, load_case
from peridyn.setup.build import build
from peridyn.solvers import ExplicitSolver

VARIANTS = {"breathing crack": {}, "no crack": {"precracks": []}, "open crack": {"contact": None}}


def sensor_signal(case: Case, sensor: str) -> tuple[np.ndarray, float]:
    """u_x (m) at the point nearest the case's ``output.sensors[sensor]`` at every step, and dt (s)."""
    if sensor not in case.output.sensors:
        raise InputError(f"sensor {sensor!r} is not one of output.sensors {sorted(case.output.sensors)}")
    setup = build(case)
    solver = ExplicitSolver(
        setup.model, setup.loading, dt=case.solver.dt, safety=case.solver.safety, contact=setup.contact
    )
    state = solver.initial_state()
    where = np.array(case.output.sensors[sensor] + [0.0] * (3 - len(case.output.sensors[sensor])))
    point = int(np.argmin(np.linalg.norm(setup.body.points - where, axis=1)))
    n_steps = case.solver.steps or int(np.ceil(case.solver.time / solver.dt - 1e-9))
    signal = np.empty(n_steps)
    for k in range(n_steps):
        solver.step(state)
        signal[k] = state.u[point, 0]
    return signal, solver.dt


def compare(case: Case, sensor: str) -> dict:
    """{variant: (signal, dt)} for the breathing crack, no crack and an open crack."""
    if case.contact is None or not case.precracks:
        raise InputError("a breathing-crack comparison needs a case with precracks and a contact block")
    return {name: sensor_signal(case.model_copy(update=update), sensor) for name, update in VARIANTS.items()}


def drive_frequency(case: Case) -> float:
    """Frequency (Hz) of the first boundary condition's tone burst."""
    for bc in case.boundary_conditions:
        if isinstance(bc.value, dict) and "frequency" in bc.value:
            return float(bc.value["frequency"])
    raise InputError("no boundary condition with a tone-burst frequency in this case")


def main(argv=None) -> None:
    from peridyn.analysis.harmonics import second_harmonic_ratio
    from peridyn.plotting.spectra import plot_spectra

    args = sys.argv[1:] if argv is None else argv
    case = load_case(args[0])
    sensor = args[2] if len(args) > 2 else next(iter(case.output.sensors))
    f0 = drive_frequency(case)
    runs = compare(case, sensor)
    for name, (signal, dt) in runs.items():
        print(f"{name}: A2/A1 = {second_harmonic_ratio(signal, dt, f0):.4g}")
    # the variants have different stable steps: resample onto the finest one
    dt = min(dt for _, dt in runs.values())
    signals = {}
    for name, (signal, step) in runs.items():
        t = step * np.arange(1, len(signal) + 1)
        signals[name] = np.interp(dt * np.arange(1, int(t[-1] / dt) + 1), t, signal)
    print(plot_spectra(signals, dt, f0, args[1], title=f"{case.name}: sensor {sensor}"))


if __name__ == "__main__":
    main()
