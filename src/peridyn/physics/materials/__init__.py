"""Material models: PMB (bond-based) and LPS (state-based), and their factory."""

from __future__ import annotations

import numpy as np

from peridyn.discretization.body import Body
from peridyn.discretization.bonds import Bonds
from peridyn.errors import InputError, did_you_mean
from peridyn.physics.materials.base import Model
from peridyn.physics.materials.lps import LPSModel
from peridyn.physics.materials.pmb import PMBModel

MODELS = {"pmb": PMBModel, "lps": LPSModel}

__all__ = ["MODELS", "LPSModel", "Model", "PMBModel", "make_model"]


def make_model(
    name: str,
    body: Body,
    bonds: Bonds,
    *,
    E: float,
    density: float,
    nu: float | None = None,
    surface_correction: str = "none",
    dtype=np.float64,
) -> Model:
    """Bind the material model ``name`` ("pmb" or "lps") to a body and its bonds."""
    if name not in MODELS:
        raise InputError(
            f"unknown material model {name!r}{did_you_mean(name, MODELS)}; choose one of {sorted(MODELS)}"
        )
    if name == "lps":
        if nu is None:
            raise InputError("an LPS material needs Poisson's ratio nu")
        return LPSModel(
            body, bonds, E=E, nu=nu, density=density, surface_correction=surface_correction, dtype=dtype
        )
    return PMBModel(
        body, bonds, E=E, density=density, nu=nu, surface_correction=surface_correction, dtype=dtype
    )
