"""Shared factories: small bodies and models used across the test folders.

Importing ``materials.conical_bond`` registers the test-only "conical" material, so that every
test parametrized with ``MODEL_CASES`` or ``MATERIALS`` (the registered materials) runs on it.
"""

import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from materials import conical_bond  # noqa: F401  (registers the "conical" material)

import peridyn
from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.physics.materials import MODELS, make_model

#: ``materials/`` holds material modules imported above, not tests: doctest collection
#: (``--doctest-modules``) would import them a second time under another module name.
collect_ignore = ["materials"]

#: Maraging steel of seed 001 / VALIDATION V3: rho = 8000, mu = 81.92 GPa, K = 132.77 GPa.
STEEL_K, STEEL_MU, STEEL_RHO = 132.77e9, 81.92e9, 8000.0
STEEL_E = 9 * STEEL_K * STEEL_MU / (3 * STEEL_K + STEEL_MU)
STEEL_NU = (3 * STEEL_K - 2 * STEEL_MU) / (2 * (3 * STEEL_K + STEEL_MU))


def small_body(dim: int, plane: str = "stress", n: int = 12, h: float = 1e-3):
    """A cube (3D) or square (2D) of n points per side, spacing h."""
    if dim == 3:
        return geometry.box((n * h,) * 3, h)
    return geometry.rectangle(n * h, n * h, h, thickness=h, plane=plane)


def small_model(
    name: str,
    dim: int = 3,
    plane: str = "stress",
    n: int = 12,
    horizon_factor: float = 3.015,
    partial_volumes: bool = True,
    dtype=np.float64,
    nu: float = 0.25,
    surface_correction: str = "none",
):
    """A model on ``small_body`` with steel-like constants; ``nu`` goes to the materials that
    take one (a bond-based material gets the ratio it implies)."""
    body = small_body(dim, plane, n)
    bonds = find_bonds(body, horizon_factor * body.spacing, partial_volumes=partial_volumes)
    implied = MODELS[name].implied_poisson_ratio(dim, plane) if name in MODELS else None
    return make_model(
        name,
        body,
        bonds,
        E=200e9,
        density=7850.0,
        nu=(nu if implied is None else implied),
        surface_correction=surface_correction,
        dtype=dtype,
    )


#: Every registered material (the shipped ones and the test-only "conical").
MATERIALS = sorted(MODELS)

#: (material, dimension, plane) of the material invariant suite: each material in 3D and in
#: 2D plane stress and plane strain.
MODEL_CASES = [
    pytest.param((name, dim, plane), id=f"{name}-{label}")
    for name in MATERIALS
    for dim, plane, label in ((3, "stress", "3d"), (2, "stress", "2d-stress"), (2, "strain", "2d-strain"))
]


@pytest.fixture
def rng():
    """A seeded generator (tests never use global random state)."""
    return np.random.default_rng(20261123)


def results_datasets(path) -> dict:
    """Every dataset under final/ and series/ of a results file, by its path in the file."""
    found = {}
    with h5py.File(path) as f:
        for group in ("final", "series"):
            if group in f:
                f[group].visititems(
                    lambda name, obj, g=group: (
                        found.__setitem__(f"{g}/{name}", obj[()]) if isinstance(obj, h5py.Dataset) else None
                    )
                )
    return found


def peridyn_process(argv: list, ranks: int = 1) -> subprocess.CompletedProcess:
    """``python -m peridyn ARGV`` in a new process of this checkout, one numba thread, under
    ``mpiexec -n RANKS`` when ``ranks`` > 1; output captured, 600 s at most."""
    command = [sys.executable, "-m", "peridyn", *argv]
    if ranks > 1:
        command = ["mpiexec", "-n", str(ranks), *command]
    env = dict(os.environ, PYTHONPATH=str(Path(peridyn.__file__).parents[1]), NUMBA_NUM_THREADS="1")
    return subprocess.run(command, capture_output=True, text=True, timeout=600, env=env)
