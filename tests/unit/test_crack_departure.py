"""Departure angle of a crack from a notch tip (peridyn.analysis.crack.path_from and
departure_angle) on damage fields whose paths are known by construction: a kinked band of
cracked points leaving a tip at a known angle, then turning."""

import numpy as np
import pytest

from peridyn.analysis.crack import crack_paths, departure_angle, path_from
from peridyn.errors import InputError

H = 1e-3  # spacing (m)
TIP = np.array([10 * H, 30 * H])


def kinked_crack(first_deg: float, then_deg: float):
    """Grid of 60 x 60 points with phi = 0.45 within 0.7 spacings of a crack that leaves TIP at
    ``first_deg`` for 20 spacings, then runs 20 spacings at ``then_deg``; phi = 0 elsewhere."""
    x, y = np.meshgrid((np.arange(60) + 0.5) * H, (np.arange(60) + 0.5) * H, indexing="ij")
    pts = np.c_[x.ravel(), y.ravel()]
    kink = TIP + 20 * H * np.array([np.cos(np.radians(first_deg)), np.sin(np.radians(first_deg))])
    end = kink + 20 * H * np.array([np.cos(np.radians(then_deg)), np.sin(np.radians(then_deg))])
    dist = np.min([_distance_to_segment(pts, TIP, kink), _distance_to_segment(pts, kink, end)], axis=0)
    return pts, np.where(dist <= 0.7 * H, 0.45, 0.0)


def _distance_to_segment(p, a, b):
    d = b - a
    t = np.clip(((p - a) @ d) / (d @ d), 0, 1)
    return np.linalg.norm(p - (a + t[:, None] * d), axis=1)


@pytest.mark.parametrize("first, then", [(70.0, 90.0), (-70.0, -20.0)])
def test_departure_angle_is_the_direction_of_the_first_run(first, then):
    """Fitted over the first 15 spacings (before the kink at 20), the angle is the first
    leg's within 3 degrees (the grid's staircase), while the chord of the whole path is not."""
    pts, phi = kinked_crack(first, then)
    crack = path_from(crack_paths(pts, phi, H), TIP, 3 * H)
    assert crack is not None
    assert departure_angle(crack, TIP, 15 * H) == pytest.approx(first, abs=3.0)
    assert abs(crack.angle_deg - first) > 5.0


def test_no_path_from_a_tip_the_crack_does_not_reach():
    pts, phi = kinked_crack(70.0, 90.0)
    assert path_from(crack_paths(pts, phi, H), [50 * H, 5 * H], 3 * H) is None


def test_departure_angle_needs_two_vertices_near_the_tip():
    pts, phi = kinked_crack(70.0, 90.0)
    crack = path_from(crack_paths(pts, phi, H), TIP, 3 * H)
    with pytest.raises(InputError, match="fewer than two crack-path vertices"):
        departure_angle(crack, TIP, 0.1 * H)
