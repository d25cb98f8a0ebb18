"""The signal processing of a monitoring job's interrogations (``peridyn.analysis.shm``) and the
figures of merit of its summary (docs/monitoring.md, "What the summary reports")."""

from __future__ import annotations

import numpy as np
from scipy.stats import spearmanr

from peridyn.analysis.shm.imaging import image_peak, rapid_image
from peridyn.analysis.shm.indices import correlation_index, direct_peaks, residual_energy_index, with_noise
from peridyn.analysis.shm.paths import crossed_paths, path_lengths, polyline_centre
from peridyn.analysis.shm.windows import arrival_windows, fundamental_group_velocities, window_masks

#: The index names of a case's ``processing.index`` -> the dataset's variable names.
INDEX_NAMES = {"correlation": "correlation_index", "residual_energy": "residual_energy_index"}


def assess(mon, wave, plan, data: dict) -> dict:
    """Indices, windows, images and figures of merit of the interrogations.

    Parameters
    ----------
    mon : MonitorCase
    wave : Case
        The wave case (its material and plate).
    plan : peridyn.jobs.monitor.Plan
    data : dict
        ``times`` (n_t,) s, ``signals`` (n_int, n_paths, n_t), ``check`` (n_checked, n_paths,
        n_t): the interrogations ``plan.checked`` by the other damage transfer (``plan.check``),
        or None.

    Returns
    -------
    dict of arrays and numbers (keys as the dataset's variables, and ``monitoring``: the
    summary block)
    """
    m, t = wave.material, mon.transducers
    fundamental = fundamental_group_velocities(m.E, m.nu, m.density, wave.geometry.size[2], t.frequency)
    velocities = {mode: fundamental[mode] for mode in mon.processing.modes}
    distances = path_lengths(plan.transducers, plan.paths)
    windows = arrival_windows(
        distances, velocities.values(), t.cycles / t.frequency, mon.processing.window_padding
    )
    masks = window_masks(data["times"], windows)
    signals = data["signals"]
    peaks = direct_peaks(signals[0], masks)
    level, seed = mon.noise.level, mon.noise.seed
    recorded = (
        np.stack([with_noise(s, level, peaks, seed + k) for k, s in enumerate(signals)]) if level else signals
    )
    out = {"velocities": velocities, "windows": windows, "direct_peak": peaks, "recorded": recorded}
    for name, index in (
        ("residual_energy_index", residual_energy_index),
        ("correlation_index", correlation_index),
    ):
        out[name] = np.stack([index(recorded[0], s, masks) for s in recorded])
        out[f"{name}_noise_free"] = np.stack([index(signals[0], s, masks) for s in signals])
    chosen = out[INDEX_NAMES[mon.processing.index]]
    final = plan.cracks[-1]
    out["crossed"] = (
        crossed_paths(plan.transducers, plan.paths, final)
        if final is not None
        else np.zeros(len(plan.paths), bool)
    )
    out.update(_images(mon, wave, plan, chosen))
    block = {
        "interrogations": len(plan.steps),
        "final_crack_length_m": float(plan.crack_length[-1]),
        "index": mon.processing.index,
        "noise_level": level,
        "crossed_paths": [f"t{i}-t{j}" for i, j in plan.paths[out["crossed"]]],
        **trend_figures(chosen, plan.crack_length, out["crossed"]),
        "image_peak_error_max_m": _max_or_none(out["image_peak_error"][plan.crack_length > 0]),
    }
    if level:
        block["noise_free"] = trend_figures(
            out[f"{INDEX_NAMES[mon.processing.index]}_noise_free"], plan.crack_length, out["crossed"]
        )
    if data["check"] is not None:
        block["transfer"] = transfer_figures(
            signals, data["check"], plan.checked, masks, out["crossed"], plan.route, plan.check
        )
    out["monitoring"] = block
    return out


