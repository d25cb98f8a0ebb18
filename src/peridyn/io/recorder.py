"""Recording a run: sensors, line and plane probes, field snapshots -> HDF5 and VTU/PVD.

Series in ``results.h5`` (see ``peridyn.io.hdf5`` for the layout):

- ``sensor_u``, ``sensor_v``: (n_sensors, 3) displacement (m) and velocity (m/s) of the
  points nearest to the named sensor positions (names in the series attribute ``names``);
- ``line_<name>``: (n, 3) displacement along a line probe;
- ``plane_<name>``: (n, 3) displacement of a plane probe (a node set or a plate layer);
- ``pzt_signal``: (n_pzt,) mean in-plane strain under each PZT sensor patch;
- ``field_u``: (n_points, 3) displacement at every snapshot, with ``snapshots/*.vtu``
  files (under MPI ``snapshots/*.pvtu`` and their per-rank pieces) and ``snapshots.pvd`` for
  ParaView, and ``results.e`` (Exodus II) when asked.

When asked (``stress``, ``strain``), the final fields ``final/stress`` (partial stress, Pa) and
``final/strain`` (Green-Lagrange strain) with ``final/strain_valid``, (n_points, dim, dim)
and (n_points,) bool (``peridyn.physics.deformation``), and the same point data in every VTU
snapshot (9 components, row-major, padded with zeros in 2D: a tensor for ParaView).

The series records are held in memory and written in blocks (``peridyn.io.series_buffer``:
at most ``SeriesBuffer``'s 8 MiB or 256 records per series), not one HDF5 append and flush
per record. ``Recorder.flush`` writes them: the owner of the run calls it before every
checkpoint (``peridyn.io.checkpoint.Checkpointer``'s ``before_save``), and ``finish`` and
``close`` (the end of the run, an error, an interruption) write them first, so a restart
from a checkpoint finds every record up to it. A process killed outright (SIGKILL) loses the
records held since the last flush, which all come after the last checkpoint when
checkpointing; the file itself stays readable (nothing is written to it between flushes).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from peridyn.discretization.body import Body
from peridyn.discretization.state import ProbeState, State, check_state, runaway_limit
from peridyn.errors import InputError
from peridyn.io.exodus_write import PERIDIGM_VARIABLES, ExodusWriter
from peridyn.io.hdf5 import CHUNK_BYTES, MIN_INDEX_CHUNK, HDF5Writer
from peridyn.io.netcdf import COMPONENTS
from peridyn.io.outdir import end_status
from peridyn.io.reserve import Reserve, as_disk_error, ensure_room
from peridyn.io.series_buffer import SeriesBuffer
from peridyn.io.vtk import PVDCollection, write_vtu


@dataclass
class LineProbe:
    """Points nearest to ``points`` samples evenly spaced from ``start`` to ``end`` (m)."""

    start: tuple
    end: tuple
    points: int


#: units and long names of the per-point tensor fields written in ``final/`` (``tensors``)
FINAL_TENSORS = {
    "stress": ("Pa", "stress (partial stress of the bonds)"),
    "strain": ("1", "strain (least squares over the bonds)"),
    "strain_valid": ("1", "whether the point's bonds determine its strain"),
}

#: Values per point of one snapshot in all files: field_u (3) in results.h5, points, u, v and
#: damage and volume in VTU (11) and u, v, volume and damage in Exodus (8), as 8-byte numbers.
SNAPSHOT_VALUES = 22


def _every_due(step: int, settings: dict) -> bool:
    """True when an Exodus file of ``settings`` (``exodus_every``, and optionally
    ``exodus_first`` and ``exodus_last``: ``RecorderSpec``'s) gets a record at ``step``."""
    last = settings.get("exodus_last")
    within = settings.get("exodus_first", 0) <= step and (last is None or step <= last)
    return within and step % settings["exodus_every"] == 0


@dataclass
class RecorderSpec:
    """What to record and how often.

    Attributes
    ----------
    every : int
        Steps between records of the sensor, line and plane series.
    snapshot_every : int or None
        Steps between field snapshots (None: only at ``snapshot_steps`` and the end).
    snapshot_steps : list of int
        Extra steps with a snapshot (e.g. the paper's 20, 40, 60 us).
    sensors : dict of name -> 3 floats (m)
    lines : dict of name -> LineProbe
    planes : dict of name -> (n,) point indices
    pzt_sensors : dict of name -> ((n,) point indices, (n, 2) weights)
        The signal is sum(weights * u[indices, :2]): the mean in-plane strain under a patch
        (see ``peridyn.physics.transducers.pzt_sensor_weights``).
    series_dtype : "float64" or "float32"
        Storage type of the line and plane series (float32 halves big records).
    vtu : bool
        Write VTU snapshots and a PVD collection.
    vtu_compression : {"none", "zlib"}
        Their data arrays' compression (``peridyn.io.vtk.write_vtu``).
    stress, strain : bool
        Write the per-point partial stress / Green-Lagrange strain (final fields and VTU).
    exodus : bool
        Write the snapshots to ``results.e`` (``snapshot_exodus``).
    exodus_file : str
        The Exodus file's name in the output folder.
    exodus_every : int or None
        Steps between Exodus records, written at these steps only (step 0 included); None:
        at every snapshot.
    exodus_first, exodus_last : int, int or None
        The first and last steps that may get an Exodus record (Peridigm's ``Initial Output
        Step`` and ``Final Output Step``; None: no last), with ``exodus_every``.
    exodus_variables : tuple of str
        Peridigm's names of the variables written (``peridyn.io.exodus_write.PERIDIGM_VARIABLES``),
        their values from the recorder's ``fields``; empty: ``snapshot_exodus``'s fields.
    exodus_sums : dict of name -> (variable, node set name, calculation)
        Global variables written with the named ones: a variable's sum, maximum or minimum
        over a set.
    exodus_order : {"peridyn", "grid"}
        The named variables' point order: the body's, or ``grid_order`` (x fastest, then y,
        then z: PdQuickGrid's numbering).
    exodus_three_d : bool
        Write a 2D body's named variables with three coordinates and vector components (z 0),
        as Peridigm does.
    exodus_named : bool
        The Exodus file holds the named variables and sums (``output.exodus`` as a mapping),
        not ``snapshot_exodus``'s fields.
    exodus_more : tuple of dict
        More Exodus files of named variables, each a dict of the ``exodus_*`` settings above
        (``exodus_file``, ``exodus_every``, ``exodus_variables``, ...), written at its own steps.
    """

    every: int = 1
    snapshot_every: int | None = None
    snapshot_steps: list = field(default_factory=list)
    sensors: dict = field(default_factory=dict)
    lines: dict = field(default_factory=dict)
    planes: dict = field(default_factory=dict)
    pzt_sensors: dict = field(default_factory=dict)
    series_dtype: str = "float64"
    vtu: bool = True
    vtu_compression: str = "none"
    exodus: bool = False
    exodus_file: str = "results.e"
    exodus_every: int | None = None
    exodus_first: int = 0
    exodus_last: int | None = None
    exodus_variables: tuple = ()
    exodus_sums: dict = field(default_factory=dict)
    exodus_order: str = "peridyn"
    exodus_three_d: bool = False
    exodus_more: tuple = ()
    exodus_named: bool = False
    stress: bool = False
    strain: bool = False

    def series_due(self, step: int) -> bool:
        """True when the probe series are recorded at ``step``."""
        return step % self.every == 0

    def snapshot_due(self, step: int) -> bool:
        """True when a field snapshot is written at ``step``."""
        return bool(self.snapshot_every and step % self.snapshot_every == 0) or step in self.snapshot_steps

    def exodus_due(self, step: int) -> bool:
        """True when an Exodus file gets a record at ``step``."""
        if any(_every_due(step, more) for more in self.exodus_more):
            return True
        return self.main_exodus_due(step)

    def main_exodus_due(self, step: int) -> bool:
        """True when the first Exodus file (``exodus_file``) gets a record at ``step``."""
        if not self.exodus:
            return False
        if self.exodus_every is None:
            return self.snapshot_due(step)
        return _every_due(
            step,
            {
                "exodus_every": self.exodus_every,
                "exodus_first": self.exodus_first,
                "exodus_last": self.exodus_last,
            },
        )

    def all_exodus_variables(self) -> tuple[list, dict]:
        """The named variables and global sums of every Exodus file, each once."""
        variables, sums = list(self.exodus_variables), dict(self.exodus_sums)
        for more in self.exodus_more:
            variables += [v for v in more["exodus_variables"] if v not in variables]
            sums |= more["exodus_sums"]
        return variables, sums

    def whole_due(self, step: int) -> bool:
        """True when something that reads the whole body (a snapshot, an Exodus record) is
        written at ``step``."""
        return self.snapshot_due(step) or self.exodus_due(step)

    def due(self, step: int) -> bool:
        """True when anything is recorded at ``step``."""
        return self.series_due(step) or self.whole_due(step)

    def output_bytes(self, n_points: int, n_steps: int, dim: int = 3, damage: bool = False) -> float:
        """Bytes a run of ``n_steps`` steps on ``n_points`` points of dimension ``dim`` (with a
        ``damage`` field or not) writes, about: results.h5 (the geometry, every series in whole
        chunks as ``peridyn.io.hdf5`` allocates them, the final u and v), the VTU snapshots
        (uncompressed: base64 of the points, u, v, damage, stress/strain and the vertex cells,
        ``VTU_CELL_BYTES`` a point; u and v padded to 3 components, the damage index always) and
        the Exodus snapshots (tests/simulation/test_run_safety.py compares it with what runs
        wrote)."""
        item = np.dtype(self.series_dtype).itemsize
        records = float(n_steps // self.every + 1)
        every = self.snapshot_every
        extra = {s for s in self.snapshot_steps if 0 < s <= n_steps} | ({n_steps} if n_steps > 0 else set())
        # step 0, the multiples of snapshot_every, the snapshot steps and the end, each once
        snapshots = (
            1.0
            + float(n_steps // every if every else 0)
            + sum(1 for s in extra if not (every and s % every == 0))
        )
        series = [(records, 6 * 8 * len(self.sensors))] * (2 if self.sensors else 0)
        series += [(records, 3 * item * line.points) for line in self.lines.values()]
        series += [(records, 3 * item * len(idx)) for idx in self.planes.values()]
        series += [(records, 8 * len(self.pzt_sensors))] if self.pzt_sensors else []
        series += [(snapshots, 3 * item * n_points)]
        h5 = sum(_chunked_bytes(k, b) for k, b in series if b) + n_points * 8.0 * (dim + 1 + 6 + damage)
        tensors = 72 * (self.stress + self.strain)
        vtu = snapshots * n_points * (4 / 3) * (3 * 3 * 8 + 8 + tensors + VTU_CELL_BYTES) if self.vtu else 0
        exodus = snapshots * n_points * 8.0 * (2 * dim + 1 + damage) if self.exodus else 0
        return float(h5 + vtu + exodus)


#: Bytes a point of a VTU snapshot holds besides its fields (before base64): its vertex cell's
#: connectivity and offset (8 bytes each), type (1 byte) and the arrays' headers: 24 fits the
#: 138.7 bytes a point measured in the snapshots of the 3D bar and of the 2D plate alike.
VTU_CELL_BYTES = 24


def _chunked_bytes(records: float, record_bytes: int) -> float:
    """Bytes of a series of ``records`` records of ``record_bytes`` in whole chunks, with its
    time and step datasets (``peridyn.io.hdf5``'s chunk sizes)."""
    per_chunk = max(1, CHUNK_BYTES // record_bytes)
    index = max(per_chunk, MIN_INDEX_CHUNK)
    return float(
        np.ceil(records / per_chunk) * per_chunk * record_bytes + 16.0 * np.ceil(records / index) * index
    )


class Recorder:
    """Observer of an explicit run that writes ``results.h5`` (and VTU files) incrementally.

    Parameters
    ----------
    body : Body
    directory : path
        Output folder (created).
    spec : RecorderSpec
    provenance : dict
        Stored as attributes of the results file.
    damage : callable () -> (n_points,) float64, or None
        The damage index of the current state, for snapshots and the final state (e.g.
        ``lambda: damage_field(model)``); None: no damage written.
    tensors : callable (u) -> dict of str to array, or None
        The per-point fields ``output.stress`` and ``output.strain`` ask for (``stress`` and
        ``strain`` (n_points, dim, dim), ``strain_valid`` (n_points,)) at displacement ``u``
        (n_points, 3), m, for snapshots and the final state; required when they are asked.
    resume : (step, time) or None
        Reopen an existing results file and drop the records after this step and
        time (s), for a restart from a checkpoint.
    fields : callable (state) -> dict, or None
        The values of ``spec.exodus_variables`` at a state: ``{"nodal": {...}, "element":
        {...}, "global_": {...}}`` of name -> array, as ``ExodusWriter.append`` takes them;
        required when variables are named.
    vtu_pieces : bool
        The VTU snapshots are per-rank pieces that the ranks of an MPI run write with their
        ``.pvtu`` (``peridyn.io.vtu_pieces``): ``snapshots.pvd`` lists the ``.pvtu`` files.
    probes : Probes or None
        The points the series read (``Probes.of(body, spec)``, computed when None): an MPI run
        gathers these only at a series record and passes a ``ProbeState`` to ``record_series``.
    """

    def __init__(
        self,
        body: Body,
        directory,
        spec: RecorderSpec,
        provenance: dict,
        damage=None,
        resume: tuple[int, float] | None = None,
        tensors=None,
        fields=None,
        vtu_pieces: bool = False,
        probes: Probes | None = None,
    ):
        self.body = body
        self.vtu_pieces = vtu_pieces
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.spec = spec
        self.damage = damage
        self.tensors = tensors
        if spec.every < 1:
            raise InputError(f"output.every must be at least 1, got {spec.every}")
        if (spec.stress or spec.strain) and tensors is None:
            raise InputError("output.stress and output.strain need a tensors function: the recorder has none")
        self.probes = probes if probes is not None else Probes.of(body, spec)
        index = self.probes.index
        self.sensor_names = list(spec.sensors)
        self.sensor_index = self.probes.v_points
        self.line_index = {name: index[f"line_{name}"] for name in spec.lines}
        self.plane_index = {name: index[f"plane_{name}"] for name in spec.planes}
        #: where ``record_series`` reads each series in a whole state's u: global rows (a
        #: plate layer's as a slice, ``rows_of``)
        self._point_rows = {
            key: rows_of(idx) if key.startswith("plane_") else idx for key, idx in index.items()
        }
        mode = "a" if resume is not None else "w"
        self.reserve = Reserve(self.directory)  # room to close the files on a full disk
        self.h5 = HDF5Writer(
            self.directory / "results.h5",
            body.points[:, : body.dim],
            body.volumes,
            provenance,
            mode=mode,
            flush_every=None,
        )
        self.series = SeriesBuffer(self.h5)
        self.h5.set_status("running")
        self._create_series()
        self.max_displacement = runaway_limit(body.points)
        self.pvd = None
        if spec.vtu:
            (self.directory / "snapshots").mkdir(exist_ok=True)
            self.pvd = PVDCollection(self.directory / "snapshots.pvd", mode=mode)
        if spec.exodus_named and fields is None:
            raise InputError("named Exodus variables need a fields function: the recorder has none")
        self.fields = fields
        self._exodus_step = None  # the step of the last Exodus record
        self.exodus = None
        self._rows = grid_order(body.points) if spec.exodus_order == "grid" else None
        self._dim = 3 if spec.exodus_three_d else body.dim
        if spec.exodus and spec.exodus_named:
            self.exodus = variables_exodus(
                body,
                self.directory / spec.exodus_file,
                spec.exodus_variables,
                spec.exodus_sums,
                rows=self._rows,
                dim=self._dim,
            )
        elif spec.exodus:
            self.exodus = snapshot_exodus(body, self.directory / spec.exodus_file, damage is not None)
        self._more = [
            (
                more,
                variables_exodus(
                    body,
                    self.directory / more["exodus_file"],
                    more["exodus_variables"],
                    more["exodus_sums"],
                    rows=self._rows,
                    dim=self._dim,
                ),
            )
            for more in spec.exodus_more
        ]
        if resume is not None:
            self.h5.truncate(resume[0])
            if self.pvd is not None:
                self.pvd.truncate(resume[1])
            if self.exodus is not None:
                self.exodus.resume(resume[1])
            for _, writer in self._more:
                writer.resume(resume[1])

    def _create_series(self) -> None:
        h5, spec = self.h5, self.spec
        vector = ("point", "component")
        if self.sensor_names:
            for q, units, what in (("u", "m", "displacement"), ("v", "m/s", "velocity")):
                h5.create_series(
                    f"sensor_{q}",
                    (len(self.sensor_names), 3),
                    attrs={"names": self.sensor_names, "points": self.sensor_index.tolist()},
                    dims=("sensor", "component"),
                    coords={"sensor": self.sensor_names},
                    units=units,
                    long_name=f"{what} at the sensors",
                )
        for name, idx in self.line_index.items():
            h5.create_series(
                f"line_{name}",
                (len(idx), 3),
                spec.series_dtype,
                attrs={"points": idx.tolist()},
                dims=vector,
                coords={"point": idx},
                units="m",
                long_name=f"displacement along line {name}",
            )
        for name, idx in self.plane_index.items():
            h5.create_series(
                f"plane_{name}",
                (len(idx), 3),
                spec.series_dtype,
                dims=vector,
                coords={"point": idx},
                units="m",
                long_name=f"displacement on plane {name}",
            )
            h5.write_array(
                f"probes/plane_{name}", idx, {"long_name": f"points of plane {name}", "units": "1"}
            )
        if spec.pzt_sensors:
            h5.create_series(
                "pzt_signal",
                (len(spec.pzt_sensors),),
                attrs={"names": list(spec.pzt_sensors)},
                dims=("sensor",),
                coords={"sensor": list(spec.pzt_sensors)},
                long_name="PZT sensor signal: weighted mean in-plane strain under the sensor",
            )
        h5.create_series(
            "field_u",
            (self.body.n_points, 3),
            spec.series_dtype,
            dims=vector,
            units="m",
            long_name="displacement",
        )

    def observe(self, state: State, solver) -> None:
        """Record what is due at this step (called after every step)."""
        if self.spec.series_due(state.step):
            self.record_series(state)
        if self.spec.snapshot_due(state.step):
            self.snapshot(state)
        elif self.spec.exodus_every is not None and self.spec.exodus_due(state.step):
            self.write_exodus(state)

    def record_series(self, state: State | ProbeState) -> None:
        """Append one record to every probe series, from the whole body's ``state`` or from the
        values at the probe points only (a ``ProbeState`` in ``probes``' order, checked by
        whoever gathered it).

        Raises
        ------
        InstabilityError
            The whole ``state`` is not finite or runs away (``check_state``): nothing is written.
        """
        if isinstance(state, ProbeState):
            rows, sensor_rows = self.probes.slices, slice(None)
        else:
            check_state(state, self.max_displacement)
            rows, sensor_rows = self._point_rows, self.sensor_index
        h5, step, t = self.series, state.step, state.time
        if self.sensor_names:
            h5.append("sensor_u", step, t, state.u, rows["sensor_u"])
            h5.append("sensor_v", step, t, state.v, sensor_rows)
        for name in self.line_index:
            h5.append(f"line_{name}", step, t, state.u, rows[f"line_{name}"])
        for name in self.plane_index:
            h5.append(f"plane_{name}", step, t, state.u, rows[f"plane_{name}"])
        if self.spec.pzt_sensors:
            signals = [
                np.sum(w * state.u[rows[f"pzt_{k}"], :2]) for k, (_, w) in self.spec.pzt_sensors.items()
            ]
            h5.append("pzt_signal", step, t, np.array(signals))

    def snapshot(self, state: State, checked: bool = False) -> None:
        """Write the whole displacement field (HDF5, and VTU when enabled); raises
        InstabilityError, writing nothing, for a non-finite or runaway state (unless
        ``checked``: the ranks of an MPI run checked it together, and ``state`` holds u alone)."""
        if not checked:
            check_state(state, self.max_displacement)
        self.series.append("field_u", state.step, state.time, state.u)
        if self.exodus is not None and (self.spec.exodus_every is None or self.spec.exodus_due(state.step)):
            self.write_exodus(state, at_snapshot=True)
        if self.pvd is None:
            return
        if self.vtu_pieces:  # written by the ranks (peridyn.io.vtu_pieces)
            self.pvd.add(state.time, snapshot_name(state.step, ".pvtu"))
            return
        damage = self.damage() if self.damage is not None else None
        body = self.body
        data = snapshot_fields(state.u, state.v, body.dim, damage, self._tensor_fields(state.u), body.volumes)
        name = snapshot_name(state.step, ".vtu")
        ensure_room(self.directory / name, 8.0 * SNAPSHOT_VALUES * self.body.n_points)
        try:
            write_vtu(
                self.directory / name,
                self.body.points[:, : self.body.dim],
                data,
                self.spec.vtu_compression,
                state.time,
            )
        except OSError as exc:  # a part-written snapshot is no snapshot (and frees its room)
            (self.directory / name).unlink(missing_ok=True)
            raise as_disk_error(exc, self.directory / name) from exc
        self.pvd.add(state.time, name)

    def write_exodus(self, state: State, at_snapshot: bool = False) -> None:
        """Append ``state`` to the Exodus files due at its step (once per step: the end-of-run
        snapshot of a step already written adds nothing); the first file, without a frequency
        of its own, at the snapshots (``at_snapshot``)."""
        if state.step == self._exodus_step:
            return
        self._exodus_step = state.step
        spec = self.spec
        main = spec.main_exodus_due(state.step) if spec.exodus_every is not None else at_snapshot
        if not spec.exodus_named:
            if main:
                self.exodus.append(state.time, **exodus_fields(self.body, state, self.damage))
            return
        values = self.fields(state)
        if main:
            self.exodus.append(
                state.time,
                **arranged(chosen(values, spec.exodus_variables, spec.exodus_sums), self._rows, self._dim),
            )
        for more, writer in self._more:
            if _every_due(state.step, more):
                picked = chosen(values, more["exodus_variables"], more["exodus_sums"])
                writer.append(state.time, **arranged(picked, self._rows, self._dim))

    def flush(self) -> None:
        """Write the series records held in memory and flush the file (before a checkpoint)."""
        self.series.flush()

    def finish(self, state: State) -> None:
        """Write the held records and the final state, then close the file (on a failure,
        closed as by :meth:`close` with the failure's status). The reserve stays until the
        run's owner deletes it (the summary is written after)."""
        try:
            fields = {"u": state.u, "v": state.v}
            if self.damage is not None:
                fields["damage"] = self.damage()
            fields.update(self._tensor_fields(state.u))
        except Exception as exc:
            self.close(end_status(exc))
            raise
        for key, value in fields.items():
            self.write_final(key, value)
        self.finished()

    def final_keys(self) -> list[str]:
        """The fields ``finish`` writes when no tensor field is asked for: ``u``, ``v`` and,
        with a damage index, ``damage``."""
        return ["u", "v", *(["damage"] if self.damage is not None else [])]

    def finished(self) -> None:
        """Close the file after the final state (``finish``, or ``write_final`` field by field);
        the reserve stays until the run's owner deletes it."""
        self.h5.close()

    def write_final(self, key: str, value: np.ndarray) -> None:
        """Write one field of the final state, ``final/<key>`` (the whole body's ``u``, ``v``,
        ``damage`` or a tensor field), after the held records; on a failure, close the file
        as :meth:`close` does, with the failure's status. ``finish`` writes every field; under
        MPI they may come one at a time (``RootObservers.finish``), and :meth:`finished`
        closes the file after them."""
        try:
            self.flush()
            if key in ("u", "v"):
                about = {"u": ("m", "displacement"), "v": ("m/s", "velocity")}[key]
                self.h5.write_array(
                    f"final/{key}", value, {"units": about[0], "long_name": about[1]}, ("point", "component")
                )
            elif key == "damage":
                about = {"units": "1", "long_name": "damage: share of the point's bonds broken"}
                self.h5.write_array("final/damage", value, about, ("point",))
            else:
                units, long_name = FINAL_TENSORS.get(key, ("1", key))
                dims = ("point", "row", "column")[: np.ndim(value)]
                labels = COMPONENTS[: np.shape(value)[-1]]
                coords = {"row": labels, "column": labels}
                self.h5.write_array(
                    f"final/{key}", value, {"units": units, "long_name": long_name}, dims, coords
                )
        except Exception as exc:
            self.close(end_status(exc))
            raise

    def _tensor_fields(self, u: np.ndarray) -> dict:
        """The per-point tensor fields asked for (``tensors``), or none."""
        return self.tensors(u) if self.tensors is not None else {}

    def close(self, status: str | None = None) -> None:
        """Close the file early (failure, interruption), setting its ``status`` when given,
        after writing the records held. The room of the run's ``Reserve`` is given back first,
        so that on a full disk the records held, the status and the file's closing are written
        all the same."""
        self.reserve.release()
        try:
            self.flush()
        finally:
            if status is not None:
                self.h5.set_status(status)
            self.h5.close()


@dataclass(frozen=True)
class Probes:
    """The points whose values a recorder's series read (``Recorder.record_series``).

    Attributes
    ----------
    index : dict of str -> (n,) int
        Global point indices of each series' displacement, in this order: ``sensor_u`` (the
        points nearest to the sensors, when there are sensors), ``line_<name>`` (nearest to
        each line's samples), ``plane_<name>`` (each plane's points) and ``pzt_<name>`` (the
        points under each PZT sensor patch, ``RecorderSpec.pzt_sensors``' indices).
    u_points : (k,) int
        Their concatenation in that order (a point may appear in several series).
    slices : dict of str -> slice
        Each series' rows of ``u_points``.
    v_points : (s,) int
        The sensors' points, whose velocity ``sensor_v`` records.
    """

    index: dict
    u_points: np.ndarray
    slices: dict
    v_points: np.ndarray

    @classmethod
    def of(cls, body: Body, spec: RecorderSpec) -> Probes:
        """The probes of ``spec`` in ``body`` (the whole body's points)."""
        tree = cKDTree(body.points)
        index = {}
        if spec.sensors:
            index["sensor_u"] = tree.query(np.array(list(spec.sensors.values())))[1]
        for name, p in spec.lines.items():
            index[f"line_{name}"] = tree.query(np.linspace(p.start, p.end, p.points))[1]
        for name, idx in spec.planes.items():
            index[f"plane_{name}"] = np.asarray(idx)
        for name, (idx, _) in spec.pzt_sensors.items():
            index[f"pzt_{name}"] = np.asarray(idx)
        ends = np.cumsum([0, *(len(idx) for idx in index.values())])
        slices = {key: slice(int(a), int(b)) for key, a, b in zip(index, ends[:-1], ends[1:], strict=True)}
        u_points = np.concatenate([np.zeros(0, dtype=np.int64), *index.values()])
        return cls(index, u_points, slices, index.get("sensor_u", np.zeros(0, dtype=np.int64)))


def rows_of(index: np.ndarray) -> np.ndarray | slice:
    """``index`` (k,) of rows as a slice when it is an increasing arithmetic progression (the
    layer of a plate: every ``layers``-th point), so that ``u[rows]`` is a view, copied once;
    else ``index`` itself. ``u[rows_of(index)]`` has the values of ``u[index]``."""
    index = np.asarray(index)
    if len(index) < 2:
        return index
    step = int(index[1] - index[0])
    if step < 1 or np.any(np.diff(index) != step):
        return index
    return slice(int(index[0]), int(index[-1]) + 1, step)


def snapshot_name(step: int, suffix: str) -> str:
    """The VTU snapshot of ``step`` in the output folder: ``snapshots/step_NNNNNNNN`` + ``suffix``."""
    return f"snapshots/step_{step:08d}{suffix}"


def snapshot_fields(
    u: np.ndarray, v: np.ndarray, dim: int, damage, tensors: dict, volumes: np.ndarray
) -> dict:
    """The point data of a VTU snapshot: displacement and velocity ((n, 3) m, m/s, first ``dim``
    columns), the points' ``volume`` ((n,) m^3), the ``damage`` index ((n,) or None) and the
    ``tensors`` (``Recorder``'s ``tensors``: (n, dim, dim) as 9 components, others as they are)."""
    data = {"displacement": u[:, :dim], "velocity": v[:, :dim], "volume": volumes}
    if damage is not None:
        data["damage"] = damage
    for key, value in tensors.items():
        data[key] = _padded_tensor(value)
    return data


def _padded_tensor(values: np.ndarray) -> np.ndarray:
    """A VTU point field: (n, dim, dim) tensors as (n, 9) rows, zero-padded to 3 x 3 in 2D;
    other shapes pass through."""
    if values.ndim != 3:
        return values
    full = np.zeros((len(values), 3, 3), dtype=values.dtype)
    full[:, : values.shape[1], : values.shape[2]] = values
    return full.reshape(len(values), 9)


def snapshot_exodus(body: Body, path, damage: bool = False) -> ExodusWriter:
    """An Exodus writer of snapshots: nodal ``Displacement`` and ``Velocity`` (m, m/s), element
    ``Volume`` (m^3) and, with ``damage``, ``Damage``; one block, the body's node sets."""
    element = {"Volume": 1, **({"Damage": 1} if damage else {})}
    sets = {k: v for k, v in body.node_sets.items() if len(v)}
    return ExodusWriter(
        path,
        body.points[:, : body.dim],
        node_sets=sets,
        nodal={"Displacement": body.dim, "Velocity": body.dim},
        element=element,
    )


def grid_order(points: np.ndarray) -> np.ndarray:
    """(n,) indices of ``points`` ((n, 3), m) ordered x fastest, then y, then z: a grid's
    points as PdQuickGrid numbers them."""
    return np.lexsort((points[:, 0], points[:, 1], points[:, 2]))


#: Variables that number the file's points: they count in the file's order, not the body's.
POSITIONAL = ("Element_Id", "ID")


def arranged(values: dict, rows: np.ndarray | None, dim: int) -> dict:
    """``ExodusWriter.append``'s keyword arguments ``values`` (``variable_values``'s) with the
    per-point arrays in the order ``rows`` ((n,) body indices, or None: the body's; the
    ``POSITIONAL`` ones stay) and vectors padded with zero components to ``dim``."""
    out = {}
    for placement, fields in values.items():
        out[placement] = {}
        for name, array in fields.items():
            array = np.asarray(array)
            if rows is not None and placement != "global_" and name not in POSITIONAL:
                array = array[rows]
            if array.ndim >= 1 and placement == "global_" and array.shape[-1] < dim:
                array = np.concatenate([array, np.zeros(dim - array.shape[-1])])
            elif array.ndim == 2 and array.shape[1] < dim:
                array = np.hstack([array, np.zeros((len(array), dim - array.shape[1]))])
            out[placement][name] = array
    return out


def chosen(values: dict, variables, sums) -> dict:
    """The part of ``values`` (``ExodusWriter.append``'s keyword arguments) that one file
    writes: its ``variables`` and its global ``sums``."""
    return {
        placement: {
            k: v for k, v in fields.items() if k in variables or (placement == "global_" and k in sums)
        }
        for placement, fields in values.items()
    }


def variables_exodus(body: Body, path, variables, sums=None, rows=None, dim=None) -> ExodusWriter:
    """An Exodus writer of Peridigm's named ``variables`` (``PERIDIGM_VARIABLES`` gives each one's
    placement, nodal or element, and size) and global vectors named by ``sums``' keys, one
    block, the body's node sets; the points in the order ``rows`` ((n,) body indices, None:
    the body's), with ``dim`` coordinates (default the body's; 3 in 2D: z = 0). Of global
    variables only, the file is a history file, as Peridigm writes one: a single point at the
    origin."""
    dim = body.dim if dim is None else dim
    fields = {"nodal": {}, "element": {}, "global": {}}
    for name in variables:
        placement, vector = PERIDIGM_VARIABLES[name]
        fields[placement][name] = dim if vector else 1
    global_ = fields["global"] | {
        k: dim if PERIDIGM_VARIABLES[v[0]][1] else 1 for k, v in (sums or {}).items()
    }
    if not fields["nodal"] and not fields["element"]:  # global variables only: a history file
        return ExodusWriter(path, np.zeros((1, dim)), global_=global_)
    position = np.arange(body.n_points)
    if rows is not None:
        position[rows] = np.arange(body.n_points)
    sets = {k: np.sort(position[v]) for k, v in body.node_sets.items() if len(v)}
    points = np.zeros((body.n_points, dim))
    points[:, : body.dim] = body.points[:, : body.dim]
    return ExodusWriter(
        path,
        points if rows is None else points[rows],
        node_sets=sets,
        nodal=fields["nodal"],
        element=fields["element"],
        global_=global_,
    )


def exodus_fields(body: Body, state: State, damage=None) -> dict:
    """The fields of ``snapshot_exodus`` at ``state``, as keyword arguments of ``append``
    (``damage``: the recorder's callable, or None)."""
    element = {"Volume": body.volumes}
    if damage is not None:
        element["Damage"] = damage()
    return {
        "nodal": {"Displacement": state.u[:, : body.dim], "Velocity": state.v[:, : body.dim]},
        "element": element,
    }
