"""Linear static equilibrium K u = F of the current bonds, with prescribed displacements.

The fatigue loop needs the displacement at the maximum load after every step that broke bonds;
the linearised model (``peridyn.stiffness``) is adequate for fatigue strains. K is applied
matrix-free (``stiffness_operator``, always with the bonds intact now) and the system on the
free dofs is solved by preconditioned conjugate gradients, warm started from the previous step:

- ``direct`` (default): the preconditioner is a sparse factorisation of the stiffness at some
  earlier step (``solvers.modal.shifted_inverse``: the augmented LPS system in nested-dissection
  order, as sparse as the bonds). Fresh, it solves the system in one iteration; after bonds
  break, K differs from the factorised one by a low-rank change (each broken bond removes a
  rank-one pair term and changes two dilatation rows), so CG needs a few iterations more; the
  search directions of the earlier solves (up to ``recycle``) deflate the later ones
  (``fatigue.pcg``), so the iterations grow little as the change accumulates. When a solve has
  not converged after ``refactor_iterations``, K is factorised again and the solve goes on from
  where it was.
- ``cg``: Jacobi preconditioner (no factorisation; least memory, many more iterations).

Tolerance: the relative equilibrium residual ||F - K u|| / ||F|| on the free dofs is brought below
``rtol`` (default 1e-8). The fatigue model reads bond strains; an error of delta in a strain
changes a bond's life decrement by the relative amount m delta / (eps - eps_inf) (eq. 7.4, m <= 4
for V5), so strains to about 1e-6 relative (what 1e-8 on the residual gives on these bodies,
tested) leave the cycle at which a bond breaks unchanged within one mapping step by far.

A tiny diagonal shift (1e-9 of the mean diagonal stiffness of the intact body) keeps bodies held
only by balanced forces, and points that lost every bond, solvable: it changes the elastic
response by about 1e-9 and leaves linear bond strains free of rigid motion.
"""

from __future__ import annotations

import time as clock
from dataclasses import dataclass

import numpy as np

from peridyn.errors import InputError
from peridyn.fatigue.pcg import PCGResult, RecycledDirections, deflated_pcg
from peridyn.loads import Loading
from peridyn.materials.base import Model
from peridyn.solvers.modal import free_dofs, shifted_inverse
from peridyn.stiffness import stiffness_operator, stiffness_parts

#: Diagonal shift relative to the mean diagonal stiffness.
SHIFT = 1e-9
#: CG iterations with an old factorisation after which K is factorised again.
REFACTOR_ITERATIONS = 40
#: Search directions of earlier solves kept to deflate the next ones (``fatigue.pcg``).
RECYCLE = 80


@dataclass
class SolveRecord:
    """One equilibrium solve: CG ``iterations``, whether it ``factorised`` K, the true relative
    ``residual`` ||F - K u|| / ||F|| on the free dofs, and its wall time in ``seconds``."""

    iterations: int
    factorised: bool
    residual: float
    seconds: float


