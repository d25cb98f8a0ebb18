"""From a validated case to results: build the body, bonds, model and loads, then run.

``run_case`` is what ``peridyn run`` calls; the ``build_*`` functions are the
same steps for Python users who want to stop half-way (e.g. to inspect the bonds).
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from peridyn.discretization import geometry
from peridyn.discretization.body import Body, in_box, in_cylinder, in_sphere
from peridyn.discretization.bonds import Bonds, crossing_rectangle, crossing_segment, cut_bonds, find_bonds
from peridyn.discretization.state import State
from peridyn.errors import CaseFileError, InputError
from peridyn.io import mesh_text
from peridyn.io.case import Case, Region
from peridyn.io.checkpoint import Checkpointer, load_checkpoint
from peridyn.io.hdf5 import HDF5Writer, read_series
from peridyn.io.recorder import LineProbe, Recorder, RecorderSpec, provenance
from peridyn.jobs.lamb_analysis import analyse
from peridyn.physics.absorbing import layer_damping
from peridyn.physics.contact import Contact
from peridyn.physics.damage import BondDamage, damage_field
from peridyn.physics.loads import BoundaryCondition, InitialCondition, Loading
from peridyn.physics.materials import Model, make_model
from peridyn.physics.timefunctions import from_spec
from peridyn.physics.transducers import pin_force_actuator, pzt_radial_actuator, pzt_sensor_weights
from peridyn.solvers import ExplicitSolver, relax


@dataclass
class Setup:
    """Everything a case builds before running."""

    body: Body
    bonds: Bonds
    model: Model
    loading: Loading
    damage: BondDamage | None
    contact: Contact | None = None


def build_body(case: Case, base_dir=".") -> Body:
    """Points of the case geometry, minus removals, with the case's node sets (and ``all``)."""
    g, d = case.geometry, case.discretization
    if g.type != "mesh" and d.spacing is None:
        raise CaseFileError(case.name, "discretization.spacing", None, "a positive spacing (m)")
    if g.type == "box":
        body = geometry.box(g.size, d.spacing, g.origin or (0.0, 0.0, 0.0))
    elif g.type == "plate":
        body = geometry.plate(*g.size, spacing=d.spacing, layers=g.layers,
                              origin=g.origin or (0.0, 0.0, 0.0),
                              layer_placement=g.layer_placement)
    elif g.type == "rectangle":
        body = geometry.rectangle(*g.size, spacing=d.spacing, thickness=g.thickness,
                                  plane=g.plane, origin=(g.origin or (0.0, 0.0))[:2])
    else:
        mesh = Path(g.file) if Path(g.file).is_absolute() else Path(base_dir) / g.file
        body = mesh_text.from_text_mesh(mesh, dim=g.dimension, thickness=g.thickness,
                                       plane=g.plane if g.dimension == 2 else None)
    for k, region in enumerate(case.removals):
        body = body.remove(region_mask(body, region, f"removals[{k}]"))
    body = body.with_node_set("all", np.ones(body.n_points, dtype=bool))
    for name, region in case.node_sets.items():
        mask = region_mask(body, region, f"node_sets.{name}")
        if not mask.any():
            raise CaseFileError(case.name, f"node_sets.{name}", region.model_dump(exclude_none=True),
                                "a region that contains at least one point")
        body = body.with_node_set(name, mask)
    return body


def region_mask(body: Body, region: Region, where: str) -> np.ndarray:
    """(n_points,) bool mask of a case-file region."""
    pad = _pad3
    if region.type == "all":
        return np.ones(body.n_points, dtype=bool)
    if region.type == "box":
        return in_box(pad(region.min), pad(region.max))(body.points)
    if region.type == "sphere":
        return in_sphere(pad(region.center), region.radius)(body.points)
    if region.type == "cylinder":
        return in_cylinder(pad(region.center), region.radius, region.axis)(body.points)
    if region.type == "face":
        return geometry.face(body, region.face, region.depth)
    try:
        return geometry.layer(body, region.index)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def _pad3(v) -> list:
    """A 2- or 3-component coordinate as 3 components (z = 0 for 2D input)."""
    return list(v) + [0.0] * (3 - len(v))


def build_bonds(case: Case, body: Body) -> Bonds:
    """Families of the case's discretisation, with its pre-cracks cut."""
    d = case.discretization
    horizon = d.horizon_m if d.horizon_m is not None else d.horizon * body.spacing
    bonds = find_bonds(body, horizon, d.influence, d.partial_volumes)
    for crack in case.precracks:
        if crack.type == "rectangle":
            def crossing(a, b, c=crack):
                return crossing_rectangle(a, b, c.origin, c.edge_u, c.edge_v)
        else:
            def crossing(a, b, c=crack):
                return crossing_segment(a, b, c.start, c.end)
        cut_bonds(body, bonds, crossing)
    return bonds


