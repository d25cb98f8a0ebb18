"""Peridynamic dispersion curves: omega(k), phase and group velocity of each branch."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from peridyn.analysis.dispersion import DispersionRelation, Study

#: The three panels of a row: (attribute of Branch, axis label, scale to the plotted unit).
_PANELS = (
    ("frequency", "angular frequency (Mrad/s)", 1e-6),
    ("phase_velocity", "phase velocity (m/s)", 1.0),
    ("group_velocity", "group velocity (m/s)", 1.0),
)
_SWEEPS = ("influence", "horizon", "spacing")


def plot_dispersion(relations, path=None, title: str | None = None) -> Figure:
    """Draw omega(k), phase and group velocity, one row per branch.

    A row is drawn for the longitudinal branch and for each shear branch that
    differs from the first one (e.g. shear_2 along xy on a lattice). Classical
    speeds are dashed grey lines; the group-velocity panels mark zero. Drawn on
    an Agg canvas, never in a window.

    Parameters
    ----------
    relations : DispersionRelation or dict of str to DispersionRelation
        One relation, or several labelled curves drawn on the same axes.
    path : str or os.PathLike, optional
        Where to save the figure as PNG.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    if isinstance(relations, DispersionRelation):
        title = title or _describe(relations)
        relations = {_describe(relations): relations}
    names = _branches_to_draw(relations.values())
    fig = Figure(figsize=(13.0, 3.3 * len(names) + 0.6), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(names), len(_PANELS), squeeze=False)
    for row, name in zip(axes, names, strict=True):
        for i, (label, rel) in enumerate(relations.items()):
            branch = rel.branches[name]
            for ax, (attr, _, scale) in zip(row, _PANELS, strict=True):
                ax.plot(branch.wavenumber, getattr(branch, attr) * scale, color=f"C{i % 10}", label=label)
        _decorate(row, name, next(iter(relations.values())))
    if len(relations) > 1:
        axes[0, -1].legend(fontsize="small", loc="upper right")
    if title:
        fig.suptitle(title)
    if path is not None:
        fig.savefig(path, format="png", dpi=120)
    return fig


def plot_study(study: Study, directory, prefix: str = "dispersion") -> list[Path]:
    """Write one figure per sweep of a study (``<prefix>_influence.png``, ``_horizon``,
    ``_spacing``: the dispersion study figures 4-6 and 10-12); returns the paths written."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for parameter in _SWEEPS:
        curves = study.sweep(parameter)
        if len(curves) > 1:
            path = directory / f"{prefix}_{parameter}.png"
            plot_dispersion(curves, path, title=f"{_kind(next(iter(curves.values())))}: {parameter} sweep")
            written.append(path)
    return written


def _branches_to_draw(relations) -> list[str]:
    """Longitudinal, shear_1, and shear_2 where it differs from shear_1."""
    relations = list(relations)
    names = [n for n in ("longitudinal", "shear_1") if n in relations[0].branches]
    if "shear_2" in relations[0].branches and any(
        not np.allclose(r.branches["shear_2"].frequency, r.branches["shear_1"].frequency, rtol=1e-9)
        for r in relations
    ):
        names.append("shear_2")
    return names


def _decorate(row, name: str, relation: DispersionRelation) -> None:
    classical = relation.classical[0 if name == "longitudinal" else 1]
    for ax, (attr, ylabel, _) in zip(row, _PANELS, strict=True):
        ax.set(xlabel="wavenumber k (rad/m)", ylabel=ylabel, title=name.replace("_", " "))
        ax.set_xlim(left=0.0)
        ax.grid(alpha=0.3)
        if attr != "frequency":
            ax.axhline(classical, color="0.5", linestyle="--", linewidth=0.8)
    row[-1].axhline(0.0, color="k", linewidth=0.6)


def _kind(rel: DispersionRelation) -> str:
    """E.g. ``LPS 3D (discrete, partial volumes)``."""
    if rel.discrete:
        kind = "discrete, partial volumes" if rel.partial_volumes else "discrete, centre distance"
    else:
        kind = "continuous"
    return f"{rel.model.upper()} {rel.dim}D ({kind})"


def _describe(rel: DispersionRelation) -> str:
    return f"{_kind(rel)}, {rel.influence}, delta = {rel.horizon * 1e3:g} mm, h = {rel.spacing * 1e3:g} mm"
