"""What a monitoring job interrogates: the fatigue life's interrogation points (the schedule), the
crack at each of them, and the wave cases of the body so damaged (the damage transfer).

The fatigue runs on a plane-stress (2D) model of the plate; its history (cycles, crack length),
final damage field (with each point's first-break cycle) and broken bonds (with the cycle of
each break) give the crack at any cycle. The wave case is the 3D plate on the same in-plane
grid; a crack reaches it in one of two ways (docs/monitoring.md, "Damage transfer"; the
monitoring case's ``transfer`` chooses the interrogations', the other checks it):

- ``bonds`` (the default): every 3D bond whose ends lie in the columns of a 2D bond that the
  fatigue had broken by that cycle is cut (a ``bonds`` pre-crack), the 2D model's own broken
  bonds through the thickness;
- ``cut``: every crack path (``peridyn.analysis.crack``, branches included) of the fatigue
  model's damage at that cycle, from the crack's start (``fatigue.tip.start``), becomes
  through-thickness pre-crack rectangles, one per polyline segment, that cut every bond
  crossing them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from peridyn.analysis.crack import crack_paths
from peridyn.errors import InputError
from peridyn.io.case import Case, validate_case
from peridyn.physics.damage import damage_field

AXIS = {"x": 0, "y": 1}


@dataclass(frozen=True)
class FatigueHistory:
    """What the fatigue run left: history and broken bonds of the plane-stress model.

    Attributes
    ----------
    cycles, crack_length : (n_steps + 1,) float64; cycles and crack length (m) after each step
    points : (n_points, 2) float64, m, the 2D model's points
    first_break : (n_points,) float64, cycle of each point's first broken bond (inf: none)
    broken_pairs : (n_broken, 2) int64, the points (indices into ``points``) of each bond the
        cycles broke
    break_cycle : (n_broken,) float64, the cycle at which each of them broke
    """

    cycles: np.ndarray
    crack_length: np.ndarray
    points: np.ndarray
    first_break: np.ndarray
    broken_pairs: np.ndarray
    break_cycle: np.ndarray


def interrogation_steps(
    cycles, crack_length, every_cycles=None, every_growth=None, most: int = 20, until=None
) -> np.ndarray:
    """Indices into the fatigue history of the interrogations: 0 (the baseline), the last step at
    or before each multiple of ``every_cycles``, the first step at which the crack grew by
    ``every_growth`` (m) since the last interrogation, and the last step (the first whose crack
    reaches ``until``, m, when it is given and reached); at most ``most`` (the baseline, the
    first ``most - 2`` others and the last step)."""
    cycles = np.asarray(cycles, dtype=float)
    a = np.asarray(crack_length, dtype=float)
    if until is not None and np.any(a >= until):
        end = int(np.argmax(a >= until)) + 1
        cycles, a = cycles[:end], a[:end]
    chosen = {0, len(cycles) - 1}
    if every_cycles is not None:
        marks = np.arange(every_cycles, cycles[-1] + 0.5 * every_cycles, every_cycles)
        chosen |= {int(np.searchsorted(cycles, m, side="right") - 1) for m in marks}
    if every_growth is not None:
        last = a[0]
        for k in range(1, len(a)):
            if a[k] >= last + every_growth * (1 - 1e-9):
                chosen.add(k)
                last = a[k]
    steps = sorted(chosen)
    if len(steps) > most:
        steps = steps[: most - 1] + [steps[-1]]
    return np.array(steps, dtype=int)


def damage_at(model, history: FatigueHistory, cycles) -> np.ndarray:
    """(n_cycles, n_points) the fatigue model's damage index at each of ``cycles``, exactly:
    ``model`` (the fatigue case built, its pre-cracks cut) with the bonds that had broken by
    then (``history.broken_pairs``, ``break_cycle``) broken. ``model.bonds`` is left as given."""
    b = model.bonds
    n = model.body.n_points
    if n != len(history.points) or not np.allclose(model.body.points[:, :2], history.points):
        raise InputError("the fatigue run's points are not those of its case (damage.vtu of another case?)")
    owners = b.owners()
    key = np.minimum(owners, b.neighbours) * n + np.maximum(owners, b.neighbours)
    listed = history.broken_pairs[:, 0] * n + history.broken_pairs[:, 1]
    order = np.argsort(listed)
    at = np.clip(np.searchsorted(listed[order], key), 0, max(len(listed) - 1, 0))
    found = listed[order][at] == key if len(listed) else np.zeros(b.n_bonds, bool)
    broke = np.where(found, history.break_cycle[order][at] if len(listed) else 0.0, np.inf)
    intact = b.intact.copy()
    phi = []
    try:
        for n_cycles in np.atleast_1d(cycles):
            b.intact[:] = intact & ~(found & (broke <= n_cycles))
            phi.append(damage_field(model))
    finally:
        b.intact[:] = intact
    return np.array(phi)


def crack_lines(points: np.ndarray, phi: np.ndarray, spacing: float, tip) -> list[np.ndarray]:
    """The crack of the damage ``phi`` ((n_points,)) as (m, 2) polylines (m): every crack path
    (``peridyn.analysis.crack.crack_paths`` at the tip's damage threshold, branches included)
    beyond ``tip.start`` along ``tip.axis`` in ``tip.sense`` (the fatigue case's
    ``FatigueTip``), the path that comes nearest to the start first (the main crack, from the
    start); [] without one."""
    if tip.axis not in AXIS or tip.start is None:
        raise InputError(
            "a monitored fatigue case needs fatigue.tip.axis x or y and tip.start (the notch root)"
        )
    axis = AXIS[tip.axis]
    sense = 1.0 if tip.sense == "+" else -1.0
    paths = sorted(
        (p.points for p in crack_paths(points, phi, spacing, threshold=tip.damage)),
        key=lambda line: np.abs(line[:, axis] - tip.start).min(),
    )
    lines = [_beyond(line, axis, sense, tip.start, k == 0) for k, line in enumerate(paths)]
    return [line for line in lines if line is not None]


def _beyond(line: np.ndarray, axis: int, sense: float, start: float, main: bool) -> np.ndarray | None:
    """The part of the polyline ``line`` beyond ``start`` along ``axis`` in ``sense``, from the
    point where it passes the start (a ``main`` path that begins beyond it: from its first
    vertex moved back to the start); None if it never does."""
    ahead = (line[:, axis] - start) * sense
    if ahead[-1] < ahead[0]:
        line, ahead = line[::-1], ahead[::-1]
    inside = np.flatnonzero(ahead > 0)
    if inside.size == 0:
        return None
    k = inside[0]
    if k > 0:  # the point where the path passes the start
        w = -ahead[k - 1] / (ahead[k] - ahead[k - 1])
        first = line[k - 1] + w * (line[k] - line[k - 1])
        return np.vstack([first, line[k:]])
    if not main:
        return line
    first = line[0].copy()
    first[axis] = start
    return np.vstack([first, line])


def cut_case(wave: Case, name: str, lines: list) -> Case:
    """The wave case with the crack ``lines`` ((m, 2) polylines, m, e.g. a crack and its
    branches) as through-thickness pre-crack rectangles (one per segment), renamed ``name``."""
    data = wave.model_dump(mode="python")
    data["name"] = name
    z0, depth = _through(wave)
    for line in lines:
        for a, b in zip(line[:-1], line[1:], strict=True):
            data["precracks"].append(
                {
                    "type": "rectangle",
                    "origin": [float(a[0]), float(a[1]), z0],
                    "edge_u": [float(b[0] - a[0]), float(b[1] - a[1]), 0.0],
                    "edge_v": [0.0, 0.0, depth],
                }
            )
    return validate_case(data, name)


def bonds_case(wave: Case, name: str, history: FatigueHistory, cycles: float, spacing: float) -> Case:
    """The wave case with the bonds that the fatigue had broken by ``cycles`` cut through the
    thickness (a ``bonds`` pre-crack: every bond between the two columns of points at the
    broken 2D bond's ends; the columns found within a quarter ``spacing``, m), renamed ``name``."""
    data = wave.model_dump(mode="python")
    data["name"] = name
    broken = history.broken_pairs[history.break_cycle <= cycles]
    if len(broken):
        pairs = history.points[broken].reshape(-1, 4)
        data["precracks"].append({"type": "bonds", "pairs": pairs.tolist(), "tolerance": 0.25 * spacing})
    return validate_case(data, name)


def _through(wave: Case) -> tuple[float, float]:
    """Bottom (m) and height (m) of a region that spans the plate's thickness with a margin."""
    if wave.geometry.type != "plate":
        raise InputError(f"the wave case of a monitoring job is a plate, got geometry {wave.geometry.type!r}")
    t = wave.geometry.size[2]
    return -t, 3 * t
