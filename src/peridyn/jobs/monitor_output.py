"""What a monitoring job writes: ``monitoring.nc`` (one netCDF-4 dataset, units and long_name on
every variable), the figures (drawn from the dataset, so that ``peridyn plot`` redraws them from
the file: ``redraw_figures``) and ``monitor.json`` (the summary with its ``monitoring`` block)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from peridyn.errors import InputError
from peridyn.io.dataset import load_dataset, require_xarray, write_dataset
from peridyn.io.job_files import write_json_file, write_summary
from peridyn.jobs.monitor_assess import assess
from peridyn.jobs.summary import finish_summary
from peridyn.plotting.monitoring import FIGURE_VARIABLES, draw_monitoring_figures

#: The dataset of a monitoring job in its output folder.
DATASET = "monitoring.nc"


def write_outputs(mon, wave, plan, data: dict, out: Path, start: float) -> dict:
    """Process the signals, write the dataset, figures and summary; returns the summary."""
    result = assess(mon, wave, plan, data)
    ds = monitoring_dataset(mon, wave, plan, data, result)
    write_dataset(ds, out / DATASET)
    plots = draw_monitoring_figures(ds, out) if mon.output.plots else []
    summary = {
        "monitoring": result["monitoring"],
        "dataset": str(out / DATASET),
        "cycles": plan.cycles.tolist(),
    }
    finish_summary(summary, "monitor", out, start, plots)
    from peridyn.jobs.monitor import SUMMARY

    write_json_file(out / SUMMARY, summary, "summary")
    write_summary(out, summary)  # the output contract's copy (peridyn.io.job_files)
    return summary


def redraw_figures(out) -> list[Path]:
    """The figures of the monitoring job in folder ``out`` drawn again from its ``monitoring.nc``
    (``peridyn plot``); returns their paths.

    Raises
    ------
    InputError
        ``out`` holds no ``monitoring.nc``, or one without a variable that the figures need.
    """
    path = Path(out) / DATASET
    ds = load_dataset(path, "monitoring dataset")
    missing = [name for name in FIGURE_VARIABLES if name not in ds.variables]
    if missing:
        raise InputError(
            f"{str(path)!r} has no {', '.join(missing)} (written by an older peridyn): remove "
            "monitor.json and run peridyn monitor again (its runs are kept)"
        )
    return draw_monitoring_figures(ds, out)


#: long_name of the crack polylines' vertices in the dataset.
CRACK_VERTICES = "{} of the crack polylines' vertices (main crack first, NaN between branches)"


def branches(lines: list) -> np.ndarray:
    """(m, 2) the crack ``lines`` ((m_i, 2) polylines, m: the main crack and its branches) one
    after the other, a NaN row between two (a drawn line breaks there); (0, 2) without one."""
    rows = []
    for line in lines:
        rows += [np.full((1, 2), np.nan)] if rows else []
        rows.append(np.asarray(line, dtype=float))
    return np.vstack(rows) if rows else np.empty((0, 2))


def monitoring_dataset(mon, wave, plan, data: dict, result: dict):
    """The xarray Dataset of the job (dimensions interrogation, path, time, transducer, vertex,
    image_y, image_x, cracked_point)."""
    xr = require_xarray()
    labels = [f"t{i}-t{j}" for i, j in plan.paths]
    drawn = [branches(lines) for lines in plan.lines]
    crack = np.full((len(drawn), max([len(c) for c in drawn] + [1]), 2), np.nan)
    for k, c in enumerate(drawn):
        crack[k, : len(c)] = c
    tip = np.array([c[-1] if c is not None else [np.nan, np.nan] for c in plan.cracks])
    h = plan.history
    cracked = np.isfinite(h.first_break)
    lx, ly = wave.geometry.size[:2]
    ip, ipath, it = ("interrogation",), ("interrogation", "path"), ("interrogation", "path", "time")
    strain = "1"  # pzt_signal: mean in-plane strain under a patch
    variables = {
        "cycles": (ip, plan.cycles, "1", "fatigue cycles at the interrogation"),
        "crack_length": (ip, plan.crack_length, "m", "crack length from the notch root"),
        "crack_tip_x": (ip, tip[:, 0], "m", "x of the crack tip"),
        "crack_tip_y": (ip, tip[:, 1], "m", "y of the crack tip"),
        "crack_x": (("interrogation", "vertex"), crack[:, :, 0], "m", CRACK_VERTICES.format("x")),
        "crack_y": (("interrogation", "vertex"), crack[:, :, 1], "m", CRACK_VERTICES.format("y")),
        "signal": (it, result["recorded"], strain, "path signal (mean of both directions), noise included"),
        "signal_noise_free": (it, data["signals"], strain, "path signal (mean of both directions), no noise"),
        "residual_energy_index": (ipath, result["residual_energy_index"], "1", "residual energy index"),
        "correlation_index": (ipath, result["correlation_index"], "1", "correlation index 1 - Pearson rho"),
        "window_start": (("path",), result["windows"][:, 0], "s", "start of the first-arrival window"),
        "window_end": (("path",), result["windows"][:, 1], "s", "end of the first-arrival window"),
        "direct_peak": (
            ("path",),
            result["direct_peak"],
            strain,
            "baseline peak in the first-arrival window",
        ),
        "crossed": (
            ("path",),
            result["crossed"].astype(np.int8),
            "1",
            "1 if the final crack crosses the path",
        ),
        "path_actuator": (("path",), plan.paths[:, 0], "1", "index of the path's first transducer"),
        "path_sensor": (("path",), plan.paths[:, 1], "1", "index of the path's second transducer"),
        "plate_size_x": ((), lx, "m", "plate's extent along x"),
        "plate_size_y": ((), ly, "m", "plate's extent along y"),
        "cracked_point_x": (("cracked_point",), h.points[cracked, 0], "m", "x of a point with a broken bond"),
        "cracked_point_y": (("cracked_point",), h.points[cracked, 1], "m", "y of a point with a broken bond"),
        "first_break_cycle": (
            ("cracked_point",),
            h.first_break[cracked],
            "1",
            "fatigue cycle of the point's first broken bond",
        ),
        "transducer_x": (("transducer",), plan.transducers[:, 0], "m", "x of the transducer centre"),
        "transducer_y": (("transducer",), plan.transducers[:, 1], "m", "y of the transducer centre"),
        "image": (("interrogation", "image_y", "image_x"), result["image"], "1", "RAPID damage image"),
        "image_peak_x": (ip, result["image_peak"][:, 0], "m", "x of the image's peak"),
        "image_peak_y": (ip, result["image_peak"][:, 1], "m", "y of the image's peak"),
        "crack_centre_x": (ip, result["crack_centre"][:, 0], "m", "x of the crack's centre (halfway along)"),
        "crack_centre_y": (ip, result["crack_centre"][:, 1], "m", "y of the crack's centre (halfway along)"),
        "image_peak_error": (
            ip,
            result["image_peak_error"],
            "m",
            "distance of the image peak from the crack centre",
        ),
    }
    ds = xr.Dataset(
        {name: (dims, np.asarray(values)) for name, (dims, values, _, _) in variables.items()},
        coords={
            "interrogation": np.arange(len(plan.steps)),
            "path": labels,
            "time": data["times"],
            "image_x": result["image_x"],
            "image_y": result["image_y"],
        },
    )
    for name, (_, _, units, long_name) in variables.items():
        ds[name].attrs.update(units=units, long_name=long_name)
    ds["interrogation"].attrs.update(units="1", long_name="interrogation (0: the baseline)")
    ds["path"].attrs.update(long_name="transducer pair")
    ds["time"].attrs.update(units="s", long_name="time after the burst starts")
    ds["image_x"].attrs.update(units="m", long_name="x of the image pixels")
    ds["image_y"].attrs.update(units="m", long_name="y of the image pixels")
    ds.attrs.update(
        title=f"peridyn monitoring job {mon.name}",
        index=mon.processing.index,
        noise_level=mon.noise.level,
        noise_seed=mon.noise.seed,
        Conventions="CF-1.8",
    )
    return ds
