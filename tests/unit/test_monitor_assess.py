"""The figures of merit of a monitoring job's summary (peridyn.jobs.monitor_assess.trend_figures)
on index tables whose answers are known."""

import numpy as np
import pytest

from peridyn.jobs.monitor_assess import trend_figures

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