def add_actuators(case: Case, body: Body) -> tuple[Body, list[BoundaryCondition]]:
    """The body with a node set per actuator, and the actuators' boundary conditions."""
    conditions = []
    for name, a in case.actuators.items():
        signal = from_spec(a.signal, f"actuators.{name}.signal")
        if a.type == "pzt_radial":
            body, bcs = pzt_radial_actuator(body, a.center, a.size, signal, shape=a.shape,
                                            layer=a.layer, amplitude=a.amplitude, name=name)
        else:
            body, bcs = pin_force_actuator(body, a.center, a.size, signal, shape=a.shape,
                                           layer=a.layer, line_force=a.line_force, name=name)
        conditions += bcs
    return body, conditions


def build_loading(case: Case, body: Body, extra=()) -> Loading:
    """Boundary and initial conditions of the case (plus ``extra`` ones), checked for conflicts."""
    bcs = [BoundaryCondition(bc.set, bc.kind, bc.components,
                             from_spec(bc.value, f"boundary_conditions[{k}].value"))
           for k, bc in enumerate(case.boundary_conditions)]
    ics = [InitialCondition(ic.set, ic.kind, ic.components, ic.value)
           for ic in case.initial_conditions]
    return Loading(body, [*extra, *bcs], ics)


def build(case: Case, base_dir=".") -> Setup:
    """Body, bonds, model, loading and damage of a case."""
    body, actuation = add_actuators(case, build_body(case, base_dir))
    bonds = build_bonds(case, body)
    mat = case.material
    model = make_model(mat.model, body, bonds, E=mat.E, density=mat.density, nu=mat.nu,
                       surface_correction=mat.surface_correction, dtype=case.solver.dtype)
    damage = None
    if mat.damage is not None:
        damage = BondDamage(model, mat.damage.critical_stretch, mat.damage.fracture_energy,
                            mat.damage.no_damage_sets,
                            critical_bond_stress=mat.damage.critical_bond_stress)
    loading = build_loading(case, body, actuation)
    if case.solver.type == "static" and not loading.has_loads:
        raise CaseFileError(case.name, "boundary_conditions", [], "at least one load for a static run")
    if case.solver.type == "newmark" and not (loading.has_loads or loading.initial):
        raise CaseFileError(case.name, "boundary_conditions", [],
                            "a load or an initial condition: nothing would move")
    if case.solver.type == "newton" and not loading.has_loads:
        raise CaseFileError(case.name, "boundary_conditions", [], "at least one load for a newton run")
    if case.solver.type == "explicit" and not (loading.has_loads or loading.initial):
        raise CaseFileError(case.name, "boundary_conditions", [],
                            "a load or an initial condition: nothing would move")
    return Setup(body, bonds, model, loading, damage, build_contact(case, model))


def build_contact(case: Case, model: Model) -> Contact | None:
    """The case's short-range contact forces, or None without a ``contact`` block."""
    c = case.contact
    if c is None:
        return None
    radius = c.radius_m if c.radius_m is not None else c.radius * model.body.spacing
    try:
        return Contact(model, radius, c.stiffness_factor)
    except InputError as exc:
        raise CaseFileError(case.name, "contact", c.model_dump(exclude_none=True), str(exc)) from None


def recorder_spec(case: Case, body: Body, dt: float) -> RecorderSpec:
    """What the case asks to record, with snapshot times turned into steps."""
    out = case.output
    planes = {name: body.node_set(set_name) for name, set_name in out.planes.items()}
    return RecorderSpec(
        every=out.every,
        snapshot_every=out.snapshot_every,
        snapshot_steps=[int(round(t / dt)) for t in out.snapshot_times],
        sensors={k: _pad3(v) for k, v in out.sensors.items()},
        lines={k: LineProbe(_pad3(v.start), _pad3(v.end), v.points) for k, v in out.lines.items()},
        planes=planes,
        pzt_sensors={k: _pzt_weights(body, v) for k, v in out.pzt_sensors.items()},
        series_dtype=out.series_dtype,
        vtu=out.vtu,
    )


