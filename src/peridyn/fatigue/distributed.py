"""Linear static equilibrium of the fatigue loop on one MPI rank's part of the body.

The distributed stand-in of ``fatigue.statics.LinearStatics`` (same system, same criterion):
K u = F at the maximum load, with the prescribed displacements, K linearised with the bonds
intact now plus the same tiny diagonal shift (``statics.SHIFT`` of the mean diagonal stiffness of
the free dofs at the start). Each rank holds the owned free rows (``linalg.distributed.RankDofs``);
K is applied matrix-free with one halo exchange (``RankStiffness``), the system solved by CG
(``solvers.distributed_static.conjugate_gradients``: global inner products by allreduce)
preconditioned by each rank's AMG V-cycle (block Jacobi, ``rank_preconditioner``), warm started
from the previous solve, until ||F - (K + shift) u|| <= rtol ||F|| over every rank's free dofs.

The preconditioner is kept while bonds break and built again from the bonds intact now when a
solve with it has not converged after ``STALE_FACTOR`` times the iterations of the solve that
built it (at least ``statics.REFACTOR_ITERATIONS``); the solve then goes on from where it was.
Serial renews after a fixed 30 iterations, tuned for its own V-cycle (20 fresh). Block Jacobi
needs more: on the 2D SEN specimen at 1 mm on 2 ranks, about 50 from zero and 20-50 warm started,
as many after 96 broken bonds as fresh; renewing after 30 rebuilt it at 35 of 49 solves, and the
run's solves took 28 s instead of 2.9 s (loaded machine).

The answer equals the serial one to the solver tolerance, not bit for bit: the inner products
are rounded in rank order and the preconditioner differs.
"""

from __future__ import annotations

import time as clock

import numpy as np

from peridyn.errors import InputError
from peridyn.fatigue.statics import FRESH_ITERATIONS, REFACTOR_ITERATIONS, SHIFT, SolveRecord
from peridyn.linalg.distributed import RankDofs, RankStiffness, rank_preconditioner
from peridyn.linalg.stiffness import stiffness_parts
from peridyn.parallel.domain import Domain
from peridyn.physics.loads import Loading
from peridyn.physics.materials.base import Model
from peridyn.solvers.distributed_static import conjugate_gradients

#: A solve with an old preconditioner may take this many times the iterations of the solve that
#: built it before the preconditioner is built again.
STALE_FACTOR = 2


class _Shifted:
    """(K + shift I) applied to the rank's free dofs (collective)."""

    def __init__(self, K: RankStiffness, shift: float):
        self.K, self.shift = K, shift

    def __matmul__(self, v: np.ndarray) -> np.ndarray:
        return self.K @ v + self.shift * v


class RankStatics:
    """Displacement (n_local, 3), m, of a rank's part ``model`` under ``loading`` at ``time`` (s),
    ghost rows filled (see the module docstring; collective: every rank calls each method).

    Parameters
    ----------
    model : Model
        The rank's part (owned points, then ghosts).
    domain : Domain
    rtol : relative equilibrium residual the solves reach (as ``LinearStatics``)
    refactor_iterations : CG iterations with an old preconditioner before it is renewed; None:
        ``STALE_FACTOR`` times those of the solve that built it, at least REFACTOR_ITERATIONS

    Attributes
    ----------
    records : list of ``statics.SolveRecord``, one per ``solve()``
    """

    method = "amg"

    def __init__(
        self,
        model: Model,
        loading: Loading,
        domain: Domain,
        time: float = 1.0,
        rtol: float = 1e-8,
        refactor_iterations: int | None = None,
    ):
        if not 0.0 < rtol < 1.0:
            raise InputError(f"linear solver tolerance rtol must be in (0, 1), got {rtol!r}")
        self.model, self.domain, self.rtol = model, domain, rtol
        self.refactor_iterations = refactor_iterations
        n = model.body.n_points
        self.dofs = RankDofs(model, domain, loading.constrained)
        self.u_prescribed = np.zeros((n, 3))
        loading.apply_kinematics(float(time), 1.0, self.u_prescribed, np.zeros((n, 3)))
        force = loading.body_force_density(float(time), np.zeros((n, 3)))
        self.force = (force * model.body.volumes[:, None]).ravel()[self.dofs.dofs]
        loaded = domain.max(float(np.any(self.u_prescribed[: domain.n_owned]) or np.any(self.force)))
        if not loaded:
            raise InputError(
                f"the loads at t = {float(time):g} s are all zero: a fatigue run needs a "
                "cyclic load (non-zero displacement or force at the maximum load)"
            )
        self.stiffness = RankStiffness(self.dofs)
        diagonal = stiffness_parts(model).diagonal()[self.dofs.dofs]
        total = domain.allsum(np.array([diagonal.sum(), len(diagonal)], dtype=np.float64))
        shift = SHIFT * float(total[0] / total[1]) if total[1] else 0.0
        self.operator = _Shifted(self.stiffness, shift)
        self.records: list[SolveRecord] = []
        self._preconditioner = None
        self._stale_limit = REFACTOR_ITERATIONS if refactor_iterations is None else int(refactor_iterations)
        self._last = None

    def solve(self) -> np.ndarray:
        """Equilibrium displacement with the bonds intact now (n_local, 3), m, ghosts filled."""
        start = clock.perf_counter()
        u = self.u_prescribed.copy()
        if self.dofs.n_total == 0:
            return u
        rhs = self.force - self.stiffness.field_rows(u[:, :, None])[:, 0]
        target = self.rtol * self._norm(rhs)
        x = np.zeros_like(rhs) if self._last is None else self._last.copy()
        factorised = self._preconditioner is None
        if factorised:
            self._preconditioner = rank_preconditioner(self.dofs)
        iterations, converged = self._cg(rhs, x, target, FRESH_ITERATIONS if factorised else None)
        fresh = iterations  # with the preconditioner built for this solve
        if not converged and not factorised:  # the old preconditioner is too far off now
            self._preconditioner = rank_preconditioner(self.dofs)
            factorised = True
            fresh, converged = self._cg(rhs, x, target, FRESH_ITERATIONS)
            iterations += fresh
        if factorised and self.refactor_iterations is None:
            self._stale_limit = max(REFACTOR_ITERATIONS, STALE_FACTOR * fresh)
        if not converged:
            raise InputError(
                f"fatigue static solve: CG did not converge in {iterations} "
                f"iterations to the relative residual {self.rtol:g}"
            )
        self._last = x
        u.reshape(-1)[self.dofs.dofs] = x
        self.domain.exchange(u)
        residual = self._norm(rhs - self.operator @ x) / max(self._norm(rhs), 1e-300)
        self.records.append(SolveRecord(iterations, factorised, residual, clock.perf_counter() - start))
        return u

    def _norm(self, v: np.ndarray) -> float:
        """Euclidean norm of a vector of every rank's free dofs (collective)."""
        return float(self.dofs.column_norms(v[:, None])[0])

    def _cg(self, rhs, x, target: float, maxiter: int | None) -> tuple[int, bool]:
        """Improve ``x`` in place by CG until ||rhs - (K + shift) x|| <= ``target`` (at most
        ``maxiter`` iterations, else those allowed an old preconditioner); (iterations, converged)."""
        maxiter = self._stale_limit if maxiter is None else maxiter
        r = rhs - self.operator @ x
        if self._norm(r) <= target:
            return 0, True
        dx, used = conjugate_gradients(
            self.operator, self._preconditioner, self.dofs, r, target, np.ones_like(r), maxiter
        )
        x += dx
        return used, self._norm(rhs - self.operator @ x) <= target
