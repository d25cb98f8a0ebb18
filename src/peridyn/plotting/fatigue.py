"""Fatigue figures: crack length against cycles, and simulated against experimental da/dN."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


def plot_crack_length(cycles, crack_length, path) -> Path:
    """Crack length (mm) against cycles as a step plot; writes PNG ``path``."""
    fig = Figure(figsize=(6, 4))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.step(np.asarray(cycles), 1e3 * np.asarray(crack_length), where="post")
    ax.set_xlabel("cycles N")
    ax.set_ylabel("crack length a (mm)")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    return Path(path)


def plot_paris(delta_k_sim, rate_sim, delta_k_exp, rate_exp, path, label_sim="simulated") -> Path:
    """log-log da/dN (m/cycle) against dK (MPa m^0.5), simulated and experimental; writes PNG."""
    fig = Figure(figsize=(6, 4))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.loglog(np.asarray(delta_k_exp) / 1e6, rate_exp, "o", label="experimental")
    ax.loglog(np.asarray(delta_k_sim) / 1e6, rate_sim, "s", mfc="none", label=label_sim)
    ax.set_xlabel("dK (MPa m^0.5)")
    ax.set_ylabel("da/dN (m/cycle)")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    return Path(path)
