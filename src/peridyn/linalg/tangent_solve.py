"""The linear systems of the implicit solvers: (K(u) + s M) du = r on the free dofs.

K(u) is the consistent tangent (``linalg.tangent``), M the lumped mass and s >= 0 a mass shift
(1/s^2: Newmark's 4 / dt^2 + 2 c / dt, zero for Newton's statics). Two ways:

- ``lu``: the tangent assembled and factorised by SuperLU in nested-dissection order
  (``linalg.ordering``), exact to round-off. The factor's size is estimated first
  (``estimated_factor_entries``; the tangent of a material with dilatation reaches two
  horizons): a factor that would not fit in memory is refused with its numbers.
- ``cg``: scipy's conjugate gradients (``linalg.krylov.solve_spd``) on the matrix-free tangent
  (``tangent_operator``), preconditioned by one smoothed-aggregation V-cycle on the sparse
  pair proxy of the short bonds (``linalg.amg``), scaled to the tangent and shifted by s M;
  where the mass shift dominates the stiffness (``MASS_DOMINANT``: implicit steps near the
  explicit stable step) by the mass diagonal instead. The preconditioner is set up once and
  kept until bonds break; memory is the bonds' and the proxy's.

``auto`` factorises when the estimated factor holds at most ``DIRECT_BUDGET`` bytes (small
bodies, most 2D ones: exact and faster there) and takes ``cg`` beyond (3D bodies of more than
a few thousand points, wide horizons), where the factor grows much faster than the bonds.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy.sparse.linalg import LinearOperator

from peridyn.discretization.geometry import memory_limit
from peridyn.errors import InputError, did_you_mean
from peridyn.linalg.amg import (
    amg_preconditioner,
    orthonormal,
    proxy_aggregates,
    proxy_stiffness,
    rigid_fields,
)
from peridyn.linalg.krylov import solve_spd
from peridyn.linalg.ordering import estimated_factor_entries
from peridyn.linalg.shift_invert import ordered_lu
from peridyn.linalg.stiffness import mass_matrix
from peridyn.linalg.tangent import tangent_operator, tangent_stiffness
from peridyn.physics.materials.base import Model

logger = logging.getLogger(__name__)

#: Linear solvers of the Newton and Newmark systems (see the module docstring).
LINEAR_SOLVERS = ("auto", "lu", "cg")

#: Relative residual at which the conjugate gradients stop: Newton's increments must be exact
#: to well below its tolerances (1e-10 m on increments of up to ~1e-6 m, 1e-10 relative residual).
CG_RTOL = 1e-12

#: Bytes of the estimated LU factor (8-byte values, 4-byte indices) up to which ``auto``
#: factorises.
DIRECT_BUDGET = 2**28

#: Fraction of the memory an explicit ``lu`` factor may take.
MEMORY_SHARE = 0.7

#: Bytes per factor entry.
FACTOR_ENTRY_BYTES = 12.0

#: The mass shift s dominates K when it is at least this times the ratio K / M of a rough field
#: (the stiff end of the spectrum): then K + s M has a condition number below about 1.3 and
#: CG scaled by the mass converges in about ten iterations, where a V-cycle costs more than it
#: saves (measured on the 38 400-point plate at dt = 20 ns: s is 66 times that ratio).
MASS_DOMINANT = 10.0

#: Shift of the preconditioner without mass shift (statics), relative to the proxy's diagonal
#: over the mass: keeps its coarsest level definite when only a 3-2-1 support holds the body.
STATIC_SHIFT = 1e-6


def check_linear_solver(name: str) -> None:
    """Raise InputError unless ``name`` is one of ``LINEAR_SOLVERS``."""
    if name not in LINEAR_SOLVERS:
        raise InputError(
            f"unknown linear solver {name!r}{did_you_mean(name, LINEAR_SOLVERS)}; "
            f"choose one of {LINEAR_SOLVERS}"
        )


def _reach(model: Model) -> float:
    """Longest coupling of the tangent, m: two horizons with a dilatation, one without."""
    return 2.0 * model.bonds.horizon if model.has_dilatation else model.bonds.horizon


def factor_bytes(model: Model) -> float:
    """Estimated bytes of the tangent's LU factor in nested-dissection order."""
    return FACTOR_ENTRY_BYTES * estimated_factor_entries(model.body.points, _reach(model), model.body.dim)


def choose_linear_solver(model: Model, requested: str = "auto") -> str:
    """``lu`` or ``cg`` for ``model`` (module docstring); an ``lu`` whose estimated factor
    exceeds ``MEMORY_SHARE`` of the memory is refused with the numbers."""
    check_linear_solver(requested)
    if requested == "cg":
        return "cg"
    needed = factor_bytes(model)
    if requested == "auto":
        budget = min(DIRECT_BUDGET, MEMORY_SHARE * memory_limit())
        if needed <= budget:
            return "lu"
        logger.info(
            "linear solver: cg (the tangent's LU factor would take ~%.2f GiB, over %.2f GiB)",
            needed / 2**30,
            budget / 2**30,
        )
        return "cg"
    available = memory_limit()
    if needed > MEMORY_SHARE * available:
        raise InputError(
            f"the sparse LU of this tangent would hold about {needed / FACTOR_ENTRY_BYTES / 1e9:.2f} "
            f"billion entries (~{needed / 2**30:.1f} GiB; {available / 2**30:.0f} GiB here): "
            "use linear_solver cg (or auto)"
        )
    return "lu"


