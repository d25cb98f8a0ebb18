"""The monitoring job's bonds transfer against a direct run on the damaged body
(docs/monitoring.md, "Where they must agree, and how far they do"): the clean-crack job of
tests/simulation/test_monitor_transfer.py (the small notched-hole plate, its fatigue confined to
the notch's plane y = 20 mm, interrogated at 5.5 and 6.5 mm of crack) against the fatigue run on
the 3D wave plate itself and interrogated with its own broken bonds (a ``bonds`` pre-crack of
their 3D ends), at the cycles where the 3D crack first reaches the same lengths by the same tip
rule.

The 3D fatigue case is the wave case's body (plate, grid, layers, material, hole and notch) with
the 2D fatigue case's node sets, loads and fatigue block. Its bonds fail about ten times more
slowly in cycles, so its steps are ten times longer (20 000 cycles): the crack then grows by
about as many steps a millimetre as in the 2D life (30 against 36 steps from 1.5 to 6.5 mm).

    PYTHONPATH=src python benchmarks/monitoring_transfer_direct.py [OUTPUT_DIR]

Prints, for the path that the crack crosses, each index by the bonds route, the cut and the
direct run, and ``|bonds - direct| / bonds`` (the job's ``|route - check| / route``); and how
far past the tip rule's point each fatigue model's broken bonds reach along the plane.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

from peridyn.analysis.shm.indices import correlation_index, residual_energy_index
from peridyn.analysis.shm.windows import window_masks
from peridyn.io.case import load_case, validate_case
from peridyn.io.monitor_case import load_monitor_case
from peridyn.io.results import Results
from peridyn.jobs.fatigue import run_fatigue_case
from peridyn.jobs.monitor import network_case, read_history, run_monitor
from peridyn.jobs.run import run_case

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases" / "monitoring"
#: The crack plane (y, m) and the notch root (x, m).
PLANE_Y, ROOT_X = 0.020, 0.020
INDICES = {"residual_energy_index": residual_energy_index, "correlation_index": correlation_index}


def cases(folder: Path) -> None:
    """The clean-crack monitoring case (its 2D fatigue case, the wave case) and the 3D fatigue case."""
    fatigue = yaml.safe_load((CASES / "monitor_small_fatigue.yaml").read_text())
    fatigue["fatigue"]["crack_plane"] = {"axis": "y", "at": PLANE_Y}
    fatigue["fatigue"]["mapping"] = [{"steps": 80, "tau": 5.0e-4}]
    (folder / "fatigue.yaml").write_text(yaml.safe_dump(fatigue))
    wave = yaml.safe_load((CASES / "monitor_small_wave.yaml").read_text())
    direct = dict(fatigue, name="monitor_small_fatigue_3d")
    for key in ("geometry", "discretization", "material", "removals", "precracks"):
        direct[key] = wave[key]
    direct["fatigue"] = dict(fatigue["fatigue"], mapping=[{"steps": 110, "tau": 5.0e-5}])
    (folder / "fatigue_3d.yaml").write_text(yaml.safe_dump(direct))
    mon = yaml.safe_load((CASES / "monitor_small.yaml").read_text())
    mon.update(
        fatigue_case="fatigue.yaml",
        wave_case=str(CASES / mon["wave_case"]),
        schedule={"every_crack_growth": 5.5e-3, "until_crack_length": 6.5e-3},
        output={"plots": False},
    )
    (folder / "monitor.yaml").write_text(yaml.safe_dump(mon))


def reach(history, cycles: float, crack_length: float) -> float:
    """How far (m) past the tip rule's point the bonds broken by ``cycles`` reach along the plane."""
    broken = history.broken_pairs[history.break_cycle <= cycles]
    a, b = history.points[broken[:, 0]], history.points[broken[:, 1]]
    x = a[:, 0] + (PLANE_Y - a[:, 1]) / (b[:, 1] - a[:, 1]) * (b[:, 0] - a[:, 0])
    return float(x.max() - (ROOT_X + crack_length))


