"""Table and figure of the Lamb layer study (docs/lamb.md, "Layers through the thickness").

Reads the two sweeps' output folders:

- ``LAYERS``: ``peridyn sweep sweeps/lamb_layers.yaml -o LAYERS`` (the simulations; every run
  complete there is used, whichever sweep file ran it): each run's ``run.json`` gives the
  k-space ring wavenumbers of the top face (``kxky_rings_rad_m``) against Rayleigh-Lamb
  (``kxky_theory_rad_m``), its wall time and peak memory;
- ``BLOCH``: ``peridyn sweep sweeps/lamb_layers_bloch.yaml -o BLOCH`` (the Bloch prediction of
  every discretisation, ``bloch.<mode>.<f>.error`` in its dataset).

Prints the Markdown table (errors k / k0 - 1 in %, "simulation / Bloch", and the f-k
errors at 150 kHz of the x-axis line, ``fk_error``) and draws
``docs/figures/lamb_layers.png`` (S0 and A0 error against frequency: Bloch lines for all nine
discretisations, simulation markers where run). The runs not simulated show the estimated
peak memory (``peridyn validate``, :func:`peridyn.setup.estimate.estimate_case`).

    PYTHONPATH=src python docs/figures/lamb_layers.py LAYERS BLOCH [--doc]

``--doc`` also puts the table in docs/lamb.md in place of the one there (the first table after
the heading "Simulation against Bloch").
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from peridyn.io.dataset import load_sweep  # noqa: E402
from peridyn.jobs.sweep_run import read_record  # noqa: E402
from peridyn.jobs.sweep_spec import expand  # noqa: E402
from peridyn.setup.estimate import estimate_case  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SWEEP = ROOT / "sweeps" / "lamb_layers.yaml"
FIGURE = Path(__file__).with_name("lamb_layers.png")
DOC = ROOT / "docs" / "lamb.md"
HEADING = "### Simulation against Bloch"
MODES = ("S0", "A0")
FREQUENCIES = (110e3, 150e3, 185e3, 225e3)
#: The accuracy asked of a discretisation, |k / k0 - 1|.
TARGET = 0.015


def simulated(record: dict) -> dict:
    """``{(mode, f): error}`` of a complete run's k-space rings against Rayleigh-Lamb; NaN where
    the run's map shows no ring of that mode (the analysis found none)."""
    rings, theory = record["summary"]["kxky_rings_rad_m"], record["summary"]["kxky_theory_rad_m"]
    ring = {(m, f): rings[f"{f:g}"][m] for m in MODES for f in FREQUENCIES}
    return {
        (m, f): np.nan if ring[(m, f)] is None else ring[(m, f)] / theory[f"{f:g}"][m] - 1
        for m in MODES
        for f in FREQUENCIES
    }


def percent(error) -> str:
    """An error as a signed percentage, or "n/f" (no ring or peak found)."""
    return "n/f" if error is None or np.isnan(error) else f"{100 * error:+.1f}"


def bloch_errors(ds, layers: int, spacing: float) -> dict:
    """``{(mode, f): error}`` of the Bloch sweep's run with ``layers`` and ``spacing``."""
    (i,) = np.flatnonzero(
        (ds["geometry.layers"].values == layers) & np.isclose(ds["discretization.spacing"].values, spacing)
    )
    return {(m, f): float(ds[f"bloch.{m}.{f:g}.error"].values[i]) for m in MODES for f in FREQUENCIES}


def rows(layers_dir: Path, bloch_dir: Path) -> list[dict]:
    """One row per run of sweeps/lamb_layers.yaml, in its order."""
    sweep = expand(SWEEP)
    bloch = load_sweep(bloch_dir / "dataset.nc")
    out = []
    for run in sweep.runs:
        layers, spacing = run.parameters["geometry.layers"], run.parameters["discretization.spacing"]
        record = read_record(layers_dir / "runs" / run.run_id)
        done = record is not None and record["status"] == "complete" and record["case_hash"] == run.case_hash
        estimate = estimate_case(run.case, sweep.base.parent)
        out.append(
            {
                "layers": layers,
                "spacing": spacing,
                "points": estimate.points,
                "estimated_bytes": estimate.peak_bytes,
                "simulation": simulated(record) if done else None,
                "fk": record["summary"]["fk_error"] if done else None,
                "seconds": record["seconds"] if done else None,
                "peak_bytes": record["summary"]["peak_memory_bytes"] if done else None,
                "bloch": bloch_errors(bloch, layers, spacing),
            }
        )
    return out


