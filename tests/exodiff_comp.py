"""A small exodiff for tests: compare an Exodus result with a gold file under the tolerances of
an exodiff command file (``*.comp``, as Peridigm's test suite writes them).

The subset read: ``DEFAULT TOLERANCE`` (coordinates and times without their own line take it),
``COORDINATES``, ``TIME STEPS``, and the sections
``NODAL VARIABLES``, ``ELEMENT VARIABLES``, ``GLOBAL VARIABLES`` whose indented lines name a
variable and its tolerance (``absolute T`` or ``relative T``, optionally ``floor F``: values
below F in magnitude count as equal). As in exodiff, a section compares the variables it lists.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from peridyn.io.exodus import read_exodus


@dataclass(frozen=True)
class Tolerance:
    """One exodiff tolerance: ``kind`` "absolute" or "relative", ``value`` and ``floor``."""

    kind: str
    value: float
    floor: float = 0.0

    def excess(self, gold: np.ndarray, mine: np.ndarray) -> float:
        """Largest difference over the tolerance (<= 0: within it), in units of the tolerance."""
        diff = np.abs(np.asarray(mine, dtype=float) - np.asarray(gold, dtype=float))
        if self.floor > 0:
            diff = np.where((np.abs(gold) < self.floor) & (np.abs(mine) < self.floor), 0.0, diff)
        scale = np.maximum(np.abs(gold), np.abs(mine)) if self.kind == "relative" else 1.0
        scale = np.where(scale == 0, 1.0, scale)  # two zeros: no difference to scale
        return float(np.max(diff / (self.value * scale), initial=0.0)) - 1.0


def _tolerance(words: list[str]) -> Tolerance:
    kind, value = words[0].lower(), float(words[1])
    floor = float(words[words.index("floor") + 1]) if "floor" in words else 0.0
    return Tolerance(kind, value, floor)


def read_comp(path) -> dict:
    """``{"coordinates": Tolerance, "times": Tolerance, "nodal"|"element"|"global": {name: Tolerance}}``."""
    out = {"nodal": {}, "element": {}, "global": {}}
    section = None
    for line in Path(path).read_text().splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        words = line.split()
        if line[0].isspace() and section is not None:
            out[section][words[0]] = _tolerance(words[1:])
            continue
        head = " ".join(words[:2]).upper()
        section = None
        if head == "DEFAULT TOLERANCE":
            out["default"] = _tolerance(words[2:])
        elif words[0].upper() == "COORDINATES":
            out["coordinates"] = _tolerance(words[1:])
        elif head == "TIME STEPS":
            out["times"] = _tolerance(words[2:])
        elif head in ("NODAL VARIABLES", "ELEMENT VARIABLES", "GLOBAL VARIABLES"):
            section = words[0].lower()
    default = out.get("default", Tolerance("relative", 1e-6))  # exodiff's own default
    out.setdefault("coordinates", default)
    out.setdefault("times", default)
    return out


def compare(gold_path, result_path, comp_path) -> dict:
    """Excess over tolerance (<= 0 passes) of each compared item of the result against the
    gold: ``coordinates``, ``times`` and every variable the comp file lists. A variable that
    the result lacks, or time steps that differ in number, count as +inf."""
    return compare_meshes(read_exodus(gold_path), read_exodus(result_path), comp_path)


def compare_meshes(gold, mine, comp_path) -> dict:
    """``compare`` of two Exodus files read (``read_exodus``)."""
    comp = read_comp(comp_path)
    out = {}
    same_shape = gold.coordinates.shape == mine.coordinates.shape
    out["coordinates"] = (
        comp["coordinates"].excess(gold.coordinates, mine.coordinates) if same_shape else np.inf
    )
    same_steps = len(gold.times) == len(mine.times)
    out["times"] = comp["times"].excess(gold.times, mine.times) if same_steps else np.inf
    for kind in ("nodal", "element", "global"):
        gold_vars, mine_vars = (getattr(m, f"{kind}_variables") for m in (gold, mine))
        for name, tol in comp[kind].items():
            if name not in gold_vars:
                continue  # as exodiff: a listed variable missing from the gold file is not compared
            ok = name in mine_vars and same_steps and np.shape(mine_vars[name]) == np.shape(gold_vars[name])
            out[name] = tol.excess(gold_vars[name], mine_vars[name]) if ok else np.inf
    return out
