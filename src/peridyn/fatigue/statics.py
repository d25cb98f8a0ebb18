"""Linear static equilibrium K u = F of the current bonds, with prescribed displacements.

The fatigue loop needs the displacement at the maximum load after every step that broke bonds;
the linearised model (``peridyn.linalg.stiffness``) is adequate for fatigue strains. K is applied
matrix-free (``stiffness_operator``, always with the bonds intact now) and the system on the
free dofs is solved by preconditioned conjugate gradients, warm started from the previous step.
The preconditioner is built once from the bonds of some step and kept while bonds break (K then
differs from it by a low-rank change: each broken bond removes a rank-one pair term and changes
two dilatation rows); when a solve with it has not converged after ``refactor_iterations``, it is
built again from the bonds intact now and the solve goes on from where it was.

- ``amg``: one V-cycle of smoothed-aggregation AMG on the pair proxy of the bonds
  (``linalg.amg.proxy_stiffness`` and ``amg_preconditioner``, rigid motions as
  near-null space). About 15-25 iterations per solve, each a V-cycle and a product, both linear
  in the number of points; little memory.
- ``direct``: a sparse factorisation of K (``linalg.shift_invert.shifted_inverse``: the augmented LPS
  system in nested-dissection order). Fresh, it solves the system in one iteration; after bonds
  break, a few more, fewer still because the search directions of the earlier solves (up to
  ``recycle``) deflate the later ones (``linalg.krylov``). Each iteration is a triangular solve
  with the whole factor, whose size grows faster than the points (3 GB and 1.5 s per solve at
  48 000 points of the dog-bone under load, against 0.12-0.2 s for a V-cycle).
- ``auto`` (default): ``direct`` up to ``DIRECT_DOFS`` free dofs, ``amg`` above.
- ``cg``: Jacobi preconditioner (no set-up; many more iterations).

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
from peridyn.linalg.amg import amg_preconditioner, proxy_stiffness, rigid_fields
from peridyn.linalg.block_operator import block_stiffness_operator
from peridyn.linalg.dofs import free_dofs
from peridyn.linalg.krylov import KrylovResult, RecycledDirections, pcg
from peridyn.linalg.shift_invert import shifted_inverse
from peridyn.linalg.stiffness import stiffness_operator, stiffness_parts
from peridyn.physics.loads import Loading
from peridyn.physics.materials.base import Model

#: Diagonal shift relative to the mean diagonal stiffness.
SHIFT = 1e-9
#: CG iterations with a preconditioner of earlier bonds after which it is built again (a fresh
#: AMG V-cycle needs about 20 on the dog-bone at 14 000-48 000 points, a stale one up to 36 after
#: 900 broken bonds; rebuilding costs about as much as 30 iterations; a stale factor needs < 20).
REFACTOR_ITERATIONS = 30
#: CG iterations at most with a preconditioner built from the bonds intact now.
FRESH_ITERATIONS = 1000
#: ``auto`` factorises up to this many free dofs and uses AMG above (at the 0.5 mm dog-bone,
#: 42 000 dofs, both take the same time; at 134 000 the factor's solves cost 10 V-cycles each).
DIRECT_DOFS = 40_000
#: Search directions of earlier solves kept to deflate the next ones (``linalg.krylov``).
RECYCLE = 80
#: Vectors per block product (bounds the (n_bonds, BLOCK) work arrays of ``linalg.block_operator``).
BLOCK = 20


@dataclass
class SolveRecord:
    """One equilibrium solve: CG ``iterations``, whether it ``factorised`` (built the
    preconditioner anew: factorised K or set up the AMG hierarchy), the true relative
    ``residual`` ||F - K u|| / ||F|| on the free dofs, and its wall time in ``seconds``."""

    iterations: int
    factorised: bool
    residual: float
    seconds: float


class LinearStatics:
    """Displacement (n_points, 3), m, of ``model`` under ``loading`` at time ``time`` (s).

    Parameters
    ----------
    method : "auto", "amg" (AMG V-cycle as CG preconditioner), "direct" (factorisation) or "cg"
        (Jacobi); see the module docstring
    rtol : relative equilibrium residual the solves reach
    refactor_iterations : CG iterations with an old preconditioner before it is renewed
    recycle : search directions of earlier solves kept to deflate later ones (0: none; "direct"
        only: with AMG they save a few per cent of the iterations at the cost of dense products)

    Attributes
    ----------
    records : list of SolveRecord, one per ``solve()``
    """

    def __init__(
        self,
        model: Model,
        loading: Loading,
        time: float = 1.0,
        method: str = "auto",
        rtol: float = 1e-8,
        refactor_iterations: int = REFACTOR_ITERATIONS,
        recycle: int = RECYCLE,
    ):
        if method not in ("auto", "amg", "direct", "cg"):
            raise InputError(f"linear solver must be auto, amg, direct or cg, got {method!r}")
        if not 0.0 < rtol < 1.0:
            raise InputError(f"linear solver tolerance rtol must be in (0, 1), got {rtol!r}")
        if refactor_iterations < 1:
            raise InputError(f"refactor_iterations must be at least 1, got {refactor_iterations!r}")
        if recycle < 0:
            raise InputError(f"recycle (directions kept between solves) must be >= 0, got {recycle!r}")
        self.model, self.loading, self.time, self.rtol = model, loading, float(time), rtol
        self.refactor_iterations = int(refactor_iterations)
        n = model.body.n_points
        self.free = free_dofs(model, loading.constrained)
        if method == "auto":
            method = "direct" if len(self.free) <= DIRECT_DOFS else "amg"
        self.method = method
        self.u_prescribed = np.zeros((n, 3))
        loading.apply_kinematics(self.time, 1.0, self.u_prescribed, np.zeros((n, 3)))
        force = loading.body_force_density(self.time, np.zeros((n, 3)))
        self.force = (force * model.body.volumes[:, None]).ravel()
        if not (np.any(self.u_prescribed) or np.any(self.force)):
            raise InputError(
                f"the loads at t = {self.time:g} s are all zero: a fatigue run needs a "
                "cyclic load (non-zero displacement or force at the maximum load)"
            )
        self.stiffness = stiffness_operator(model)  # reads model.bonds.intact at every product
        self.block_stiffness = block_stiffness_operator(model, self.free)  # likewise, on the free dofs
        diagonal = stiffness_parts(model).diagonal()[self.free]
        self.shift = SHIFT * float(diagonal.mean()) if len(self.free) else 0.0
        self.records: list[SolveRecord] = []
        self._preconditioner = None
        self.recycled = RecycledDirections(recycle if self.method == "direct" else 0)  # see recycle
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
            result = pcg(
                self._free_product,
                lambda r: r / diagonal,
                rhs,
                self.rtol * np.linalg.norm(rhs),
                20 * len(rhs),
                x0=self._last,
                keep_directions=True,
            )
        else:
            if self._preconditioner is None:
                self._build_preconditioner()
                factorised = True
            result = self._preconditioned_cg(rhs, self._last, factorised)
            if not result.converged and not factorised:  # the old preconditioner is too far off now
                self._build_preconditioner()
                factorised = True
                more = self._preconditioned_cg(rhs, result.x, True)
                result = KrylovResult(
                    more.x, result.iterations + more.iterations, more.converged, more.directions
                )
            self.recycled.add(result.directions)
        if not result.converged:
            raise InputError(
                f"fatigue static solve: CG did not converge in {result.iterations} "
                f"iterations to the relative residual {self.rtol:g}"
            )
        self._last = result.x
        u[self.free] = result.x
        residual = np.linalg.norm(rhs - self._free_product(result.x)) / max(np.linalg.norm(rhs), 1e-300)
        self.records.append(
            SolveRecord(result.iterations, factorised, float(residual), clock.perf_counter() - start)
        )
        return u.reshape(-1, 3)

    def _product(self, u: np.ndarray) -> np.ndarray:
        """K u (3 n,), N, on all dofs, with the bonds intact now (matrix-free)."""
        return self.stiffness @ u

    def _free_product(self, v: np.ndarray) -> np.ndarray:
        """(K + shift I) v on the free dofs (free,), with the bonds intact now."""
        full = np.zeros(3 * self.model.body.n_points)
        full[self.free] = v
        return self._product(full)[self.free] + self.shift * v

    def _free_block_product(self, V: np.ndarray) -> np.ndarray:
        """(K + shift I) V on the free dofs for a block V (free, k), BLOCK columns per bond pass."""
        out = np.empty_like(V)
        for start in range(0, V.shape[1], BLOCK):
            part = V[:, start : start + BLOCK]
            out[:, start : start + BLOCK] = self.block_stiffness.matmat(part) + self.shift * part
        return out

    def _preconditioned_cg(self, rhs: np.ndarray, x0: np.ndarray | None, fresh: bool) -> KrylovResult:
        """CG with the kept preconditioner, deflated by the recycled directions; at most
        FRESH_ITERATIONS iterations when the preconditioner is ``fresh``, else refactor_iterations."""
        maxiter = FRESH_ITERATIONS if fresh else self.refactor_iterations
        return pcg(
            self._free_product,
            self._preconditioner.matvec,
            rhs,
            self.rtol * np.linalg.norm(rhs),
            maxiter,
            x0=x0,
            deflation=self.recycled.basis(self._free_block_product),
            keep_directions=True,
        )

    def _diagonal(self) -> np.ndarray:
        """Diagonal of the free system with the bonds intact now (free,)."""
        return stiffness_parts(self.model).diagonal()[self.free] + self.shift

    def _build_preconditioner(self) -> None:
        """Factorise K + shift I on the free dofs (``direct``), or set up the AMG V-cycle on the
        pair proxy plus the same relative shift (``amg``), with the bonds intact now."""
        self._preconditioner = None  # release the old one before building the new one
        self.recycled.clear()
        body = self.model.body
        if self.method == "direct":
            self._preconditioner = shifted_inverse(
                stiffness_parts(self.model),
                self.free,
                np.full(len(self.free), self.shift),
                body.points,
                self.model.bonds.horizon,
            )
            return
        proxy = proxy_stiffness(self.model, self.free)
        self._preconditioner = amg_preconditioner(
            proxy,
            np.ones(len(self.free)),
            rigid_fields(body.points)[self.free],
            SHIFT * float(proxy.diagonal().mean()),
        )
