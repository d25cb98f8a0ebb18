"""Crack lines drawn on the deformed configuration (peridyn.plotting.crack.displaced_polylines):
a crack opened symmetrically stays on its mid-line, in 2D and through a 7-layer 3D plate."""

import numpy as np
import pytest

from peridyn.analysis.crack import CrackPath
from peridyn.plotting.crack import displaced_polylines

H = 1e-3  # spacing (m)
OPENING = 1e-5  # m: each face moves this far away from the crack line y = 0


@pytest.mark.parametrize("layers", [1, 7])
def test_opened_crack_line_stays_on_the_mid_line(layers):
    """Rows at y = +-H/2, +-3H/2, ... with u_y = +-OPENING either side of y = 0, drawn x100:
    the mean displacement of both faces is zero, so the drawn crack line stays at y = 0
    within a hundredth of the drawn opening; with 7 layers per (x, y) position the 8 nearest
    points alone would be one face (a drawn offset of the whole opening)."""
    x, y = np.meshgrid((np.arange(20) + 0.5) * H, (np.arange(10) - 4.5) * H, indexing="ij")
    xy = np.repeat(np.c_[x.ravel(), y.ravel()], layers, axis=0)
    uv = np.zeros_like(xy)
    uv[:, 1] = np.sign(xy[:, 1]) * OPENING
    polyline = np.c_[np.linspace(5 * H, 15 * H, 11), np.zeros(11)]
    crack = CrackPath(polyline, 10 * H, 0.0, 0.0)
    (line,) = displaced_polylines(xy, uv, [crack], scale=100.0)
    assert np.abs(line[:, 1]).max() <= 0.01 * 100.0 * OPENING
    assert line[:, 0] == pytest.approx(polyline[:, 0])
