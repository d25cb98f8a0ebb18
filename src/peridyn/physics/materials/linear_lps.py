"""Linear LPS (``linear_lps``): the LPS material linearised about the reference configuration,
Peridigm's "Linear LPS" (small displacements).

Its law is the linear form of ``LPSModel`` (``peridyn.physics.materials.linearisation``), with
the same coefficients, so stiffness, tangent, modal analysis and the stable step are LPS's.
With n = xi / |xi| and e_ij = n . (u_j - u_i) (m) the linearised extension,

    theta_i = (d / m_i) sum_j w_ij |xi_ij| e_ij,
    f_i = sum_j [w_ij |xi_ij| (P_i + P_j) + dev_ij e_ij] n_ij,    P_i = p_coef_i theta_i,
    W_i = (1/4) sum_j pair_ij e_ij^2 + c_i theta_i^2,

over the intact bonds (``kernels.linear``). In 3D without a surface correction this is
Peridigm's ``LinearLPSPVMaterial``: t = (3 K - 5 mu) omega theta / m xi + 15 mu omega / (m
|xi|^2) (xi (x) xi) eta from each end. It is exactly linear, f(a u) = a f(u), and equals LPS
to O(u^2). Bonds break as for any material (critical stretch of the deformed length, as
Peridigm's damage models do): a broken bond leaves theta and f at once.
"""

from __future__ import annotations

import numpy as np

from peridyn.kernels.linear import bond_extension
from peridyn.physics.materials.lps import LPSModel
from peridyn.physics.materials.registry import register_material


@register_material("linear_lps")
class LinearLPSModel(LPSModel):
    """LPS linearised about the reference configuration (module docstring); constructed as
    ``LPSModel`` (E, nu, density, surface correction). Forces and energies are computed in
    float64 whatever ``dtype``."""

    is_linear = True

    def _extension_and_dilatation(self, u) -> tuple[np.ndarray, np.ndarray]:
        """Linearised extension e (n_bonds,), m, and dilatation theta (n_points,) of u."""
        b, lin = self.bonds, self.linearisation()
        u64 = np.ascontiguousarray(u, dtype=np.float64)
        e = bond_extension(
            self.body.points, u64, b.offsets, b.neighbours, b.length, b.intact, np.empty(b.n_bonds)
        )
        owners = b.owners()
        theta = lin.theta_coef * np.bincount(owners, lin.weight * b.length * e, minlength=self.body.n_points)
        return e, theta

    def dilatation(self, u) -> np.ndarray:
        """Linearised dilatation theta (n_points,), dimensionless."""
        return self._extension_and_dilatation(u)[1]

    def force(self, u, out=None):
        """Linear force density (n_points, 3), N/m^3 (``BondLinearisation.force``)."""
        f = self.linearisation().force(self.body.points, self.bonds, u)
        if out is None:
            return f.astype(self.dtype, copy=False)
        out[:] = f
        return out

    def partial_stress(self, u):
        """Partial stress (n_points, 3, 3), Pa: sigma_i = sum_j t_ij n_ij (x) xi_ij over the
        intact bonds with the linear force state t_ij = w_ij |xi_ij| P_i + (pair_ij / 2) e_ij
        along the reference direction n (the derivative of W_i; ``Model.partial_stress``
        takes the deformed direction of the nonlinear law)."""
        b, lin = self.bonds, self.linearisation()
        e, theta = self._extension_and_dilatation(u)
        owners = b.owners()
        t = np.where(b.intact, lin.weight * b.length * (lin.p_coef * theta)[owners] + 0.5 * lin.pair * e, 0.0)
        xi = self.body.points[b.neighbours] - self.body.points[owners]
        sigma = np.zeros((self.body.n_points, 3, 3))
        np.add.at(sigma, owners, (t / b.length)[:, None, None] * xi[:, :, None] * xi[:, None, :])
        return sigma

    def energy_density(self, u):
        """Quadratic energy density (n_points,), J/m^3: W_i of the module docstring."""
        lin = self.linearisation()
        e, theta = self._extension_and_dilatation(u)
        owners = self.bonds.owners()
        pairs = np.bincount(owners, lin.pair * e * e, minlength=self.body.n_points)
        return 0.25 * pairs + lin.dilatation_energy * theta**2