class LinearStatics:
    """Displacement (n_points, 3), m, of ``model`` under ``loading`` at time ``time`` (s).

    Parameters
    ----------
    method : "auto" (= "direct"), "direct" (factorisation as CG preconditioner) or "cg" (Jacobi)
    rtol : relative equilibrium residual the solves reach
    refactor_iterations : CG iterations with an old factorisation before it is renewed
    recycle : search directions of earlier solves kept to deflate later ones (0: none)

    Attributes
    ----------
    records : list of SolveRecord, one per ``solve()``
    """

    def __init__(self, model: Model, loading: Loading, time: float = 1.0, method: str = "auto",
                 rtol: float = 1e-8, refactor_iterations: int = REFACTOR_ITERATIONS,
                 recycle: int = RECYCLE):
        if method not in ("auto", "direct", "cg"):
            raise InputError(f"linear solver must be auto, direct or cg, got {method!r}")
        if not 0.0 < rtol < 1.0:
            raise InputError(f"linear solver tolerance rtol must be in (0, 1), got {rtol!r}")
        if refactor_iterations < 1:
            raise InputError(f"refactor_iterations must be at least 1, got {refactor_iterations!r}")
        if recycle < 0:
            raise InputError(f"recycle (directions kept between solves) must be >= 0, got {recycle!r}")
        self.model, self.loading, self.time, self.rtol = model, loading, float(time), rtol
        self.refactor_iterations = int(refactor_iterations)
        self.method = "direct" if method == "auto" else method
        n = model.body.n_points
        self.free = free_dofs(model, loading.constrained)
        self.u_prescribed = np.zeros((n, 3))
        loading.apply_kinematics(self.time, 1.0, self.u_prescribed, np.zeros((n, 3)))
        force = loading.body_force_density(self.time, np.zeros((n, 3)))
        self.force = (force * model.body.volumes[:, None]).ravel()
        if not (np.any(self.u_prescribed) or np.any(self.force)):
            raise InputError(f"the loads at t = {self.time:g} s are all zero: a fatigue run needs a "
                             "cyclic load (non-zero displacement or force at the maximum load)")
        self.stiffness = stiffness_operator(model)  # reads model.bonds.intact at every product
        diagonal = stiffness_parts(model).diagonal()[self.free]
        self.shift = SHIFT * float(diagonal.mean()) if len(self.free) else 0.0
        self.records: list[SolveRecord] = []
        self._preconditioner = None
        self.recycled = RecycledDirections(recycle if self.method == "direct" else 0)
        self._last = None

    def solve(self) -> np.ndarray:
        """Equilibrium displacement with the bonds intact now."""
        start = clock.perf_counter()
        u = self.u_prescribed.ravel().copy()
        if len(self.free) == 0:
            return u.reshape(-1, 3)
        rhs = (self.force - self._product(u))[self.free]
        factorised = False
        if self.method == "cg":
            diagonal = self._diagonal()
            result = deflated_pcg(self._free_product, lambda r: r / diagonal, rhs, self._last,
                                  self.rtol, 20 * len(rhs))
        else:
            if self._preconditioner is None:
                self._factorise()
                factorised = True
            result = self._factor_pcg(rhs, self._last)
            if not result.converged and not factorised:  # the old factorisation is too far off now
                self._factorise()
                factorised = True
                more = self._factor_pcg(rhs, result.x)
                result = PCGResult(more.x, result.iterations + more.iterations, more.converged,
                                   more.directions)
            self.recycled.add(result.directions)
        if not result.converged:
            raise InputError(f"fatigue static solve: CG did not converge in {result.iterations} "
                             f"iterations to the relative residual {self.rtol:g}")
        self._last = result.x
        u[self.free] = result.x
        residual = np.linalg.norm(rhs - self._free_product(result.x)) / max(np.linalg.norm(rhs), 1e-300)
        self.records.append(SolveRecord(result.iterations, factorised, float(residual),
                                        clock.perf_counter() - start))
        return u.reshape(-1, 3)

    def _product(self, u: np.ndarray) -> np.ndarray:
        """K u (3 n,), N, on all dofs, with the bonds intact now (matrix-free)."""
        return self.stiffness @ u

    def _free_product(self, v: np.ndarray) -> np.ndarray:
        """(K + shift I) v on the free dofs (free,), with the bonds intact now."""
        full = np.zeros(3 * self.model.body.n_points)
        full[self.free] = v
        return self._product(full)[self.free] + self.shift * v

    def _factor_pcg(self, rhs: np.ndarray, x0: np.ndarray | None) -> PCGResult:
        """CG preconditioned by the factorisation, deflated by the recycled directions."""
        return deflated_pcg(self._free_product, self._preconditioner.matvec, rhs, x0, self.rtol,
                            self.refactor_iterations, self.recycled.basis(self._free_product))

    def _diagonal(self) -> np.ndarray:
        """Diagonal of the free system with the bonds intact now (free,)."""
        return stiffness_parts(self.model).diagonal()[self.free] + self.shift

    def _factorise(self) -> None:
        """Factorise K + shift I on the free dofs with the bonds intact now."""
        self._preconditioner = None  # release the old factor before building the new one
        self.recycled.clear()
        body = self.model.body
        self._preconditioner = shifted_inverse(stiffness_parts(self.model), self.free,
                                               np.full(len(self.free), self.shift), body.points,
                                               self.model.bonds.horizon)
