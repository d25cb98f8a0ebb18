"""Crack-path extraction (peridyn.analysis.crack) on damage fields whose paths are known by
construction: a band of cracked points along a line of known length and angle."""

import numpy as np
import pytest

from peridyn.analysis.crack import crack_paths, total_crack_length
from peridyn.errors import InputError
from peridyn.jobs.observers import CrackLengthObserver

H = 1e-3  # spacing (m)


def grid(n=60):
    x, y = np.meshgrid((np.arange(n) + 0.5) * H, (np.arange(n) + 0.5) * H, indexing="ij")
    return np.c_[x.ravel(), y.ravel(), np.zeros(n * n)]


def band(points, start, end, half_width=0.7 * H, value=0.45):
    """phi = value on points within half_width of the segment start-end, 0 elsewhere."""
    a, b = np.asarray(start), np.asarray(end)
    d = b - a
    t = np.clip(((points[:, :2] - a) @ d) / (d @ d), 0, 1)
    dist = np.linalg.norm(points[:, :2] - (a + t[:, None] * d), axis=1)
    return np.where(dist <= half_width, value, 0.0)


@pytest.mark.parametrize("angle", [0.0, 30.0, 70.0, 90.0, -45.0])
def test_straight_band_gives_its_length_and_angle(angle):
    """A band of length L = 30 spacings at angle a: one path, length within 2 spacings
    (the ends of the band are cut by the grid), angle within 3 degrees, mid-line within half
    a spacing of the band's line (no reference line: deviation from the start-end line)."""
    pts = grid()
    c = np.array([30 * H, 30 * H])
    e = 15 * H * np.array([np.cos(np.radians(angle)), np.sin(np.radians(angle))])
    phi = band(pts, c - e, c + e)
    paths = crack_paths(pts, phi, H)
    assert len(paths) == 1
    p = paths[0]
    assert p.length_m == pytest.approx(30 * H, abs=2 * H)
    expected = angle if angle > -90 else angle + 180
    assert p.angle_deg == pytest.approx(90.0 if angle == 90 else expected, abs=3.0)
    assert p.max_deviation_m <= 0.5 * H


def test_deviation_from_reference_line():
    """A crack from the tip of a horizontal pre-crack at 30 degrees for 20 spacings ends
    20 sin 30 = 10 spacings off the pre-crack's line."""
    pts = grid()
    tip = np.array([20 * H, 30 * H])
    end = tip + 20 * H * np.array([np.cos(np.radians(30)), np.sin(np.radians(30))])
    phi = band(pts, tip, end)
    path = crack_paths(pts, phi, H, reference_lines=[((5 * H, 30 * H), tuple(tip))])[0]
    assert path.max_deviation_m == pytest.approx(10 * H, abs=1.0 * H)


def test_branch_is_reported_as_a_second_path():
    """A Y: a 30-spacing main band and a 12-spacing branch leaving its middle at 60 degrees."""
    pts = grid()
    phi = band(pts, (15 * H, 20 * H), (45 * H, 20 * H))
    branch_end = np.array([30 * H, 20 * H]) + 12 * H * np.array([0.5, np.sqrt(3) / 2])
    phi = np.maximum(phi, band(pts, (30 * H, 20 * H), branch_end))
    paths = crack_paths(pts, phi, H)
    assert len(paths) == 2
    assert paths[0].length_m == pytest.approx(30 * H, abs=3 * H)
    assert paths[1].length_m == pytest.approx(10 * H, abs=3 * H)  # the part beyond 2 spacings
    assert paths[1].angle_deg == pytest.approx(60.0, abs=8.0)


def test_threshold_separates_crack_from_tip_damage():
    """Points below the threshold (phi = 0.3, a crack tip's neighbourhood) are no crack."""
    pts = grid()
    phi = band(pts, (10 * H, 10 * H), (40 * H, 10 * H), value=0.3)
    assert crack_paths(pts, phi, H) == []
    assert total_crack_length(pts, phi, H) == 0.0
    assert total_crack_length(pts, phi, H, threshold=0.25) == pytest.approx(30 * H, abs=2 * H)


def test_two_separate_cracks_sorted_longest_first():
    pts = grid()
    phi = np.maximum(
        band(pts, (5 * H, 10 * H), (25 * H, 10 * H)), band(pts, (10 * H, 40 * H), (50 * H, 40 * H))
    )
    lengths = [p.length_m for p in crack_paths(pts, phi, H)]
    assert lengths == pytest.approx([40 * H, 20 * H], abs=2 * H)
    assert total_crack_length(pts, phi, H) == pytest.approx(sum(lengths))


def test_bad_input():
    pts = grid(5)
    with pytest.raises(InputError, match=r"crack_paths needs points \(n, 2\|3\) and phi \(n,\)"):
        crack_paths(pts, np.zeros(3), H)
    with pytest.raises(InputError, match="crack threshold must be in"):
        crack_paths(pts, np.zeros(25), H, threshold=0.0)
    with pytest.raises(InputError, match="spacing must be positive"):
        crack_paths(pts, np.zeros(25), -H)
    with pytest.raises(InputError, match="crack observer interval must be >= 1 step"):
        CrackLengthObserver(None, None, 0)
