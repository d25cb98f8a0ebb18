"""Table and figure of ``sweeps/lamb_damage.yaml`` (docs/sweeps.md, "Shipped sweeps").

Reads the sweep's dataset (``peridyn sweep sweeps/lamb_damage.yaml -o OUT``): each run's four
PZT sensor signals (``pzt_signal``) and the healthy plate's (``reference_pzt_signal``, the
sweep's reference run). The residual r = s - s_healthy is the wave the damage scattered. For
each run and sensor:

- damage index DI = sum r^2 / sum s_healthy^2 (the scattered energy against the healthy
  signal's);
- arrival: the time of the largest Hilbert envelope of r, kept where that envelope reaches
  ``HEARD`` of the run's largest (the sensors that hear the damage) and peaks half a burst
  before the record ends (a later peak is cut off by the record's end);
- path: actuator centre -> damage centre -> sensor centre, m.

An arrival lies near the line t = t0 + path / c_g of the mode that carried the burst there
and back (t0: the burst's centre time, cycles / 2 / frequency): the largest envelope is mostly
the scattered A0 wave (the slower, larger flexural wave), the S0 one where A0 comes after the
record. Each arrival is given to the mode whose line of the discrete plate is nearer, and the
script fits c_g of each mode through t0 and prints it beside the group velocities of
Rayleigh-Lamb theory and of the discrete plate (Bloch, the case's own discretisation: dω/dk from
the wavenumbers at the frequency ± ``DF``), at the burst's centre frequency. Prints the
Markdown tables (runs, DI median and maximum by damage type and size; how the scattered energy
grows with the size at each position; the group velocities) and
draws ``docs/figures/lamb_damage.png``.

    PYTHONPATH=src python docs/figures/lamb_damage.py OUT
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy.signal import hilbert  # noqa: E402

from peridyn.analysis.lamb import lamb_modes  # noqa: E402
from peridyn.io.case import load_case  # noqa: E402
from peridyn.io.dataset import load_sweep  # noqa: E402
from peridyn.jobs.sweep_run import bloch_prediction  # noqa: E402

FIGURE = Path(__file__).with_name("lamb_damage.png")
#: Fraction of a run's largest residual envelope a sensor must reach to count as hearing it.
HEARD = 0.2
#: Half step (Hz) of the Bloch group velocity's central difference.
DF = 5.0e3


def sweep_geometry(ds) -> dict:
    """The base case as run (``case``), actuator and sensor centres (m), sensor names, burst
    frequency (Hz) and centre time (s)."""
    manifest = json.loads((Path(ds.encoding["source"]).parent / "sweep.json").read_text())
    base = load_case(
        manifest["base_case"], [f"{k}={json.dumps(v)}" for k, v in manifest["spec"]["set"].items()]
    )
    actuator = next(iter(base.actuators.values()))
    names = [str(n) for n in ds["pzt_signal_axis1"].values]
    frequency = float(actuator.signal["frequency"])
    return {
        "case": base,
        "actuator": np.asarray(actuator.center[:2], dtype=float),
        "sensors": np.array([base.output.pzt_sensors[n].center[:2] for n in names], dtype=float),
        "names": names,
        "frequency": frequency,
        "centre_time": float(actuator.signal["cycles"]) / 2 / frequency,
    }


def residuals(ds) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(runs (m,) indices of the complete runs, times (k,) s, r (m, k, 4)): each complete run's
    signals less the healthy plate's."""
    runs = np.flatnonzero(ds["status"].values == "complete")
    healthy = ds["reference_pzt_signal"].values
    times = ds["reference_pzt_signal_time"].values
    k = len(times)
    signals = ds["pzt_signal"].values[runs, :k]
    if not np.array_equal(ds["pzt_signal_time"].values[runs, :k], np.broadcast_to(times, (len(runs), k))):
        raise ValueError("the runs' records are not at the healthy run's times")
    return runs, times, signals - healthy


def arrivals(times: np.ndarray, r: np.ndarray, burst: float) -> np.ndarray:
    """(m, 4) time (s) of each sensor's largest residual envelope; NaN where that envelope is
    under HEARD of the run's largest or peaks within ``burst`` / 2 (s) of the record's end."""
    envelope = np.abs(hilbert(r, axis=1))
    peak = envelope.max(axis=1)
    at = times[envelope.argmax(axis=1)]
    kept = (peak >= HEARD * peak.max(axis=1, keepdims=True)) & (at <= times[-1] - burst / 2)
    return np.where(kept, at, np.nan)