class TangentSolver:
    """Solves (K(u) + s M) du = r on given free dofs, by LU or by AMG-preconditioned CG.

    Parameters
    ----------
    model : Model
    method : ``auto``, ``lu`` or ``cg`` (``choose_linear_solver``)
    mass_shift : float, 1/s^2
        s, the factor of the lumped mass M = rho V added to the tangent.

    Attributes
    ----------
    method : ``lu`` or ``cg``, the one chosen
    preconditioner_kind : ``mass`` or ``amg`` once CG has set one up (``MASS_DOMINANT``), else None
    """

    def __init__(self, model: Model, method: str = "auto", mass_shift: float = 0.0):
        self.model = model
        self.method = choose_linear_solver(model, method)
        self.mass_shift = float(mass_shift)
        self.mass = mass_matrix(model).diagonal()
        self._preconditioner = None
        self.preconditioner_kind = None
        self._built_for = (None, -1)  # (active dofs, intact bonds) of the preconditioner

    def solve(self, u: np.ndarray, free: np.ndarray, rhs: np.ndarray) -> np.ndarray:
        """du (len(free),) with (K(u) + s M)[free][:, free] du = rhs, u (n, 3) m, rhs N.

        Dofs without stiffness (a point whose bonds all broke; without a mass shift) get
        du = 0."""
        if self.method == "lu":
            return self._solve_direct(u, free, rhs)
        active = free if self.mass_shift > 0 else free[self._bonded(free)]
        du = np.zeros(len(free))
        if len(active) == 0:
            return du
        shift = self.mass_shift * self.mass[active]
        k = tangent_operator(self.model, u, active)
        a = LinearOperator(k.shape, matvec=lambda v: k @ v + shift * np.ravel(v), dtype=np.float64)
        x = solve_spd(a, rhs[np.searchsorted(free, active)], CG_RTOL, self._preconditioner_on(active, k))
        du[np.searchsorted(free, active)] = x
        return du

    def _bonded(self, free: np.ndarray) -> np.ndarray:
        """Mask of the ``free`` dofs whose point has an intact bond."""
        b = self.model.bonds
        bonded = np.bincount(b.owners()[b.intact], minlength=self.model.body.n_points) > 0
        return bonded[free // 3]

    def _solve_direct(self, u, free, rhs) -> np.ndarray:
        k = tangent_stiffness(self.model, u)[free][:, free].tocsr()
        k.setdiag(k.diagonal() + self.mass_shift * self.mass[free])
        active = np.flatnonzero(k.diagonal() != 0)
        x = np.zeros(len(rhs))
        if len(active) == 0:
            return x
        lu, perm = ordered_lu(
            k[active][:, active], free[active] // 3, self.model.body.points, _reach(self.model)
        )
        x[active[perm]] = lu.solve(rhs[active][perm])
        return x

    def _preconditioner_on(self, active: np.ndarray, k: LinearOperator) -> LinearOperator:
        """The preconditioner for the ``active`` dofs, built again when they or the intact bonds
        changed since the last one: the mass diagonal where the mass shift dominates, the
        V-cycle otherwise."""
        intact = int(np.count_nonzero(self.model.bonds.intact))
        dofs, bonds = self._built_for
        if self._preconditioner is not None and bonds == intact and np.array_equal(dofs, active):
            return self._preconditioner
        self._preconditioner = None  # release the old one first
        mass = self.mass[active]
        # a rough field probes the high-frequency end of K, where the shift competes with it
        probe = np.random.default_rng(0).standard_normal(len(active))
        stiffness = float(probe @ (k @ probe))
        rate = stiffness / float(probe @ (mass * probe))  # K / M there, 1/s^2
        if self.mass_shift >= MASS_DOMINANT * rate:
            scale = 1.0 / ((self.mass_shift + rate) * mass)
            self._preconditioner = LinearOperator(k.shape, matvec=lambda v: scale * np.ravel(v))
            self.preconditioner_kind = "mass"
        else:
            proxy = proxy_stiffness(self.model, active)
            proxy = proxy * (stiffness / float(probe @ (proxy @ probe)))  # the proxy's scale is arbitrary
            shift = self.mass_shift or STATIC_SHIFT * float(np.median(proxy.diagonal() / mass))
            near_null = orthonormal(rigid_fields(self.model.body.points)[active])
            aggregates = proxy_aggregates(self.model, active)
            self._preconditioner = amg_preconditioner(proxy.tocsr(), mass, near_null, shift, aggregates)
            self.preconditioner_kind = "amg"
        self._built_for = (active.copy(), intact)
        return self._preconditioner
