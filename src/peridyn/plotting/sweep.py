"""Sweep figures: a scalar result against one varied parameter, one line per combination of
the other parameters."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

#: The most lines drawn with a legend; more are drawn without one.
MAX_LEGEND = 10


def plot_against(ds, x: str, y: str, others, path) -> Path:
    """Draw ``ds[y]`` against ``ds[x]`` (both along ``run``), one line (sorted by x) per value
    combination of the parameters ``others``; runs without a value of ``y`` (failed, pending)
    are left out. Saved as PNG at ``path`` (an Agg canvas, never a window); returns ``path``.

    Parameters
    ----------
    ds : xarray.Dataset
        A sweep's dataset (:mod:`peridyn.io.dataset`).
    x, y : str
        Names of a numeric coordinate and a numeric data variable along ``run``.
    others : sequence of str
        The other varied parameters (coordinates along ``run``).
    """
    xs, ys = np.asarray(ds[x].values, dtype=float), np.asarray(ds[y].values, dtype=float)
    keys = [tuple(ds[o].values[i].item() for o in others) for i in range(xs.size)]
    fig = Figure(figsize=(6.0, 4.2), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    groups = list(dict.fromkeys(keys))
    for group in groups:
        idx = np.array([i for i, k in enumerate(keys) if k == group and np.isfinite(ys[i])], dtype=int)
        if idx.size == 0:
            continue
        order = idx[np.argsort(xs[idx], kind="stable")]
        label = ", ".join(
            f"{o} = {v:.4g}{_unit(ds, o, ' ')}" if isinstance(v, float) else f"{o} = {v}{_unit(ds, o, ' ')}"
            for o, v in zip(others, group, strict=True)
        )
        ax.plot(xs[order], ys[order], "o-", label=label or None)
    ax.set_xlabel(_label(ds, x))
    ax.set_ylabel(_label(ds, y))
    ax.grid(True, alpha=0.3)
    if others and len(groups) <= MAX_LEGEND:
        ax.legend(fontsize="small")
    fig.savefig(path, dpi=120)
    return Path(path)


def _unit(ds, name: str, before: str) -> str:
    """The variable's ``units`` after ``before``; nothing for a ratio or count ("1") or none."""
    units = ds[name].attrs.get("units")
    return f"{before}{units}" if units and units != "1" else ""


def _label(ds, name: str) -> str:
    """An axis label: the name and its unit in brackets (``material.E (Pa)``)."""
    units = ds[name].attrs.get("units")
    return f"{name} ({units})" if units else name
