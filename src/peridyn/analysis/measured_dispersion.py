"""Dispersion measured on the running code: plane-wave Rayleigh quotients of ``Model.force``.

A block of the simple cubic (square) lattice is built with the engine
(``peridyn.discretization.geometry``, ``find_bonds``, ``make_model``). For the plane wave
``u = A e_b cos(k d.(x - c))`` (polarisation ``e_b``, ``c`` the block centre)
the force of an infinite lattice is ``f = -D(k) u`` at every point, so at
points whose own family and whose neighbours' families are complete (farther
than twice the reach ``delta + h sqrt(dim)/2`` from the surface: an LPS force
depends on the dilatations of the neighbours)::

    D_ab(k) = - sum_i f_a(A e_b cos)_i cos_i / (A sum_i cos_i^2)

is the acoustic tensor the code has (``Model.force``, float64). The force is
taken as the odd part ``(f(u) - f(-u)) / 2``, which removes the quadratic term
of the bond kinematics; with ``A = 1e-6 h`` what is left of the nonlinearity
and of round-off is about 1e-10 relative. The branches are the eigenvalues of
``D`` labelled by polarisation as in :mod:`peridyn.analysis.dispersion`;
``omega = sqrt(lambda / rho)``.

The engine has no 1D bodies, so only 2D and 3D are measured. The explicit
time integration adds its own dispersion on top (velocity Verlet: ``sin(omega_run
dt / 2) = omega dt / 2``), which this spatial measurement leaves out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from peridyn.analysis.dispersion import (
    BRANCHES,
    Medium,
    branch_eigenvalues,
    parse_direction,
    polarisations,
)
from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.errors import InputError
from peridyn.physics.materials import Model, make_model
from peridyn.physics.materials.registry import model_class

__all__ = ["MeasuredDispersion", "lattice_block_model", "measure_dispersion"]

#: Plane-wave amplitude in spacings: small against the bond length, large against round-off.
AMPLITUDE = 1e-6
#: Interior points per axis of the measuring block.
INTERIOR_POINTS = 3


@dataclass(frozen=True)
class MeasuredDispersion:
    """omega(k) of each branch measured on a model's force.

    Attributes
    ----------
    wavenumber : (n_k,) float64, rad/m
    frequency : dict of str to (n_k,) float64, rad/s
        Per branch ("longitudinal", "shear_1", "shear_2" in 3D).
    tensor : (n_k, dim, dim) float64, Pa/m^2
        The measured acoustic tensor in the polarisation basis.
    points, interior_points : int
        Points of the block and points used in the quotients.
    """

    wavenumber: np.ndarray
    frequency: dict
    tensor: np.ndarray
    points: int
    interior_points: int

    def relative_error(self, relation) -> dict:
        """Per branch, (n_k,) ``omega_measured / omega_relation - 1`` against a
        :class:`~peridyn.analysis.dispersion.DispersionRelation` at the same wavenumbers."""
        if not np.allclose(relation.branches["longitudinal"].wavenumber, self.wavenumber):
            raise InputError("the relation must be evaluated at the measured wavenumbers")
        return {
            name: omega / relation.branches[name].frequency - 1.0 for name, omega in self.frequency.items()
        }


def lattice_block_model(
    model: str,
    medium: Medium,
    horizon: float,
    spacing: float,
    influence: str = "constant",
    dim: int = 3,
    partial_volumes: bool = True,
    plane: str = "stress",
) -> tuple[Model, np.ndarray]:
    """A model on a block of the lattice and the mask of its interior points.

    The block is centred at the origin with ``INTERIOR_POINTS`` interior points
    per axis, each farther than twice the reach ``delta + h sqrt(dim)/2`` from
    the surface. 2D: a square of thickness ``spacing``.

    Returns
    -------
    model : Model
    interior : (n_points,) bool
    """
    if dim not in (2, 3):
        raise InputError(f"the engine measures 2D and 3D media only, got dimension {dim!r}")
    margin = 2.0 * (horizon + spacing * np.sqrt(dim) / 2.0)
    n = 2 * int(np.ceil(margin / spacing)) + INTERIOR_POINTS
    side = n * spacing
    if dim == 3:
        body = geometry.box((side,) * 3, spacing, origin=(-side / 2,) * 3)
    else:
        body = geometry.rectangle(
            side, side, spacing, thickness=spacing, plane=plane, origin=(-side / 2,) * 2
        )
    bonds = find_bonds(body, horizon, influence, partial_volumes=partial_volumes)
    implied = model_class(model).implied_poisson_ratio(dim, plane)
    nu = medium.nu if implied is None else None  # a bond-based material takes none
    built = make_model(model, body, bonds, E=medium.E, density=medium.density, nu=nu)
    reach = np.abs(body.points[:, :dim])
    inside = np.all(reach <= reach.max() - margin, axis=1)
    return built, inside


def measure_dispersion(
    model: str,
    medium: Medium,
    horizon: float,
    spacing: float,
    wavenumbers,
    influence: str = "constant",
    dim: int = 3,
    direction="x",
    partial_volumes: bool = True,
    plane: str = "stress",
) -> MeasuredDispersion:
    """Measure omega(k) of every branch with the model's force on a lattice block.

    Parameters
    ----------
    model : str
        A registered material ("pmb", "lps", ...).
    medium : Medium
    horizon, spacing : float, m
    wavenumbers : (n_k,) array, rad/m
    influence, dim, direction, partial_volumes, plane
        As in :func:`peridyn.analysis.dispersion.dispersion_relation` (dim 2 or 3).

    Returns
    -------
    MeasuredDispersion
    """
    k = np.asarray(wavenumbers, dtype=float).ravel()
    if k.size == 0 or not np.all(np.isfinite(k)) or np.any(k <= 0):
        raise InputError("wavenumbers must be positive and finite (rad/m)")
    built, inside = lattice_block_model(
        model, medium, horizon, spacing, influence, dim, partial_volumes, plane
    )
    d = parse_direction(direction, dim)
    basis = polarisations(d, dim)
    tensor = np.stack([_measured_tensor(built, inside, basis, kk, AMPLITUDE * spacing) for kk in k])
    lam, _ = branch_eigenvalues(tensor, np.zeros_like(tensor))
    frequency = {
        name: np.sqrt(np.maximum(lam[:, b], 0.0) / medium.density) for b, name in enumerate(BRANCHES[:dim])
    }
    return MeasuredDispersion(k, frequency, tensor, built.body.n_points, int(inside.sum()))


def _measured_tensor(
    built: Model, inside: np.ndarray, basis: np.ndarray, k: float, amplitude: float
) -> np.ndarray:
    """(dim, dim) acoustic tensor in the polarisation basis from plane-wave quotients."""
    x = built.body.points
    wave = np.cos(k * (x @ basis[0]))
    weight = wave[inside]
    columns = []
    for e in basis:
        u = amplitude * wave[:, None] * e
        f = 0.5 * (built.force(u) - built.force(-u))
        columns.append(-(f[inside] @ basis.T).T @ weight / (amplitude * weight @ weight))
    return np.stack(columns, axis=1)
