"""The surface-correction study of docs/modal_study.md: run one model, or plot the results.

    PYTHONPATH=src python docs/figures/modal_study.py run SPACING HORIZON CORRECTION
    PYTHONPATH=src python docs/figures/modal_study.py plot
    PYTHONPATH=src python docs/figures/modal_study.py table
    PYTHONPATH=src python docs/figures/modal_study.py runs
    PYTHONPATH=src python docs/figures/modal_study.py lattice

``run`` solves the free PMMA plate of docs/reference-cases.md, V4 (LPS, no partial volumes) and
appends its six elastic frequencies, by type, to docs/figures/modal_study.json; ``plot``
draws docs/figures/modal_study_*.png from that file and ``table`` prints its Markdown table
(frequency in Hz and its deviation from FE in %, by type; then the deviations from the
thesis's Table 5.1 row of the same points and horizon, where it has one); ``runs`` prints each
run's time, peak memory and largest eigen-residual; ``lattice`` the long-wave stiffness of an
interior point (Bloch cell) against the continuum for each horizon.
"""

from __future__ import annotations

import json
import resource
import sys
import time
from pathlib import Path

import numpy as np

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.jobs.modal import modal_table
from peridyn.physics.materials import LPSModel

#: 6 rigid + 8 elastic: the 1st in-plane bending can come 7th on coarse grids
N_MODES = 14
HERE = Path(__file__).parent
RESULTS = HERE / "modal_study.json"
#: modes by type (docs/reference-cases.md, V4): 1st bending, 1st torsional, 2nd torsional, 2nd bending,
#: 1st transverse bending, 1st in-plane bending
TYPES = [
    ("bending", 1),
    ("torsional", 1),
    ("torsional", 2),
    ("bending", 2),
    ("transverse bending", 1),
    ("in-plane bending", 1),
]
LABELS = ["1B", "1T", "2T", "2B", "TB", "IPB"]
FE = [1706.1, 1982.9, 4268.0, 4542.4, 6607.0, 6868.0]
#: the thesis's Table 5.1 (Freimanis 2019) by (points, horizon / h); it has no 135k row at 3h
THESIS = {
    (40000, 1.4143): [1656.45, 1961.24, 4213.43, 4421.60, 6463.92, 6855.45],
    (40000, 2.001): [1666.51, 1882.92, 4071.67, 4436.87, 6457.59, 6847.60],
    (40000, 3.001): [1603.36, 1854.61, 4005.40, 4287.40, 6236.04, 6774.63],
    (40000, 4.001): [1563.82, 1838.27, 3969.13, 4194.43, 6121.37, 6705.49],
    (135000, 1.4143): [1683.39, 1969.31, 4236.11, 4486.55, 6545.51, 6860.09],
}


def run(spacing: float, horizon: float, correction: str) -> dict:
    start = time.perf_counter()
    body = geometry.box((0.100, 0.050, 0.008), spacing)
    bonds = find_bonds(body, horizon * spacing, partial_volumes=False)
    model = LPSModel(body, bonds, E=5.35e9, nu=0.33, density=1200.0, surface_correction=correction)
    _, _, rows = modal_table(model, N_MODES)
    by_type = {}  # the lowest mode of each type and order
    for r in rows:
        if r["type"] != "rigid":
            by_type.setdefault((r["type"], r["order"]), r["frequency_hz"])
    record = {
        "points": body.n_points,
        "spacing": spacing,
        "horizon": horizon,
        "correction": correction,
        "frequencies": [by_type.get(t) for t in TYPES],
        "max_residual": max(r["residual"] for r in rows),
        "seconds": time.perf_counter() - start,
        "peak_memory_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6,
    }
    records = json.loads(RESULTS.read_text()) if RESULTS.exists() else []
    records = [
        r
        for r in records
        if (r["points"], r["horizon"], r["correction"]) != (record["points"], horizon, correction)
    ] + [record]
    RESULTS.write_text(json.dumps(records, indent=1))
    return record


