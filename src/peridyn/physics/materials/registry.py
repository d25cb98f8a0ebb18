"""The material registry: a material class registers itself under its case-file name, and
``make_model`` builds any registered material from the case parameters.

Adding a material is adding one module: a :class:`~peridyn.physics.materials.base.Model`
subclass decorated with ``@register_material("name")`` (see ``materials.base`` for what it
implements); importing the module registers it.
"""

from __future__ import annotations

import numpy as np

from peridyn.discretization.body import Body
from peridyn.discretization.bonds import Bonds
from peridyn.errors import InputError, did_you_mean
from peridyn.physics.materials.base import Model

#: Registered materials: case-file name -> Model subclass.
MODELS: dict[str, type[Model]] = {}


def register_material(name: str):
    """Class decorator: register a :class:`Model` subclass as material ``name`` (sets ``cls.name``).

    A name is taken once: registering another class under it raises ValueError.
    """
    if not (isinstance(name, str) and name.strip() == name and name):
        raise ValueError(
            f"a material name must be a non-empty string without surrounding blanks, got {name!r}"
        )

    def register(cls: type[Model]) -> type[Model]:
        if not (isinstance(cls, type) and issubclass(cls, Model)):
            raise TypeError(f"material {name!r}: {cls!r} is not a subclass of Model")
        known = MODELS.get(name)
        if known is not None and known is not cls:
            raise ValueError(
                f"material name {name!r} is taken by {known.__module__}.{known.__qualname__}; "
                f"cannot register {cls.__module__}.{cls.__qualname__} under it"
            )
        cls.name = name
        MODELS[name] = cls
        return cls

    return register


def model_class(name: str) -> type[Model]:
    """The registered material class ``name``; InputError naming the choices if there is none."""
    if name not in MODELS:
        raise InputError(
            f"unknown material model {name!r}{did_you_mean(name, MODELS)}; choose one of {sorted(MODELS)}"
        )
    return MODELS[name]


def make_model(
    name: str,
    body: Body,
    bonds: Bonds,
    *,
    E,
    density,
    nu=None,
    surface_correction: str = "none",
    dtype=np.float64,
) -> Model:
    """Bind the registered material ``name`` (e.g. "pmb", "lps") to a body and its bonds.

    E in Pa, density in kg/m^3, ``nu`` Poisson's ratio (None: not given), numbers or (n_points,)
    arrays (a body of several blocks, ``materials.blocks``); see ``Model.from_parameters``.
    """
    return model_class(name).from_parameters(
        body, bonds, E=E, density=density, nu=nu, surface_correction=surface_correction, dtype=dtype
    )
