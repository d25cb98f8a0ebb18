"""The figures of a finished run (not its analyses): sensor signals, B-scans, final fields,
wavefields of plates, crack paths and crack length."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from peridyn.discretization.body import Body
from peridyn.io.case import Case
from peridyn.io.results import Results
from peridyn.physics.timefunctions import from_spec


def draw_run_figures(case: Case, body: Body, results: Results) -> list[Path]:
    """The figures of a finished explicit or static run (not its analyses), drawn from its
    ``results`` into their folder: sensor signals, B-scans, final fields, damage and, for plates
    with snapshot times, the wavefield per layer."""
    from peridyn.plotting.fields import plot_run

    out = Path(results.path).parent
    figures = plot_run(results, body)
    if case.geometry.type == "plate" and case.output.snapshot_times:
        from peridyn.plotting.lamb_wavefield import plot_wavefield_snapshots

        _, times, _ = results.series("field_u")
        reached = [t for t in case.output.snapshot_times if t <= times[-1] * (1 + 1e-9)]
        if reached:
            figures.append(plot_wavefield_snapshots(results, out / "wavefield.png", reached))
        figures += _actuator_figures(case, results, reached)
    return figures


def _actuator_figures(case: Case, results: Results, snapshot_times) -> list[Path]:
    """Through-thickness field under each actuator's cut (+-50 mm along x, at the middle
    snapshot) and the PZT sensor signals under the first actuator's excitation."""
    from peridyn.plotting.lamb_wavefield import plot_sensor_signals, plot_through_thickness

    out = Path(results.path).parent
    figures = []
    length = case.geometry.size[0]
    for name, actuator in case.actuators.items():
        if snapshot_times:
            cx = actuator.center[0]
            x_range = (max(0.0, cx - 0.050), min(length, cx + 0.050))
            figures.append(
                plot_through_thickness(
                    results,
                    out / f"cut_{name}.png",
                    snapshot_times[len(snapshot_times) // 2],
                    actuator.center,
                    x_range,
                )
            )
    if case.output.pzt_sensors and case.actuators:
        _, times, data = results.series("pzt_signal")
        first = next(iter(case.actuators.values()))
        excitation = from_spec(first.signal, "actuators.signal")(times)
        signals = {n: data[:, k] for k, n in enumerate(case.output.pzt_sensors)}
        figures.append(plot_sensor_signals(times, signals, out / "pzt_sensors.png", excitation=excitation))
    return figures


def final_crack_paths(case: Case, body: Body, phi: np.ndarray):
    """Crack paths of the final damage field ``phi`` ((n_points,)) of ``body`` (pre-cracks as
    reference lines; 2D bodies or the x-y projection of 3D ones)."""
    from peridyn.analysis.crack import crack_paths

    lines = [(c.start, c.end) for c in case.precracks if c.type == "segment"]
    lines += [(c.origin, np.add(c.origin, c.edge_u)) for c in case.precracks if c.type == "rectangle"]
    return crack_paths(body.points, phi, body.spacing, reference_lines=lines)


def draw_crack_figures(body: Body, results: Results, paths, summary: dict) -> list[Path]:
    """Damage map on the deformed configuration (x50, as Martowicz, or less) with the crack
    ``paths``, and the crack length against time when it was sampled, in the folder of
    ``results``; displacements and damage are the final ones of ``results``."""
    from peridyn.plotting.crack import plot_crack_length, plot_damage_map

    out = Path(results.path).parent
    u, phi = results.array("final/u"), results.array("final/damage")
    figures = [plot_damage_map(body.points, u, phi, paths, out / "crack_paths.png")]
    history = summary.get("crack_length_history")
    if history and len(history["time_s"]) > 1:
        figures.append(plot_crack_length(history["time_s"], history["length_m"], out / "crack_length.png"))
    return figures


def redraw_crack_figures(case: Case, body: Body, results: Results):
    """Crack paths and figures (``draw_crack_figures``) of a finished run with damage, from
    its ``results``: the final damage and the crack length history of the stored summary.
    Returns (paths, figure paths); (None, []) for a case without damage."""
    if all(m.damage is None for m in case.block_materials().values()):
        return None, []
    paths = final_crack_paths(case, body, results.array("final/damage"))
    return paths, draw_crack_figures(body, results, paths, results.summary())