def plot() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    records = json.loads(RESULTS.read_text())
    colours = {"none": "tab:red", "shear-factor": "tab:blue", "energy": "tab:green"}
    for points in sorted({r["points"] for r in records}):
        horizons = sorted({r["horizon"] for r in records if r["points"] == points})
        fig, axes = plt.subplots(
            1, len(horizons), figsize=(4.2 * len(horizons), 3.6), sharey=True, squeeze=False
        )
        for ax, horizon in zip(axes[0], horizons, strict=True):
            rows = [r for r in records if r["points"] == points and r["horizon"] == horizon]
            x = np.arange(len(LABELS))
            width = 0.8 / (len(rows) + 1)
            for k, r in enumerate(sorted(rows, key=lambda r: list(colours).index(r["correction"]))):
                dev = [
                    100 * (f / fe - 1) if f else np.nan for f, fe in zip(r["frequencies"], FE, strict=True)
                ]
                ax.bar(x + k * width, dev, width, color=colours[r["correction"]], label=r["correction"])
            thesis = THESIS.get((points, horizon))
            if thesis:
                ax.bar(
                    x + len(rows) * width,
                    [100 * (f / fe - 1) for f, fe in zip(thesis, FE, strict=True)],
                    width,
                    color="0.6",
                    label="thesis Table 5.1",
                )
            ax.axhline(0, color="k", lw=0.8)
            ax.axhspan(-1.5, 1.5, color="0.9", zorder=0)
            ax.set_xticks(x + 0.4 - width / 2, LABELS)
            ax.set_title(f"{points} points, horizon {horizon:g} h")
            ax.grid(axis="y", alpha=0.3)
        axes[0, 0].set_ylabel("frequency vs continuum FE (%)")
        axes[0, -1].legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(HERE / f"modal_study_{points}.png", dpi=120)
        plt.close(fig)


def table() -> str:
    lines = [
        "| points | horizon | correction | " + " | ".join(LABELS) + " | max abs dev | vs Table 5.1 |",
        "|---|---|---|" + "---|" * (len(LABELS) + 2),
    ]
    records = sorted(
        json.loads(RESULTS.read_text()), key=lambda r: (r["points"], r["horizon"], r["correction"])
    )
    for r in records:
        devs = [100 * (f / fe - 1) if f else None for f, fe in zip(r["frequencies"], FE, strict=True)]
        cells = [f"{f:.1f} ({d:+.2f})" if f else "-" for f, d in zip(r["frequencies"], devs, strict=True)]
        worst = max(abs(d) for d in devs if d is not None)
        thesis = THESIS.get((r["points"], r["horizon"]))
        vs_thesis = (
            "-"
            if thesis is None
            else ", ".join(f"{100 * (f / t - 1):+.1f}" for f, t in zip(r["frequencies"], thesis, strict=True))
        )
        lines.append(
            f"| {r['points']} | {r['horizon']:g} h | {r['correction']} | "
            + " | ".join(cells)
            + f" | {worst:.2f} % | {vs_thesis} |"
        )
    return "\n".join(lines)


def runs() -> str:
    """Markdown table of each run's time, peak memory and largest eigen-residual."""
    lines = [
        "| points | horizon | correction | time (s) | peak memory (GB) | max eigen-residual |",
        "|---|---|---|---|---|---|",
    ]
    for r in sorted(
        json.loads(RESULTS.read_text()), key=lambda r: (r["points"], r["horizon"], r["correction"])
    ):
        lines.append(
            f"| {r['points']} | {r['horizon']:g} h | {r['correction']} | "
            f"{r['seconds']:.0f} | {r['peak_memory_gb']:.2f} | {r['max_residual']:.1e} |"
        )
    return "\n".join(lines)


def lattice() -> str:
    """Long-wave stiffness of an interior point against the continuum, in %, from the Bloch
    cell of this plate's material at each horizon: shear modulus from cS^2 and P-wave modulus
    M = K + 4 mu / 3 from cL^2, along [100] and [111]."""
    from peridyn.analysis.bloch import BlochLattice, bloch_cell

    young, nu, rho = 5.35e9, 0.33, 1200.0
    mu = young / (2 * (1 + nu))
    p_modulus = young * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    lines = [
        "| horizon | correction | mu [100] | mu [111] | M [100] | M [111] |",
        "|---|---|---|---|---|---|",
    ]
    for horizon in (1.4143, 2.001, 3.001, 4.001):
        for correction in ("none", "shear-factor"):
            cell = bloch_cell(
                BlochLattice(
                    spacing=1e-3,
                    horizon=horizon * 1e-3,
                    model="lps",
                    E=young,
                    nu=nu,
                    density=rho,
                    partial_volumes=False,
                    surface_correction=correction,
                )
            )
            cells = []
            for direction in ((1, 0, 0), (1, 1, 1)):
                c_s, _, c_l = cell.long_wave_speeds(direction)
                cells.append((100 * (rho * c_s**2 / mu - 1), 100 * (rho * c_l**2 / p_modulus - 1)))
            lines.append(
                f"| {horizon:g} h | {correction} | {cells[0][0]:+.1f} % | {cells[1][0]:+.1f} % | "
                f"{cells[0][1]:+.1f} % | {cells[1][1]:+.1f} % |"
            )
    return "\n".join(lines)


if __name__ == "__main__":
    if sys.argv[1] == "run":
        print(json.dumps(run(float(sys.argv[2]), float(sys.argv[3]), sys.argv[4])))
    elif sys.argv[1] == "table":
        print(table())
    elif sys.argv[1] == "runs":
        print(runs())
    elif sys.argv[1] == "lattice":
        print(lattice())
    else:
        plot()