def direct_signals(folder: Path, history_dir: Path, lengths) -> np.ndarray:
    """(n_lengths, n_paths, n_t) the path signals of the wave plate with the 3D fatigue's broken
    bonds at the first step whose crack reaches each of ``lengths`` (m)."""
    import meshio

    mon, base = load_monitor_case(folder / "monitor.yaml")
    wave = load_case(base / mon.wave_case)
    history = read_history(history_dir)
    points = np.asarray(meshio.read(history_dir / "damage.vtu").points, dtype=float)
    n = len(mon.transducers.centers)
    out = []
    for a in lengths:
        k = int(np.argmax(history.crack_length >= a - 1e-9))
        broken = history.broken_pairs[history.break_cycle <= history.cycles[k]]
        print(
            f"3D crack {history.crack_length[k] * 1e3:.2f} mm at {history.cycles[k]:.0f} cycles, "
            f"{len(broken)} bonds broken, reach past the tip "
            f"{reach(history, history.cycles[k], history.crack_length[k]) * 1e3:.2f} mm",
            file=sys.stderr,
        )
        by_actuator = []
        for i in range(n):
            data = network_case(mon, wave, i).model_dump(mode="python")
            data["name"] = f"direct_a{a * 1e3:.2f}mm_t{i}"
            pairs = points[broken].reshape(-1, 6).tolist()
            data["precracks"].append(
                {"type": "bonds", "pairs": pairs, "tolerance": 0.25 * wave.discretization.spacing}
            )
            run_dir = folder / "direct" / data["name"]
            run_case(validate_case(data, data["name"]), run_dir, base_dir=base, overwrite=True)
            by_actuator.append(np.asarray(Results(run_dir / "results.h5").series("pzt_signal")[2], float))
        out.append([0.5 * (by_actuator[i][:, j] + by_actuator[j][:, i]) for i, j in _paths(n)])
    return np.array(out)


def _paths(n: int):
    return [(i, j) for i in range(n) for j in range(i + 1, n)]


def main(folder: Path) -> None:
    start = time.perf_counter()
    folder.mkdir(parents=True, exist_ok=True)
    cases(folder)
    summary = run_monitor(
        folder / "monitor.yaml", folder / "job", executor="processes", workers=2, threads=1, overwrite=True
    )
    m = summary["monitoring"]
    history = read_history(folder / "job" / "fatigue")
    run_fatigue_case(
        load_case(folder / "fatigue_3d.yaml"), folder / "fatigue_3d", base_dir=folder, overwrite=True
    )
    ds = xr.open_dataset(folder / "job" / "monitoring.nc", engine="h5netcdf")
    lengths = ds["crack_length"].values[m["transfer"]["interrogations"]]
    for a in lengths:
        k = int(np.argmax(history.crack_length >= a - 1e-9))
        print(
            f"2D crack {a * 1e3:.2f} mm at {history.cycles[k]:.0f} cycles, reach past the tip "
            f"{reach(history, history.cycles[k], a) * 1e3:.2f} mm",
            file=sys.stderr,
        )
    signals = ds["signal_noise_free"].values
    masks = window_masks(ds["time"].values, np.stack([ds["window_start"].values, ds["window_end"].values], 1))
    direct = direct_signals(folder, folder / "fatigue_3d", lengths)
    crossed = ds["crossed"].values.astype(bool)
    t = m["transfer"]
    for name, index in INDICES.items():
        d = np.stack([index(signals[0], s, masks)[crossed] for s in direct])
        bonds, cut = np.array(t[name]["bonds"]), np.array(t[name]["cut"])
        for k, a in enumerate(lengths):
            rel = np.abs(bonds[k] - d[k]) / bonds[k]
            print(
                f"{name} at {a * 1e3:.2f} mm: bonds {bonds[k].round(3).tolist()} "
                f"cut {cut[k].round(3).tolist()} direct {d[k].round(3).tolist()}  "
                f"|bonds - direct| / bonds {(rel * 100).round(1).tolist()} %",
                file=sys.stderr,
            )
    print(f"wall time {time.perf_counter() - start:.0f} s", file=sys.stderr)


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else "peridyn-out/monitoring-transfer-direct"))
