"""The recording plan of a run: what a case asks to record (``recorder_spec``), the per-point
tensors and named Exodus variables the recorder computes, the run's output folder and the
check that its records fit on the disk before anything is written."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from peridyn.discretization import geometry
from peridyn.discretization.body import Body
from peridyn.errors import InputError
from peridyn.io.case import Case
from peridyn.io.recorder import LineProbe, RecorderSpec
from peridyn.io.reserve import RESERVE_BYTES
from peridyn.physics.deformation import strain_field
from peridyn.physics.transducers import pzt_sensor_weights
from peridyn.setup.build import Setup, pad3
from peridyn.setup.exodus_variables import GatheredVariables, check_variables, variable_values

#: The results file in a run's output folder.
RESULTS = "results.h5"


def recorder_spec(case: Case, body: Body, dt: float) -> RecorderSpec:
    """What the case asks to record, with snapshot times turned into steps."""
    out = case.output
    planes = {name: body.node_set(set_name) for name, set_name in out.planes.items()}
    return RecorderSpec(
        every=out.every,
        snapshot_every=out.snapshot_every,
        snapshot_steps=[int(round(t / dt)) for t in out.snapshot_times],
        sensors={k: pad3(v) for k, v in out.sensors.items()},
        lines={k: LineProbe(pad3(v.start), pad3(v.end), v.points) for k, v in out.lines.items()},
        planes=planes,
        pzt_sensors={k: _pzt_weights(body, v) for k, v in out.pzt_sensors.items()},
        series_dtype=out.series_dtype,
        vtu=out.vtu,
        vtu_compression=out.vtu_compression,
        stress=out.stress,
        strain=out.strain,
        **exodus_spec(out.exodus),
        exodus_more=tuple(exodus_spec(more) for more in out.exodus_more),
    )


def exodus_spec(exodus) -> dict:
    """The recorder's Exodus settings of ``output.exodus`` (a bool or an ``ExodusOutput``)."""
    if isinstance(exodus, bool):
        return {"exodus": exodus}
    return {
        "exodus": True,
        "exodus_file": exodus.file,
        "exodus_every": exodus.every,
        "exodus_first": exodus.first_step,
        "exodus_last": exodus.last_step,
        "exodus_variables": tuple(exodus.variables),
        "exodus_sums": {k: (v.variable, v.set, v.calculation) for k, v in exodus.sums.items()},
        "exodus_order": exodus.point_order,
        "exodus_three_d": exodus.three_d,
        "exodus_named": True,
    }


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


def point_tensors(setup: Setup, spec: RecorderSpec):
    """The recorder's ``tensors``: u (n_points, 3) m -> the per-point ``stress`` (Pa) and
    ``strain`` (with ``strain_valid``) that ``output.stress`` and ``output.strain`` ask for,
    (n_points, dim, dim); None when neither is asked. Under MPI, of the rank's part (its owned
    rows are the serial ones: ``RootObservers`` gathers them)."""
    if not (spec.stress or spec.strain):
        return None
    dim = setup.body.dim

    def fields(u: np.ndarray) -> dict:
        out = {}
        if spec.stress:
            out["stress"] = setup.model.partial_stress(u)[:, :dim, :dim]
        if spec.strain:
            out["strain"], out["strain_valid"] = strain_field(setup.body, setup.model.bonds, u)
        return out

    return fields


def exodus_values(case: Case, setup: Setup, spec: RecorderSpec, force=None):
    """The recorder's ``fields``: the values of the named Exodus variables (``output.exodus``
    as a mapping) at a state, or None without them; under MPI a ``GatheredVariables``, whose
    ``collect`` every rank calls at the states recorded. ``force``: the internal force density
    at a state (``variable_values``; one process)."""
    if not spec.exodus_named:
        return None
    variables, sums = spec.all_exodus_variables()
    check_variables(case.name, setup.model, variables)
    if setup.domain.size > 1:  # each rank's owned values, gathered on rank 0 (``collect``)
        return GatheredVariables(setup.domain, setup.model, variables, sums, setup.whole_body, setup.loading)
    return variable_values(setup.model, variables, sums, setup.loading, force)


def check_output_fits(
    spec: RecorderSpec, body: Body, n_steps: int, dt: float, out: Path, damage: bool = False
) -> None:
    """Refuse a run whose records (``spec.output_bytes``, ``spec`` from ``recorder_spec``) would
    not fit in the free space of the disk of its output folder, before anything is written.

    Raises
    ------
    InputError
        Naming the steps, the bytes and the free space.
    """
    need = spec.output_bytes(body.n_points, n_steps, body.dim, damage) + RESERVE_BYTES
    folder = out.resolve()
    while not folder.exists():
        folder = folder.parent
    free = shutil.disk_usage(folder).free
    if need > free:
        raise InputError(
            f"the run's {n_steps:.3g} steps (dt = {dt:.3g} s) would write "
            + (
                f"about {need / 1e9:.3g} GB of results"
                if np.isfinite(need)
                else "more results than any disk holds"
            )
            + f", more than the {free / 1e9:.3g} GB free on {folder}: "
            "shorten solver.time or record less (output.every, output.snapshot_every)"
        )
