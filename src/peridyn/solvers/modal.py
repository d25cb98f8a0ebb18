"""Free vibration: K x = lambda M x, f = sqrt(lambda) / (2 pi).

Shift-invert Lanczos (``scipy.sparse.linalg.eigsh``) with a negative shift
``sigma = -s`` so that ``K + s M`` is positive definite even for a free body
(whose K is singular), factorised once with a sparse LU. For LPS, K = P + G^T D G
(``stiffness.StiffnessParts``) reaches two horizons, but the augmented system

    [ P + s M    G^T   ] [x]   [b]
    [    G     -D^-1   ] [y] = [0]      (y = D G x)

is as sparse as the bonds and gives (K + s M) x = b; it is quasi-definite (D > 0 on
usual materials), so a symmetric fill-reducing order (geometric nested dissection,
``linalg.ordering``) with little pivoting factorises it
at a fraction of the memory and time of K itself (D < 0, as for a 2D plane-stress LPS
with nu < 1/3, only needs more pivoting). Rigid-body modes
(six for a free 3D body, three in 2D) come out with ``|f|`` near zero and are
counted and reported separately.

Where the factor would be too large (wide horizons, large bodies; the choice is
``setup.eigensolver.choose_eigensolver``), ``method="lobpcg"`` finds the same modes without
factorising anything (``solvers.eigen_iterative``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import eigsh

from peridyn.errors import InputError
from peridyn.linalg.dofs import free_dofs
from peridyn.linalg.shift_invert import shifted_inverse
from peridyn.linalg.stiffness import mass_matrix, stiffness_parts
from peridyn.physics.materials.base import Model

#: Modes whose frequency is below this fraction of the highest computed one are rigid.
RIGID_FRACTION = 1e-4


@dataclass
class ModalResult:
    """Eigenpairs of a body.

    Attributes
    ----------
    frequencies : (n_modes,) float64, Hz
        Signed: sqrt(lambda) / 2 pi, negative when lambda < 0 (round-off of rigid modes).
    shapes : (n_modes, n_points, 3) float64
        Mass-normalised mode shapes (x^T M x = 1).
    residuals : (n_modes,) float64
        ||K x - lambda M x|| / ||K x|| (rigid modes: / (max K_ii ||x||)).
    rigid : (n_modes,) bool
        Rigid-body modes.
    """

    frequencies: np.ndarray
    shapes: np.ndarray
    residuals: np.ndarray
    rigid: np.ndarray

    @property
    def n_rigid(self) -> int:
        """Number of rigid-body modes found."""
        return int(self.rigid.sum())

    def elastic(self) -> ModalResult:
        """The elastic modes only."""
        keep = ~self.rigid
        return ModalResult(self.frequencies[keep], self.shapes[keep], self.residuals[keep], self.rigid[keep])


#: Eigensolvers of ``modal_analysis``.
EIGENSOLVERS = ("shift-invert", "lobpcg")


def modal_analysis(
    model: Model,
    n_modes: int = 12,
    fixed: np.ndarray | None = None,
    shift: float | None = None,
    tol: float = 1e-10,
    method: str = "shift-invert",
) -> ModalResult:
    """The ``n_modes`` lowest modes of ``model`` (free-free unless ``fixed`` dofs are given).

    Parameters
    ----------
    n_modes : int
        Number of modes, rigid ones included.
    fixed : (n_points, 3) bool or None
        Dofs held at zero.
    shift : float or None, 1/s^2
        Shift-invert only: magnitude s of the negative shift; default: 1e-3 of the largest
        K_ii / M_ii estimate scaled to the low end of the spectrum (see code).
    method : {"shift-invert", "lobpcg"}
        ``shift-invert``: Lanczos on the factorised K + s M (this module);
        ``lobpcg``: matrix-free and preconditioned, no factor (``solvers.eigen_iterative``),
        the rigid modes are the exact rigid motions.
    """
    if n_modes < 1:
        raise InputError(f"number of modes must be positive, got {n_modes}")
    if method not in EIGENSOLVERS:
        raise InputError(f"eigensolver must be one of {EIGENSOLVERS}, got {method!r}")
    dofs = free_dofs(model, fixed)
    if n_modes >= len(dofs):
        raise InputError(f"asked for {n_modes} modes of a model with {len(dofs)} free dofs")
    m = mass_matrix(model).diagonal()[dofs]
    if method == "lobpcg":
        from peridyn.solvers.eigen_iterative import lobpcg_modes

        lam, vecs, n_rigid, K = lobpcg_modes(model, n_modes, dofs)
        # Gershgorin: the row sums bound every diagonal entry of K
        k_max = float(np.max(model.stiffness_bound() * model.body.volumes))
        known_rigid = np.arange(n_modes) < n_rigid
        return _result(lam, vecs, K, m, dofs, model.body.n_points, k_max, known_rigid)
    parts = stiffness_parts(model)
    K = parts.restricted(dofs)
    M = sp.diags(m).tocsc()
    if shift is None:
        # a fraction of the lowest diagonal frequency estimate keeps K + s M well conditioned
        shift = 1e-6 * float(np.median(parts.diagonal()[dofs] / m))
    op = shifted_inverse(parts, dofs, shift * m, model.body.points, model.bonds.horizon)
    # a fixed start vector: the same modes, residuals and shapes on every run (ARPACK's default is random)
    v0 = np.random.default_rng(0).standard_normal(len(dofs))
    lam, vecs = eigsh(K, k=n_modes, M=M, sigma=-shift, which="LM", OPinv=op, tol=tol, v0=v0)
    k_max = float(np.abs(parts.diagonal()[dofs]).max())
    return _result(lam, vecs, K, m, dofs, model.body.n_points, k_max, np.zeros(n_modes, bool))


def _result(lam, vecs, K, m, dofs, n_points, k_max, known_rigid) -> ModalResult:
    """ModalResult from eigenpairs on the ``dofs`` (any order): frequencies, residuals and the
    rigid modes (``known_rigid``, and those below RIGID_FRACTION of the highest frequency)."""
    order = np.argsort(lam)
    lam, vecs, known_rigid = lam[order], vecs[:, order], known_rigid[order]
    kx = K @ vecs
    mx = m[:, None] * vecs
    resid = np.linalg.norm(kx - mx * lam, axis=0)
    shapes = np.zeros((len(lam), n_points * 3))
    shapes[:, dofs] = vecs.T
    return classify_result(
        lam,
        shapes.reshape(len(lam), -1, 3),
        resid,
        k_max * np.linalg.norm(vecs, axis=0),
        np.linalg.norm(kx, axis=0),
        known_rigid,
    )


def classify_result(lam, shapes, resid, scale_rigid, scale_elastic, known_rigid) -> ModalResult:
    """ModalResult of sorted eigenpairs: ``lam`` (n_modes,) 1/s^2, ``shapes`` (n_modes,
    n_points, 3), the residual norms ||K x - lambda M x|| ``resid`` (n_modes,) N, and the
    scales they are relative to, (n_modes,) N: ``scale_elastic`` ||K x||, ``scale_rigid``
    max K_ii ||x|| (K x ~ 0 for a rigid mode). Rigid modes: ``known_rigid`` and those below
    RIGID_FRACTION of the highest frequency."""
    freqs = np.sign(lam) * np.sqrt(np.abs(lam)) / (2 * np.pi)
    rigid = known_rigid | (np.abs(freqs) < RIGID_FRACTION * np.abs(freqs).max())
    scale = np.where(rigid, scale_rigid, scale_elastic)
    return ModalResult(freqs, shapes, resid / np.maximum(scale, 1e-300), rigid)