def table(data: list[dict]) -> str:
    """The Markdown table: errors (%) simulation / Bloch, time and memory per run."""
    head = [f"{m} {f / 1e3:g} kHz" for m in MODES for f in FREQUENCIES]
    lines = [
        "| layers | dx (mm) | points | "
        + " | ".join(head)
        + " | f-k 150 kHz S0, A0 | wall time | peak memory |",
        "|---|---|---|" + "---|" * len(head) + "---|---|---|",
    ]
    for r in data:
        sim = r["simulation"]
        cells = [
            ("-" if sim is None else percent(sim[k])) + f" / {100 * r['bloch'][k]:+.1f}"
            for k in ((m, f) for m in MODES for f in FREQUENCIES)
        ]
        if sim is None:
            cost = f"- | not run | est. {r['estimated_bytes'] / 1e9:.1f} GB"
        else:
            fk = ", ".join(percent(r["fk"][m]) for m in MODES)
            cost = f"{fk} | {r['seconds']:.0f} s | {r['peak_bytes'] / 1e9:.2f} GB"
        lines.append(
            f"| {r['layers']} | {r['spacing'] * 1e3:g} | {r['points']:,} | "
            + " | ".join(cells)
            + f" | {cost} |"
        )
    return "\n".join(lines)


def within(errors: dict, mode: str) -> bool:
    """Whether ``mode`` is within :data:`TARGET` at every frequency."""
    return all(abs(errors[(mode, f)]) <= TARGET for f in FREQUENCIES)


def figure(data: list[dict], path: Path) -> Path:
    """S0 and A0 error (%) against frequency: lines Bloch, markers simulation."""
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True, layout="constrained")
    colours = {3: "tab:blue", 5: "tab:orange", 7: "tab:green"}
    styles = {1.2e-3: ("-", "o"), 0.6e-3: ("--", "s"), 0.4e-3: (":", "^")}
    f_khz = np.array(FREQUENCIES) / 1e3
    for ax, mode in zip(axes, MODES, strict=True):
        ax.axhspan(-100 * TARGET, 100 * TARGET, color="0.9", zorder=0)
        for r in data:
            line, marker = styles[r["spacing"]]
            label = f"{r['layers']} layers, {r['spacing'] * 1e3:g} mm"
            ax.plot(
                f_khz,
                [100 * r["bloch"][(mode, f)] for f in FREQUENCIES],
                line,
                color=colours[r["layers"]],
                label=label,
            )
            if r["simulation"] is not None:
                ax.plot(
                    f_khz,
                    [100 * r["simulation"][(mode, f)] for f in FREQUENCIES],
                    marker,
                    color=colours[r["layers"]],
                    mfc="none",
                )
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set(title=f"{mode}: lines Bloch, open markers simulation", xlabel="frequency (kHz)")
    axes[0].set_ylabel("wavenumber error k / k0 - 1 (%)")
    fig.legend(*axes[0].get_legend_handles_labels(), fontsize=8, loc="outside right center")
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def write_doc(text: str, path: Path = DOC) -> None:
    """Replace the first Markdown table after :data:`HEADING` in ``path`` with ``text``."""
    lines = path.read_text().splitlines(keepends=True)
    start = next(i for i, line in enumerate(lines) if line.startswith(HEADING))
    first = next(i for i in range(start, len(lines)) if lines[i].startswith("|"))
    end = next((i for i in range(first, len(lines)) if not lines[i].startswith("|")), len(lines))
    path.write_text("".join(lines[:first]) + text + "\n" + "".join(lines[end:]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("layers", type=Path, help="output folder of sweeps/lamb_layers.yaml")
    parser.add_argument("bloch", type=Path, help="output folder of sweeps/lamb_layers_bloch.yaml")
    parser.add_argument("--doc", action="store_true", help="also put the table in docs/lamb.md")
    args = parser.parse_args()
    data = rows(args.layers, args.bloch)
    print(table(data))
    if args.doc:
        write_doc(table(data))
    for source in ("bloch", "simulation"):
        hits = [
            f"{r['layers']} layers at {r['spacing'] * 1e3:g} mm"
            for r in data
            if r[source] is not None and within(r[source], "S0") and within(r[source], "A0")
        ]
        print(f"{source}: within {100 * TARGET:g} % on S0 and A0 at every frequency: {hits or 'none'}")
    print(f"figure: {figure(data, FIGURE)}")


if __name__ == "__main__":
    main()
