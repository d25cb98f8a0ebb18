"""References of ``peridyn.kernels.damage``: the stretch test with its skin margins, the
skin's moved-point flags and the damage index (definitions in the kernels' docstrings)."""

import numpy as np

from peridyn.kernels.damage import MARGIN_SCALE, MAX_QUANTA
from peridyn.kernels.reference import bond_index, bond_vectors, family_sum, owners


def squared_length(y0, y1, y2):
    """``y0^2 + y1^2 + y2^2`` summed left to right, in the inputs' dtype (the kernel's
    roundings are its definition)."""
    return y0 * y0 + y1 * y1 + y2 * y2


def stretch_test_families(x, u, offsets, nbr, limit, intact, points, tested, moved, quantum):
    """The stretch test of the families of ``points``, without touching the inputs.

    Returns ``(intact_after, margin, broken)``: the (n_bonds,) bool bonds left intact,
    the (len(points),) margins (m) of the tested points, and the number of directed bonds
    broken. A bond i->j of a tested family breaks when intact and ``|Y|^2 > limit^2`` (the
    squared length of ``squared_length``); its copy j->i breaks with it when j is not
    ``tested``. A point's margin is ``quantum`` times the least, over its bonds left intact,
    of ``(limit MARGIN_SCALE - |Y| - moved_j) / quantum`` cut to [0, MAX_QUANTA] and
    truncated to a whole number (MAX_QUANTA for none), minus ``moved_i``.
    """
    n = len(offsets) - 1
    own = owners(offsets)
    nbr = np.asarray(nbr, dtype=np.int64)
    _, _, y = bond_vectors(x, u, offsets, nbr)
    r2 = squared_length(y[:, 0], y[:, 1], y[:, 2])
    in_points = np.zeros(n, dtype=bool)
    in_points[points] = True
    fails = in_points[own] & intact & (r2 > limit * limit)
    after = intact & ~fails
    reverse = bond_index(offsets, nbr, nbr[fails & ~tested[nbr]], own[fails & ~tested[nbr]])
    reverse = reverse[reverse >= 0]
    reverse = reverse[after[reverse]]
    after[reverse] = False
    left = (limit * MARGIN_SCALE - np.sqrt(r2) - moved[nbr]) / quantum
    quanta = np.where(after, np.trunc(np.clip(left, 0.0, MAX_QUANTA)), MAX_QUANTA)
    room = np.full(n, float(MAX_QUANTA))
    np.minimum.at(room, own, quanta)
    return after, room[points] * quantum - moved[points], int(fails.sum() + reverse.size)


def flag_moved_points(u, u_ref, margin):
    """``(moved, tested, count)``: (n_points,) ``|u - u_ref|`` (m), the (n_points,) bool
    ``margin <= 2 moved``, and the number of points flagged, or -1 if some ``moved`` is not
    finite."""
    moved = np.linalg.norm(np.asarray(u, np.float64) - np.asarray(u_ref, np.float64), axis=1)
    tested = margin <= 2.0 * moved
    return moved, tested, (int(tested.sum()) if np.all(np.isfinite(moved)) else -1)


def damage_index(offsets, weight, intact):
    """(n_points,) float64: phi = 1 - (intact weight) / (total weight) per family, 0 for a
    family of zero total weight."""
    total = family_sum(offsets, weight)
    alive = family_sum(offsets, np.where(intact, weight, 0.0))
    return np.where(total > 0, 1.0 - alive / np.where(total > 0, total, 1.0), 0.0)