def paths(ds, runs: np.ndarray, geometry: dict) -> np.ndarray:
    """(m, 4) actuator -> damage -> sensor distance, m."""
    damage = np.stack([ds["x"].values[runs], ds["y"].values[runs]], axis=1)
    out_leg = np.linalg.norm(damage - geometry["actuator"], axis=1)
    back_leg = np.linalg.norm(damage[:, None, :] - geometry["sensors"][None, :, :], axis=2)
    return out_leg[:, None] + back_leg


def group_velocities(geometry: dict) -> dict:
    """``{mode: {"Rayleigh-Lamb": c, "Bloch": c}}``: S0 and A0 group velocities (m/s) at the
    burst frequency of theory and of the discrete plate (2 DF 2 pi / (k(f + DF) - k(f - DF)))."""
    case, f = geometry["case"], geometry["frequency"]
    m = case.material
    modes = lamb_modes(m.E, m.nu, m.density, float(case.geometry.size[2]), f, 0)
    bloch = bloch_prediction(case, [f - DF, f + DF])
    out = {}
    for mode in modes:
        k = bloch[mode.mode]
        dk = k[f"{f + DF:g}"]["wavenumber_rad_m"] - k[f"{f - DF:g}"]["wavenumber_rad_m"]
        out[mode.mode] = {"Rayleigh-Lamb": mode.group_velocity_m_s, "Bloch": 2 * np.pi * 2 * DF / dk}
    return out


def fitted_speeds(path: np.ndarray, arrival: np.ndarray, t0: float, speeds: dict) -> dict:
    """``{mode: (c (m/s), n arrivals)}``: least-squares c of arrival = t0 + path / c over the
    finite arrivals nearer that mode's Bloch line than the other's."""
    ok = np.isfinite(arrival)
    d, t = path[ok], arrival[ok] - t0
    lines = {mode: d / c["Bloch"] for mode, c in speeds.items()}
    nearest = np.argmin(np.abs(np.stack(list(lines.values())) - t), axis=0)
    out = {}
    for index, mode in enumerate(lines):
        dm, tm = d[nearest == index], t[nearest == index]
        out[mode] = (float(dm @ dm / (dm @ tm)) if dm.size else float("nan"), int(dm.size))
    return out


def table(ds, runs: np.ndarray, di: np.ndarray) -> str:
    """Runs and damage index (median and maximum over runs of each run's largest DI of the four
    sensors) by damage type and size."""
    lines = ["| damage | size (mm) | runs | DI median | DI max |", "|---|---:|---:|---:|---:|"]
    kinds, sizes = ds["damage"].values[runs], ds["size"].values[runs]
    largest = di.max(axis=1)
    for kind in sorted(set(kinds)):
        for size in sorted(set(sizes[kinds == kind])):
            pick = (kinds == kind) & (sizes == size)
            lines.append(
                f"| {kind} | {1e3 * size:g} | {pick.sum()} | {np.median(largest[pick]):.2e} | "
                f"{largest[pick].max():.2e} |"
            )
    return "\n".join(lines)


def size_growth(ds, runs: np.ndarray, di: np.ndarray) -> str:
    """For each damage type, over the positions run at every size: the share of positions whose
    scattered energy (DI summed over the four sensors) grows from each size to the next, and the
    median ratio."""
    lines = [
        "| damage | sizes (mm) | positions | energy grows at | median ratio |",
        "|---|---|---:|---:|---:|",
    ]
    total = di.sum(axis=1)
    kinds, sizes = ds["damage"].values[runs], ds["size"].values[runs]
    for kind in sorted(set(kinds)):
        at = {}
        for i in np.flatnonzero(kinds == kind):
            key = (float(ds["x"].values[runs[i]]), float(ds["y"].values[runs[i]]))
            at.setdefault(key, {})[float(sizes[i])] = total[i]
        steps = sorted(set(sizes[kinds == kind]))
        full = np.array([[row[s] for s in steps] for row in at.values() if len(row) == len(steps)])
        for a in range(len(steps) - 1):
            ratio = full[:, a + 1] / full[:, a]
            lines.append(
                f"| {kind} | {1e3 * steps[a]:g} -> {1e3 * steps[a + 1]:g} | {len(full)} | "
                f"{np.mean(ratio > 1):.0%} | {np.median(ratio):.2f} |"
            )
    return "\n".join(lines)


