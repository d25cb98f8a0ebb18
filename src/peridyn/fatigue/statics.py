"""Linear static equilibrium K u = F of the current bonds, with prescribed displacements.

The fatigue loop needs the displacement at the maximum load after every step, with the bonds
broken so far; the linearised model (``peridyn.stiffness``) is adequate for fatigue strains.
Direct solves (SuperLU) suit small bodies; Jacobi-preconditioned conjugate gradients, warm
started from the previous step, suit large ones. A tiny diagonal shift (1e-9 of the mean
stiffness) keeps bodies held only by balanced forces, and points that lost every bond, solvable:
it changes the elastic response by about 1e-9 and leaves linear bond strains free of rigid motion.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import cg, spsolve

from peridyn.errors import InputError
from peridyn.loads import Loading
from peridyn.materials.base import Model
from peridyn.solvers.modal import free_dofs
from peridyn.stiffness import assemble_stiffness

#: Diagonal shift relative to the mean diagonal stiffness.
SHIFT = 1e-9
#: Free dofs above which ``method="auto"`` uses conjugate gradients.
DIRECT_LIMIT = 60_000


class LinearStatics:
    """Displacement (n_points, 3), m, of ``model`` under ``loading`` at time ``time`` (s).

    Parameters
    ----------
    method : "auto", "direct" or "cg"
    rtol : relative residual of the CG solve
    """

    def __init__(self, model: Model, loading: Loading, time: float = 1.0, method: str = "auto",
                 rtol: float = 1e-8):
        if method not in ("auto", "direct", "cg"):
            raise InputError(f"linear solver must be auto, direct or cg, got {method!r}")
        self.model, self.loading, self.time, self.rtol = model, loading, float(time), rtol
        n = model.body.n_points
        self.free = free_dofs(model, loading.constrained)
        self.method = method if method != "auto" else (
            "direct" if len(self.free) <= DIRECT_LIMIT else "cg")
        self.u_prescribed = np.zeros((n, 3))
        loading.apply_kinematics(self.time, 1.0, self.u_prescribed, np.zeros((n, 3)))
        force = loading.body_force_density(self.time, np.zeros((n, 3)))
        self.force = (force * model.body.volumes[:, None]).ravel()
        if not (np.any(self.u_prescribed) or np.any(self.force)):
            raise InputError(f"the loads at t = {self.time:g} s are all zero: a fatigue run needs a "
                             "cyclic load (non-zero displacement or force at the maximum load)")
        self._last = None

    def solve(self) -> np.ndarray:
        """Equilibrium displacement with the bonds intact now."""
        u = self.u_prescribed.ravel().copy()
        if len(self.free) == 0:
            return u.reshape(-1, 3)
        K = assemble_stiffness(self.model)
        rhs = (self.force - K @ u)[self.free]
        k_ff = K[self.free][:, self.free].tocsr()
        diag = k_ff.diagonal()
        k_ff = k_ff + sp.diags(np.full(len(diag), SHIFT * diag.mean()))
        if self.method == "direct":
            u[self.free] = spsolve(k_ff.tocsc(), rhs)
        else:
            precond = sp.diags(1.0 / k_ff.diagonal())
            x, info = cg(k_ff, rhs, x0=self._last, rtol=self.rtol, M=precond, maxiter=20 * len(rhs))
            if info != 0:
                raise InputError(f"fatigue static solve: CG did not converge ({info} iterations)")
            self._last = x
            u[self.free] = x
        return u.reshape(-1, 3)
