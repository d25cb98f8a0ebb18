"""Amplitude spectra of sensor signals, with the harmonics of the drive frequency marked."""

from __future__ import annotations

from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from peridyn.analysis.harmonics import amplitude_spectrum, second_harmonic_ratio


def plot_spectra(signals: dict, dt: float, f0: float, path, title: str = "") -> Path:
    """Overlay the amplitude spectra (log scale) of ``signals`` {label: (n,) array} sampled
    every ``dt`` s, each labelled with its A2/A1; dashed lines at f0, 2 f0, 3 f0 (Hz)."""
    fig = Figure(figsize=(7.0, 4.2))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for label, signal in signals.items():
        freq, spectrum = amplitude_spectrum(signal, dt)
        ratio = second_harmonic_ratio(signal, dt, f0)
        keep = freq <= 4 * f0
        ax.semilogy(freq[keep] / 1e3, spectrum[keep] / spectrum.max(), label=f"{label} (A2/A1 = {ratio:.3g})")
    for n in (1, 2, 3):
        ax.axvline(n * f0 / 1e3, color="0.6", ls="--", lw=0.8)
    ax.set_ylim(1e-5, 2.0)
    ax.set_xlabel("frequency (kHz)")
    ax.set_ylabel("normalised amplitude")
    ax.set_title(title or "Sensor spectra")
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    return path