def _pzt_weights(body: Body, sensor) -> tuple[np.ndarray, np.ndarray]:
    """Point indices and (n, 2) weights of a PZT sensor patch on its layer."""
    idx = np.flatnonzero(geometry.layer(body, sensor.layer))
    weights = pzt_sensor_weights(body.points[idx], sensor.center, sensor.size, sensor.shape)
    used = np.any(weights != 0, axis=1)
    return idx[used], weights[used]


def output_directory(case: Case, override=None) -> Path:
    """The run's output folder: the override, the case's ``output.directory`` or peridyn-out/NAME."""
    if override is not None:
        return Path(override)
    return Path(case.output.directory or Path("peridyn-out") / case.name)


def run_case(case: Case, output_dir=None, case_path=None, checkpoint_every: int | None = None,
             restart: bool = False, progress=None, base_dir=".") -> dict:
    """Run a case and write its results; returns the summary (also stored in results.h5).

    Parameters
    ----------
    checkpoint_every : int or None
        Steps between checkpoints (``<output>/checkpoint.h5``).
    restart : bool
        Continue from ``<output>/checkpoint.h5`` (results after it are dropped and rewritten).
    progress : callable(total) -> bar with update(n) and close(), or None
    """
    start = time.perf_counter()
    setup = build(case, base_dir)
    out = output_directory(case, output_dir)
    out.mkdir(parents=True, exist_ok=True)
    if case.solver.type == "static":
        summary = _run_static(case, setup, out, case_path)
    elif case.solver.type == "newton":
        summary = _run_newton(case, setup, out, case_path)
    elif case.solver.type == "newmark":
        summary = _run_explicit(case, setup, out, case_path, checkpoint_every, restart, progress,
                                solver=_newmark_solver(case, setup))
    elif case.solver.type == "modal":
        from peridyn.jobs.modal import run_modal

        summary = run_modal(case, setup, out, case_path)
    else:
        summary = _run_explicit(case, setup, out, case_path, checkpoint_every, restart, progress)
    analysis, figures = analyse(case, setup.body, out, plots=case.output.plots)
    summary.update(analysis)
    paths = (final_crack_paths(case, setup.body, damage_field(setup.model))
             if setup.damage is not None else None)
    if paths is not None:
        summary["crack_paths"] = [p.summary() for p in paths]
    if case.output.plots and case.solver.type != "modal":  # a modal run draws its own
        summary["plots"] = [str(p) for p in [*draw_run_figures(case, setup.body, out), *figures]]
        if paths is not None:
            summary["plots"] += [str(p) for p in draw_crack_figures(setup.body, out, paths, summary)]
    summary["seconds"] = time.perf_counter() - start
    store_summary(out / "results.h5", setup.body, summary)
    return summary


def draw_run_figures(case: Case, body: Body, out: Path) -> list[Path]:
    """The figures of a finished explicit or static run (not its analyses): sensor signals,
    B-scans, final fields, damage and, for plates with snapshot times, the wavefield per layer."""
    from peridyn.plotting.fields import plot_run

    figures = plot_run(out, body)
    if case.geometry.type == "plate" and case.output.snapshot_times:
        from peridyn.plotting.lamb_wavefield import plot_wavefield_snapshots

        _, times, _ = read_series(out / "results.h5", "field_u")
        reached = [t for t in case.output.snapshot_times if t <= times[-1] * (1 + 1e-9)]
        if reached:
            figures.append(plot_wavefield_snapshots(out / "results.h5", out / "wavefield.png",
                                                    reached))
        figures += _actuator_figures(case, out, reached)
    return figures


