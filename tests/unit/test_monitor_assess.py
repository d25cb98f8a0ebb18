"""The figures of merit of a monitoring job's summary (peridyn.jobs.monitor_assess.trend_figures)
on index tables whose answers are known."""

import numpy as np
import pytest

from peridyn.jobs.monitor_assess import transfer_figures, trend_figures

A = np.array([0.0, 1e-3, 2e-3, 4e-3])  # crack length at 4 interrogations, m
CROSSED = np.array([True, False, True])


def test_rising_crossed_paths_above_the_others_give_spearman_one_and_true():
    index = np.array([[0.0, 0.0, 0.0], [0.1, 0.05, 0.2], [0.3, 0.06, 0.25], [0.5, 0.07, 0.6]])
    figures = trend_figures(index, A, CROSSED)
    assert figures == {"crossed_spearman_min": pytest.approx(1.0), "crossed_above_uncrossed": True}


def test_a_crossed_path_that_falls_once_and_one_below_an_uncrossed_path_are_reported():
    # path 2 swaps its last two values: ranks (1, 2, 4, 3) against (1, 2, 3, 4), Spearman 0.8;
    # at the second interrogation path 0 (0.04) is below the uncrossed path (0.05)
    index = np.array([[0.0, 0.0, 0.0], [0.04, 0.05, 0.2], [0.3, 0.06, 0.7], [0.5, 0.07, 0.6]])
    figures = trend_figures(index, A, CROSSED)
    assert figures["crossed_spearman_min"] == pytest.approx(0.8)
    assert figures["crossed_above_uncrossed"] is False


def test_the_transfer_figures_compare_each_checked_interrogation_on_the_crossed_paths():
    """Residual energy index of a signal scaled by (1 + e): e^2 against the baseline, so the
    relative difference of two transfers scaled by e_cut and e_bonds is
    |e_cut^2 - e_bonds^2| / e_cut^2; the uncrossed path (changed most) does not count."""
    t = np.linspace(0.0, 1.0, 64)
    base = np.stack([np.sin(8 * t), np.cos(5 * t), np.sin(3 * t + 1)])  # 3 paths
    masks = np.ones_like(base, dtype=bool)
    cut_gain = {1: 0.1, 2: 0.2}
    bonds_gain = {1: 0.11, 2: 0.2}

    def scaled(gain, uncrossed=0.0):
        return base * np.array([1 + gain, 1 + uncrossed, 1 + gain])[:, None]

    signals = np.stack([base, scaled(cut_gain[1], 0.9), scaled(cut_gain[2], 0.9)])
    bonds = np.stack([scaled(bonds_gain[1]), scaled(bonds_gain[2])])
    block = transfer_figures(signals, bonds, [1, 2], masks, CROSSED, "cut", "bonds")
    assert block["interrogations"] == [1, 2] and (block["route"], block["check"]) == ("cut", "bonds")
    energy = block["residual_energy_index"]
    np.testing.assert_allclose(energy["cut"], [[0.01, 0.01], [0.04, 0.04]], rtol=1e-12)
    np.testing.assert_allclose(energy["relative_difference"], [abs(0.01 - 0.0121) / 0.01, 0.0], atol=1e-12)
    assert energy["relative_difference_max"] == pytest.approx(0.21, rel=1e-12)
    # a scaled signal keeps its shape: correlation index 0 by both routes, no difference
    np.testing.assert_allclose(block["correlation_index"]["bonds"], 0.0, atol=1e-12)
    assert block["correlation_index"]["relative_difference_max"] < 1e-6
