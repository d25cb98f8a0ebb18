"""Material models behind one interface (``base.Model``), registered by name (``registry``).

Shipped: PMB (bond-based, ``pmb``), LPS (state-based, ``lps``) and LPS linearised about the
reference configuration (``linear_lps``, Peridigm's "Linear LPS"); importing this package
registers them. ``make_model`` builds any registered material from the case parameters.
"""

from __future__ import annotations

from peridyn.physics.materials.base import Model
from peridyn.physics.materials.linear_lps import LinearLPSModel
from peridyn.physics.materials.linearisation import BondLinearisation
from peridyn.physics.materials.lps import LPSModel
from peridyn.physics.materials.pmb import PMBModel
from peridyn.physics.materials.registry import MODELS, make_model, register_material

__all__ = [
    "MODELS",
    "BondLinearisation",
    "LPSModel",
    "LinearLPSModel",
    "Model",
    "PMBModel",
    "make_model",
    "register_material",
]