def _actuator_figures(case: Case, out: Path, snapshot_times) -> list[Path]:
    """Through-thickness field under each actuator's cut (+-50 mm along x, at the middle
    snapshot) and the PZT sensor signals under the first actuator's excitation."""
    from peridyn.plotting.lamb_wavefield import plot_sensor_signals, plot_through_thickness

    figures = []
    length = case.geometry.size[0]
    for name, actuator in case.actuators.items():
        if snapshot_times:
            cx = actuator.center[0]
            x_range = (max(0.0, cx - 0.050), min(length, cx + 0.050))
            figures.append(plot_through_thickness(
                out / "results.h5", out / f"cut_{name}.png",
                snapshot_times[len(snapshot_times) // 2], actuator.center, x_range))
    if case.output.pzt_sensors and case.actuators:
        _, times, data = read_series(out / "results.h5", "pzt_signal")
        first = next(iter(case.actuators.values()))
        excitation = from_spec(first.signal, "actuators.signal")(times)
        signals = {n: data[:, k] for k, n in enumerate(case.output.pzt_sensors)}
        figures.append(plot_sensor_signals(times, signals, out / "pzt_sensors.png",
                                           excitation=excitation))
    return figures


def store_summary(results, body: Body, summary: dict) -> None:
    """(Re)write the run summary as JSON in ``/summary/json`` of a results file."""
    with HDF5Writer(results, body.points[:, : body.dim], body.volumes, {}, mode="a") as h5:
        h5.write_array("summary/json", np.bytes_(json.dumps(summary, default=_json_default)))


def _json_default(obj):
    return obj.tolist() if hasattr(obj, "tolist") else str(obj)


def _base_summary(setup: Setup, out: Path) -> dict:
    phi = damage_field(setup.model)
    return {"output_dir": str(out), "points": setup.body.n_points, "bonds": setup.bonds.n_bonds,
            "broken_bonds": int((~setup.bonds.intact).sum()), "max_damage": float(phi.max())}


def _run_explicit(case, setup, out, case_path, checkpoint_every, restart, progress,
                  solver=None) -> dict:
    """Time integration by ``solver`` (default: velocity Verlet from the case) with recording."""
    s = case.solver
    if solver is None:
        solver = ExplicitSolver(setup.model, setup.loading, dt=s.dt, safety=s.safety,
                                damping=explicit_damping(case, setup.body), damage=setup.damage,
                                contact=setup.contact)
    n_steps = s.steps if s.steps is not None else int(np.ceil(s.time / solver.dt - 1e-9))
    ckpt_path = out / "checkpoint.h5"
    if restart:
        state, intact = load_checkpoint(ckpt_path, setup.body.n_points, setup.bonds.n_bonds)
        setup.bonds.intact[:] = intact
        resume = (state.step, state.time)
    else:
        state, resume = solver.initial_state(), None
    spec = recorder_spec(case, setup.body, solver.dt)
    recorder = Recorder(setup.body, out, spec, provenance(case_path, case=case), setup.model, resume)
    if resume is None:
        recorder.record_series(state)
        recorder.snapshot(state)
    observers = [recorder]
    cracks = _crack_observer(case, setup, n_steps)
    if cracks is not None:
        observers.append(cracks)
    if checkpoint_every:
        observers.append(Checkpointer(ckpt_path, checkpoint_every, setup.bonds.intact))
    remaining = n_steps - state.step
    bar = progress(remaining) if progress is not None else None
    try:
        solver.run(state, remaining, observers, bar)
    finally:
        if bar is not None:
            bar.close()
    if state.step not in spec.snapshot_steps and not (
        spec.snapshot_every and state.step % spec.snapshot_every == 0
    ):
        recorder.snapshot(state)
    summary = _base_summary(setup, out)
    summary.update({"steps": state.step, "time_s": state.time, "dt_s": solver.dt,
                    "stable_dt_s": solver.stable_dt,
                    "kinetic_energy_j": solver.kinetic_energy(state),
                    "strain_energy_j": setup.model.strain_energy(state.u)})
    if setup.contact is not None:
        summary["contact_rebuilds"] = setup.contact.rebuilds
    if cracks is not None:
        summary["crack_length_history"] = cracks.history()
    recorder.finish(state)
    return summary


def explicit_damping(case: Case, body: Body):
    """``solver.damping`` (1/s), plus the absorbing layers' per-point damping when the case
    has them: a number or an (n_points,) array for ``ExplicitSolver``."""
    if case.absorbing is None:
        return case.solver.damping
    a = case.absorbing
    try:
        return case.solver.damping + layer_damping(body.points, a.width, a.damping, a.faces)
    except InputError as exc:
        raise CaseFileError(case.name, "absorbing", a.model_dump(), str(exc)) from None


def _crack_observer(case, setup, n_steps):
    """Crack length against time, sampled at the snapshots (or 100 times a run) of a case
    with damage; None without damage."""
    if setup.damage is None:
        return None
    from peridyn.analysis.crack import CrackLengthObserver

    every = case.output.snapshot_every or max(1, n_steps // 100)
    return CrackLengthObserver(setup.model, every)


def final_crack_paths(case: Case, body: Body, phi: np.ndarray):
    """Crack paths of the final damage field ``phi`` ((n_points,)) of ``body`` (pre-cracks as
    reference lines; 2D bodies or the x-y projection of 3D ones)."""
    from peridyn.analysis.crack import crack_paths

    lines = [(c.start, c.end) for c in case.precracks if c.type == "segment"]
    lines += [(c.origin, np.add(c.origin, c.edge_u)) for c in case.precracks
              if c.type == "rectangle"]
    return crack_paths(body.points, phi, body.spacing, reference_lines=lines)


def draw_crack_figures(body: Body, out: Path, paths, summary: dict) -> list[Path]:
    """Damage map on the deformed configuration (x50, as seed 004, or less) with the crack
    ``paths``, and the crack length against time when it was sampled; displacements and
    damage are the final ones of ``out``/results.h5."""
    from peridyn.io.hdf5 import read_array
    from peridyn.plotting.crack import plot_crack_length, plot_damage_map

    results = out / "results.h5"
    u, phi = read_array(results, "final/u"), read_array(results, "final/damage")
    figures = [plot_damage_map(body.points, u, phi, paths, out / "crack_paths.png")]
    history = summary.get("crack_length_history")
    if history and len(history["time_s"]) > 1:
        figures.append(plot_crack_length(history["time_s"], history["length_m"],
                                         out / "crack_length.png"))
    return figures


def redraw_crack_figures(case: Case, body: Body, out: Path):
    """Crack paths and figures (``draw_crack_figures``) of a finished run with damage, from
    its results.h5: the final damage and the crack length history of the stored summary.
    Returns (paths, figure paths); (None, []) for a case without damage."""
    from peridyn.io.hdf5 import read_array

    if case.material.damage is None:
        return None, []
    results = out / "results.h5"
    summary = json.loads(read_array(results, "summary/json"))
    paths = final_crack_paths(case, body, read_array(results, "final/damage"))
    return paths, draw_crack_figures(body, out, paths, summary)


def _run_static(case, setup, out, case_path) -> dict:
    s = case.solver
    u = None
    iterations = 0
    for k in range(1, s.load_steps + 1):
        result = relax(setup.model, setup.loading, time=k / s.load_steps, u0=u,
                       tolerance=s.tolerance, max_iterations=s.max_iterations,
                       damage=setup.damage, contact=setup.contact)
        u, iterations = result.u, iterations + result.iterations
        if not result.converged:
            raise InputError(
                f"static load step {k}/{s.load_steps} did not converge in {s.max_iterations} "
                f"iterations (residual {result.residual:.3g} > {s.tolerance:g}): raise "
                "solver.max_iterations or solver.load_steps"
            )
    return _record_equilibrium(case, setup, out, case_path, u,
                               {"steps": s.load_steps, "iterations": iterations,
                                "residual": result.residual})


def _record_equilibrium(case, setup, out, case_path, u, results: dict) -> dict:
    """Record a quasi-static solution ``u`` as one state at t = 1 s; the run's summary."""
    state = State(u, np.zeros_like(u), np.zeros_like(u), 1.0, results["steps"])
    spec = recorder_spec(case, setup.body, 1.0)
    recorder = Recorder(setup.body, out, spec, provenance(case_path, case=case), setup.model)
    recorder.record_series(state)
    recorder.snapshot(state)
    summary = _base_summary(setup, out)
    summary.update(results)
    summary["strain_energy_j"] = setup.model.strain_energy(u)
    recorder.finish(state)
    return summary


def _newmark_solver(case, setup):
    """The implicit Newmark solver of a ``newmark`` case."""
    from peridyn.solvers.newmark import NewmarkSolver

    s = case.solver
    return NewmarkSolver(setup.model, setup.loading, dt=s.dt, tolerance=s.displacement_tolerance,
                         max_iterations=s.newton_iterations, damping=s.damping,
                         damage=setup.damage, linear_solver=s.linear_solver)


def _run_newton(case, setup, out, case_path) -> dict:
    """Newton-Raphson equilibrium of a ``newton`` case, recorded as one state at t = 1 s."""
    from peridyn.solvers.newton import newton

    s = case.solver
    result = newton(setup.model, setup.loading, load_steps=s.load_steps, tolerance=s.tolerance,
                    max_iterations=s.newton_iterations, damage=setup.damage,
                    max_breaking_rounds=s.breaking_rounds, linear_solver=s.linear_solver)
    if not result.converged:
        step = len(result.steps)
        raise InputError(
            f"Newton load step {step}/{s.load_steps} did not converge (residual "
            f"{result.residual:.3g}, tolerance {s.tolerance:g}, {s.newton_iterations} iterations, "
            f"{s.breaking_rounds} breaking rounds): raise solver.load_steps or "
            "solver.newton_iterations"
        )
    return _record_equilibrium(case, setup, out, case_path, result.u,
                               {"steps": s.load_steps, "iterations": result.iterations,
                                "residual": result.residual,
                                "residual_history": [step.residuals for step in result.steps]})
