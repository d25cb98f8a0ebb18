"""A monitoring dataset's crack (peridyn.jobs.monitor_output.branches) holds every branch of the
fatigue crack, and the figures drawn from the dataset get them all back
(peridyn.plotting.monitoring._polyline): a Y-shaped crack is drawn as its three arms, not one."""

import numpy as np

from peridyn.jobs.monitor_output import branches
from peridyn.plotting.monitoring import _polyline

MAIN = np.array([[0.020, 0.020], [0.023, 0.020], [0.026, 0.021]])  # m
UPPER = np.array([[0.026, 0.021], [0.028, 0.023]])
LOWER = np.array([[0.026, 0.021], [0.028, 0.019]])


def test_every_branch_is_kept_with_a_break_between_two_and_read_back_from_the_padded_rows():
    rows = branches([MAIN, UPPER, LOWER])
    assert rows.shape == (3 + 1 + 2 + 1 + 2, 2)
    assert np.isnan(rows[[3, 6]]).all() and np.isfinite(np.delete(rows, [3, 6], axis=0)).all()
    np.testing.assert_array_equal(rows[4:6], UPPER)
    padded = np.vstack([rows, np.full((4, 2), np.nan)])  # the dataset pads every interrogation's rows
    np.testing.assert_array_equal(_polyline(padded[:, 0], padded[:, 1]), rows)


def test_no_crack_gives_no_rows_and_no_polyline():
    assert branches([]).shape == (0, 2)
    assert _polyline(np.full(3, np.nan), np.full(3, np.nan)) is None
