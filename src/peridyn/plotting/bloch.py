"""Bloch-wave dispersion of a discrete plate or block against the continuum theory."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from peridyn.analysis.bloch import BlochLattice, bloch_cell, plate_basis
from peridyn.analysis.bloch_study import theory_wavenumbers

#: Wavenumbers drawn per discrete branch.
_POINTS = 120


def plot_bloch(disc: BlochLattice, path=None, frequencies=(), f_max: float | None = None) -> Figure:
    """Frequency (kHz) against wavenumber (rad/m): discrete branches solid, theory dashed.

    Plates: the lowest S, A and SH (even) branches and Rayleigh-Lamb S0, A0 and SH0;
    blocks: the P and S branches along x and k = omega / c. Frequencies of interest
    (Hz) are marked by dotted lines. Drawn on an Agg canvas, never in a window.

    Parameters
    ----------
    disc : BlochLattice
    path : str or os.PathLike, optional
        Where to save the figure as PNG.
    frequencies : sequence of float, Hz
    f_max : float, optional
        Top of the frequency axis, Hz (default 1.5 x the largest of ``frequencies``,
        or the top of the discrete branches).
    """
    cell = bloch_cell(disc)
    if disc.kind == "plate":
        bases = {
            "S0": plate_basis(cell, "S"),
            "A0": plate_basis(cell, "A"),
            "SH0": plate_basis(cell, "SH", 1),
        }
    else:
        bases = {"P": np.eye(3)[:, [0]], "S": np.eye(3)[:, [1]]}
    dx = disc.spacing
    k = np.linspace(0.0, np.pi / dx, _POINTS)
    curves = {
        name: np.array([cell.frequencies((kk, 0.0, 0.0), b)[0] for kk in k]) / (2 * np.pi)
        for name, b in bases.items()
    }
    top = f_max or (
        1.5 * max(frequencies) if len(frequencies) else max(float(c.max()) for c in curves.values())
    )
    fig = Figure(figsize=(7, 5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    f_theory = np.linspace(top / 60, top, 40)
    theory = theory_wavenumbers(disc, f_theory)
    for n, (name, f_disc) in enumerate(curves.items()):
        colour = f"C{n}"
        ax.plot(k, f_disc / 1e3, color=colour, label=f"{name} discrete")
        k0 = [theory.get((name, float(f))) for f in f_theory]
        pts = [(kk, f) for kk, f in zip(k0, f_theory, strict=True) if kk is not None]
        if pts:
            ax.plot(
                [p[0] for p in pts], [p[1] / 1e3 for p in pts], "--", color=colour, label=f"{name} theory"
            )
    for f in frequencies:
        ax.axhline(f / 1e3, color="0.6", linestyle=":", linewidth=0.8)
    ax.set_xlim(0, np.pi / dx)
    ax.set_ylim(0, top / 1e3)
    ax.set_xlabel("wavenumber k (rad/m)")
    ax.set_ylabel("frequency (kHz)")
    ax.set_title(
        f"{disc.model.upper()} {disc.kind}, dx {dx * 1e3:g} mm, horizon "
        f"{disc.horizon / dx:g} dx" + (f", {disc.layers} layers" if disc.layers else "")
    )
    ax.legend(fontsize=8)
    if path is not None:
        fig.savefig(Path(path), dpi=120)
    return fig
