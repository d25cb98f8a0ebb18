"""A body made of several blocks, each of its own material (docs/blocks.md).

Every point belongs to exactly one block; the material of the body is one registered model
(``registry``) bound with per-point constants, E, nu and density of each point's block, so
that the kernels and every consumer of ``Model`` run unchanged. How the per-point constants
make the constants of a bond between blocks is the model's rule (PMB: the mean of the two
ends' micromoduli, ``pmb.bond_micromodulus``; LPS: each point's kappa, mu, alpha and P_i its
own, the bond's deviatoric stiffness w (alpha_i + alpha_j) as always).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from peridyn.discretization.body import Body
from peridyn.discretization.bonds import Bonds
from peridyn.errors import InputError
from peridyn.physics.materials.base import Model
from peridyn.physics.materials.registry import make_model, model_class


@dataclass(frozen=True)
class BlockMaterial:
    """The elastic constants of one block: E (Pa), density (kg/m^3), Poisson's ratio ``nu``
    (None: not given, a bond-based model's own)."""

    E: float
    density: float
    nu: float | None = None


def assign_blocks(masks: dict[str, np.ndarray]) -> np.ndarray:
    """(n_points,) int64: the index of each point's block in ``masks`` (name -> (n_points,) bool,
    in order).

    Raises
    ------
    InputError
        When a block holds no point, a point lies in two blocks or in none (naming the blocks
        and the first such point).
    """
    names = list(masks)
    stack = np.array([masks[name] for name in names], dtype=bool)
    for name, mask in zip(names, stack, strict=True):
        if not mask.any():
            raise InputError(f"block {name!r} holds no point")
    count = stack.sum(axis=0)
    if np.any(count > 1):
        point = int(np.flatnonzero(count > 1)[0])
        both = [name for name, mask in zip(names, stack, strict=True) if mask[point]]
        raise InputError(
            f"point {point} lies in blocks {both[0]!r} and {both[1]!r} "
            f"({int(np.sum(count > 1))} points lie in more than one block): blocks must not overlap"
        )
    if np.any(count == 0):
        point = int(np.flatnonzero(count == 0)[0])
        raise InputError(
            f"point {point} lies in no block ({int(np.sum(count == 0))} points in none; blocks: "
            f"{names}): every point needs a block"
        )
    return np.argmax(stack, axis=0).astype(np.int64)


def make_block_model(
    name: str,
    body: Body,
    bonds: Bonds,
    block_of_point: np.ndarray,
    materials: list[BlockMaterial],
    *,
    surface_correction: str = "none",
    dtype=np.float64,
) -> Model:
    """The registered material ``name`` bound to a body of several blocks.

    ``block_of_point`` (n_points,) int: each point's block, an index into ``materials``
    (``assign_blocks``). Each point gets the E, density and nu of its block; a block without
    ``nu`` takes the model's implied Poisson ratio (``Model.implied_poisson_ratio``), and nu is
    None when no block gives one.
    """
    cls = model_class(name)
    E = np.array([m.E for m in materials], dtype=float)[block_of_point]
    density = np.array([m.density for m in materials], dtype=float)[block_of_point]
    nu = None
    if any(m.nu is not None for m in materials):
        implied = cls.implied_poisson_ratio(body.dim, body.plane)
        given = [implied if m.nu is None else m.nu for m in materials]
        if any(v is None for v in given):
            raise InputError(f"a {name} material needs Poisson's ratio nu in every block")
        nu = np.array(given, dtype=float)[block_of_point]
    return make_model(
        name, body, bonds, E=E, density=density, nu=nu, surface_correction=surface_correction, dtype=dtype
    )