def figure(ds, runs, times, r, di, path_m, arrival, geometry, speeds, fit, out: Path) -> Path:
    """Damage map (marker area by DI), the strongest run's residuals, arrivals against paths."""
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.4), constrained_layout=True)
    ax = axes[0]
    kinds = ds["damage"].values[runs]
    largest = di.max(axis=1)
    for kind, marker in (("hole", "o"), ("notch", "s")):
        pick = kinds == kind
        ax.scatter(
            1e3 * ds["x"].values[runs][pick],
            1e3 * ds["y"].values[runs][pick],
            s=20 + 300 * largest[pick] / largest.max(),
            marker=marker,
            alpha=0.5,
            label=kind,
        )
    ax.plot(*(1e3 * geometry["actuator"]), "k*", ms=12, label="actuator")
    ax.plot(*(1e3 * geometry["sensors"].T), "kv", ms=8, label="sensors")
    ax.set(xlabel="x (mm)", ylabel="y (mm)", aspect="equal", title="damage (marker area: largest DI)")
    ax.legend(fontsize=7, loc="lower left")
    ax = axes[1]
    example = int(np.argmax(largest))
    for s, name in enumerate(geometry["names"]):
        ax.plot(1e6 * times, r[example, :, s], lw=0.8, label=name)
    run = runs[example]
    ax.set(
        xlabel="t (us)",
        ylabel="residual signal",
        title=f"{ds['damage'].values[run]} {1e3 * ds['size'].values[run]:g} mm at "
        f"({1e3 * ds['x'].values[run]:.0f}, {1e3 * ds['y'].values[run]:.0f}) mm",
    )
    ax.legend(fontsize=7)
    ax = axes[2]
    ax.plot(1e3 * path_m.ravel(), 1e6 * arrival.ravel(), "k.", ms=3, label="residual envelope peak")
    lengths = np.linspace(0.0, np.nanmax(path_m), 50)
    t0 = geometry["centre_time"]
    for (mode, c), color in zip(speeds.items(), ("C0", "C1"), strict=True):
        ax.plot(1e3 * lengths, 1e6 * (t0 + lengths / fit[mode][0]), "-", color=color, label=f"{mode} fit")
        ax.plot(1e3 * lengths, 1e6 * (t0 + lengths / c["Bloch"]), "--", color=color, label=f"{mode} Bloch")
        ax.plot(
            1e3 * lengths, 1e6 * (t0 + lengths / c["Rayleigh-Lamb"]), ":", color=color, label=f"{mode} theory"
        )
    ax.set(xlabel="actuator -> damage -> sensor (mm)", ylabel="arrival (us)", title="arrivals")
    ax.legend(fontsize=7)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="the sweep's output folder")
    args = parser.parse_args(argv)
    ds = load_sweep(args.out / "dataset.nc")
    geometry = sweep_geometry(ds)
    runs, times, r = residuals(ds)
    healthy = ds["reference_pzt_signal"].values
    di = (r**2).sum(axis=1) / (healthy**2).sum(axis=0)
    path_m = paths(ds, runs, geometry)
    arrival = arrivals(times, r, 2 * geometry["centre_time"])
    speeds = group_velocities(geometry)
    fit = fitted_speeds(path_m.ravel(), arrival.ravel(), geometry["centre_time"], speeds)
    print(table(ds, runs, di))
    print()
    print(size_growth(ds, runs, di))
    print(
        f"\n{len(runs)} of {ds.sizes['run']} runs complete; "
        f"group velocity at {geometry['frequency'] / 1e3:g} kHz (m/s):"
    )
    print("| mode | fitted (arrivals) | Bloch, discrete plate | Rayleigh-Lamb |\n|---|---:|---:|---:|")
    for mode, c in speeds.items():
        print(
            f"| {mode} | {fit[mode][0]:.0f} ({fit[mode][1]}) | {c['Bloch']:.0f} | {c['Rayleigh-Lamb']:.0f} |"
        )
    figure(ds, runs, times, r, di, path_m, arrival, geometry, speeds, fit, FIGURE)
    print(f"figure: {FIGURE}")


if __name__ == "__main__":
    main()