def trend_figures(index: np.ndarray, crack_length: np.ndarray, crossed: np.ndarray) -> dict:
    """Spearman's rank correlation of each crossed path's index with the crack length (min over
    them), and whether every crossed path's index exceeds every uncrossed one's at each
    interrogation after the crack first grew."""
    rho = []
    for p in np.flatnonzero(crossed):
        r = spearmanr(crack_length, index[:, p]).statistic
        rho.append(float(r) if np.isfinite(r) else -1.0)
    grown = crack_length > 0
    above = None
    if crossed.any() and (~crossed).any() and grown.any():
        above = bool(np.all(index[grown][:, crossed].min(axis=1) > index[grown][:, ~crossed].max(axis=1)))
    return {
        "crossed_spearman_min": min(rho) if rho else None,
        "crossed_above_uncrossed": above,
    }


def _images(mon, wave, plan, index: np.ndarray) -> dict:
    """RAPID images of each interrogation on the plate, their peaks and the peaks' distances
    from the crack's centre (NaN before the crack grows)."""
    step = mon.processing.image_spacing
    exclusion = mon.processing.peak_exclusion
    if exclusion is None:
        exclusion = 2 * mon.transducers.size
    lx, ly = wave.geometry.size[:2]
    x = np.arange(0.5 * step, lx, step)
    y = np.arange(0.5 * step, ly, step)
    images, peaks, centres = [], [], []
    for k, crack in enumerate(plan.cracks):
        image = rapid_image(plan.transducers, plan.paths, index[k], x, y, mon.processing.rapid_beta)
        images.append(image)
        peaks.append(image_peak(x, y, image, plan.transducers, exclusion) if k > 0 else np.full(2, np.nan))
        centres.append(polyline_centre(crack) if crack is not None else np.full(2, np.nan))
    peaks, centres = np.array(peaks), np.array(centres)
    return {
        "image_x": x,
        "image_y": y,
        "image": np.array(images),
        "image_peak": peaks,
        "crack_centre": centres,
        "image_peak_error": np.hypot(*(peaks - centres).T),
    }


def transfer_figures(
    signals: np.ndarray,
    checks: np.ndarray,
    checked: list,
    masks: np.ndarray,
    crossed: np.ndarray,
    route: str,
    check: str,
) -> dict:
    """The two damage transfers compared (docs/monitoring.md, "Damage transfer"): each index of
    the crossed paths (all paths without one) at each checked interrogation, by the
    interrogations' transfer ``route`` (``signals[k]``) and by the other, ``check``
    (``checks``), on the signals without noise (the noise is no part of a transfer), and the
    relative differences ``|route - check| / route`` (0 where both are 0): the largest per
    interrogation and over them all. The block names the two (``route``, ``check``) and holds
    each one's indices under its name.

    Parameters
    ----------
    signals : (n_int, n_paths, n_t), the interrogations by ``route``, the baseline first
    checks : (n_checked, n_paths, n_t), the interrogations ``checked`` by ``check``
    checked : the interrogations (indices into ``signals``) of ``checks``
    masks : (n_paths, n_t) bool, the paths' windows
    crossed : (n_paths,) bool, the paths that the final crack crosses
    route, check : the transfers' names (bonds, cut)
    """
    paths = crossed if crossed.any() else np.ones(len(crossed), bool)
    block = {"route": route, "check": check, "interrogations": [int(k) for k in checked]}
    for name, index in (
        ("residual_energy_index", residual_energy_index),
        ("correlation_index", correlation_index),
    ):
        used = np.stack([index(signals[0], signals[k], masks)[paths] for k in checked])
        other = np.stack([index(signals[0], s, masks)[paths] for s in checks])
        diff = np.abs(used - other)
        relative = np.divide(diff, used, out=np.where(diff > 0, np.inf, 0.0), where=used > 0)
        block[name] = {
            route: used.tolist(),
            check: other.tolist(),
            "relative_difference": relative.max(axis=1).tolist(),
            "relative_difference_max": float(relative.max()),
        }
    return block


def _max_or_none(values: np.ndarray) -> float | None:
    values = values[np.isfinite(values)]
    return float(values.max()) if values.size else None
