"""Fatigue: Silling and Askari's remaining-life model (Freimanis 2019, chapter 7).

``model`` holds the per-bond remaining life, ``mapping`` the cycles per step,
``tip`` the crack-tip tracking, ``run`` the fatigue loop and ``calibration``
the parameter fits from strain-life and Paris-law data.
"""

from peridyn.fatigue.loop import FatigueResult, run_fatigue
from peridyn.fatigue.mapping import CycleMapping
from peridyn.fatigue.model import FatigueParameters, RemainingLife, cyclic_bond_strain, scale_A_II
from peridyn.fatigue.tip import crack_tip

__all__ = [
    "CycleMapping",
    "FatigueParameters",
    "FatigueResult",
    "RemainingLife",
    "crack_tip",
    "cyclic_bond_strain",
    "run_fatigue",
    "scale_A_II",
]
