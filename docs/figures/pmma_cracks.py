"""Table and figure of ``sweeps/pmma_cracks.yaml`` (docs/sweeps.md, "Shipped sweeps").

Reads the sweep's dataset (``peridyn sweep sweeps/pmma_cracks.yaml -o OUT``): the frequency
change of the healthy plate's modes, paired by MAC (``frequency_change.<mode>``), against the
crack size, one panel per crack kind (edge: length along y; back: depth from the back face).
Prints the Markdown table (%, and the lowest MAC of the run's paired modes) and draws
``docs/figures/pmma_cracks.png``.

    PYTHONPATH=src python docs/figures/pmma_cracks.py OUT
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from peridyn.io.dataset import load_sweep  # noqa: E402

FIGURE = Path(__file__).with_name("pmma_cracks.png")
#: The healthy plate's modes shown (dataset names after ``frequency_change.``).
MODES = ("1st_bending", "1st_torsional", "2nd_bending", "1st_in-plane_bending")
KINDS = {"edge": "edge crack length (mm)", "back": "back-face crack depth (mm)"}


def table(ds) -> str:
    """Frequency change (%) of :data:`MODES` and the lowest MAC, one row per run."""
    macs = [n for n in ds.data_vars if n.startswith("mac.")]
    head = " | ".join(m.replace("_", " ") for m in MODES)
    lines = [f"| crack | size (mm) | {head} | MAC (lowest) |", "|---|---|" + "---|" * len(MODES) + "---|"]
    for i in range(ds.sizes["run"]):
        changes = " | ".join(f"{100 * float(ds[f'frequency_change.{m}'].values[i]):+.1f}" for m in MODES)
        lowest = min(float(ds[n].values[i]) for n in macs)
        lines.append(
            f"| {ds['crack'].values[i]} | {1e3 * float(ds['size'].values[i]):g} | {changes} | {lowest:.2f} |"
        )
    return "\n".join(lines)


def figure(ds, path: Path) -> Path:
    """Frequency change (%) against crack size, a line per mode, a panel per crack kind."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for ax, (kind, xlabel) in zip(axes, KINDS.items(), strict=True):
        runs = np.flatnonzero(ds["crack"].values == kind)
        size_mm = 1e3 * ds["size"].values[runs]
        for mode in MODES:
            ax.plot(
                size_mm, 100 * ds[f"frequency_change.{mode}"].values[runs], "o-", label=mode.replace("_", " ")
            )
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set(xlabel=xlabel, title=f"{kind} crack")
    axes[0].set_ylabel("frequency change (%)")
    axes[1].legend(fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="output folder of sweeps/pmma_cracks.yaml")
    ds = load_sweep(parser.parse_args().out / "dataset.nc")
    print(table(ds))
    print(f"figure: {figure(ds, FIGURE)}")


if __name__ == "__main__":
    main()
