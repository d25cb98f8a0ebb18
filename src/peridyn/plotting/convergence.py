"""Convergence-study figure: frequency against spacing per mode type, with the extrapolation."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

#: Panels per row of the figure.
COLUMNS = 3


def plot_convergence(runs, fits, path=None, title: str | None = None) -> Figure:
    """One panel per mode type: frequency (Hz) against spacing (mm), one colour per horizon
    factor (the delta-m series). Where a fit exists, f_inf + C h^p is drawn dashed from
    h = 0 and f_inf marked at h = 0; a reference value (``reference_hz`` of a fit) is a
    dotted black line. Drawn on an Agg canvas, never in a window.

    Parameters
    ----------
    runs : list of peridyn.jobs.study.StudyRun
    fits : list of dict
        From :func:`peridyn.jobs.study.fit_series` (only ``delta-m`` rows are drawn).
    path : str or os.PathLike, optional
        Where to save the figure as PNG.
    """
    fits = [f for f in fits if f["series"] == "delta-m"]
    labels = list(dict.fromkeys(f["mode"] for f in fits))
    factors = sorted({r.horizon_factor for r in runs if r.skipped is None})
    rows = max(1, math.ceil(len(labels) / COLUMNS))
    fig = Figure(figsize=(4.2 * COLUMNS, 3.3 * rows + 0.5), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, COLUMNS, squeeze=False).ravel()
    h_max = max((r.spacing for r in runs), default=1.0)
    for ax, label in zip(axes, labels, strict=False):
        for i, m in enumerate(factors):
            colour = f"C{i % 10}"
            fit = next((f for f in fits if f["mode"] == label and f["group"] == f"horizon {m:g} h"), None)
            if fit is None or not fit["x"]:
                continue
            ax.plot(np.array(fit["x"]) * 1e3, fit["frequencies_hz"], "o-", color=colour, label=f"{m:g} h")
            if "value_hz" in fit:
                h = np.linspace(0.0, h_max, 100)
                ax.plot(
                    h * 1e3,
                    fit["value_hz"] + fit["coefficient"] * h ** fit["order"],
                    "--",
                    color=colour,
                    lw=1,
                )
                ax.plot(
                    [0.0],
                    [fit["value_hz"]],
                    "s",
                    color=colour,
                    mfc="none",
                    label=f"f_inf {fit['value_hz']:.1f} Hz, p = {fit['order']:.2f}",
                )
        reference = next(
            (f["reference_hz"] for f in fits if f["mode"] == label and "reference_hz" in f), None
        )
        if reference is not None:
            ax.axhline(reference, color="k", ls=":", lw=1, label=f"reference {reference:.1f} Hz")
        ax.set_title(label)
        ax.set_xlim(left=-0.03 * h_max * 1e3)
        ax.set_xlabel("spacing h (mm)")
        ax.set_ylabel("frequency (Hz)")
        ax.legend(fontsize="x-small")
    for ax in axes[len(labels) :]:
        ax.set_visible(False)
    if title:
        fig.suptitle(title)
    if path is not None:
        fig.savefig(Path(path), dpi=110)
    return fig
