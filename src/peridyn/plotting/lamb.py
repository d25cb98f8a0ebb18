"""Rayleigh-Lamb dispersion curves: phase velocity and wavenumber against frequency."""

from __future__ import annotations

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from peridyn.analysis.lamb import DispersionBranch

#: Upper limit of the phase-velocity axis, in multiples of the fastest S0 speed
#: (phase velocities run to infinity at the cut-offs).
_PHASE_VELOCITY_SPAN = 2.5


def plot_lamb_dispersion(curves: dict[str, DispersionBranch], path=None, ax=None) -> Figure:
    """Draw phase velocity and wavenumber against frequency for every mode.

    S modes are solid, A modes dashed; each curve is labelled in the legend.
    The figure is drawn on an Agg canvas and never opens a window.

    Parameters
    ----------
    curves : dict of str to DispersionBranch
        From :func:`peridyn.analysis.lamb.dispersion_curves`.
    path : str or os.PathLike, optional
        Where to save the figure as PNG.
    ax : pair of matplotlib.axes.Axes, optional
        ``(phase_velocity_axes, wavenumber_axes)`` to draw into; by default a
        new figure with the two panels side by side.

    Returns
    -------
    matplotlib.figure.Figure
        The figure holding the axes.
    """
    if ax is None:
        fig = Figure(figsize=(11.0, 4.5), layout="constrained")
        FigureCanvasAgg(fig)
        ax = fig.subplots(1, 2)
    ax_c, ax_k = ax
    for i, (label, branch) in enumerate(curves.items()):
        style = dict(linestyle="-" if label.startswith("S") else "--", color=f"C{i % 10}")
        f_khz = branch.frequency_hz / 1e3
        ax_c.plot(f_khz, branch.phase_velocity_m_s, label=label, **style)
        ax_k.plot(f_khz, branch.wavenumber_rad_m, label=label, **style)
    if "S0" in curves:
        ax_c.set_ylim(0.0, _PHASE_VELOCITY_SPAN * curves["S0"].phase_velocity_m_s.max())
    ax_c.set(xlabel="frequency (kHz)", ylabel="phase velocity (m/s)", title="Phase velocity")
    ax_k.set(xlabel="frequency (kHz)", ylabel="wavenumber (rad/m)", title="Wavenumber")
    for axes in ax:
        axes.set_xlim(left=0.0)
        axes.grid(alpha=0.3)
    ax_k.legend(ncols=2, fontsize="small", title="S solid, A dashed")
    fig = ax_c.figure
    if path is not None:
        fig.savefig(path, format="png", dpi=150)
    return fig
