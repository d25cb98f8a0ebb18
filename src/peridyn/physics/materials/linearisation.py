"""The small-displacement form every material gives to stiffness, tangent and modal analysis.

Bond-based and ordinary state-based materials share one linear form. Bond i->j (reference
vector xi, length |xi|, unit vector n) carries a scalar force t_ij along n, and

    f_i = sum_j t_ij n_ij,                          N/m^3
    t_ij = axial_ij (P_i + P_j) + extension_ij e_ij,
    e_ij = n_ij . (u_j - u_i),                       m
    theta_i = theta_coef_i sum_j axial_ij e_ij,      axial_ij = weight_ij |xi_ij|
    P_i = p_coef_i theta_i,

summed over the intact bonds (``bonds.intact`` is read by every consumer at every use, so
broken bonds need no new linearisation). A bond-based material has no dilatation: its
``weight``, ``theta_coef``, ``p_coef`` and ``dilatation_energy`` are None and t_ij =
extension_ij e_ij.

The strain energy of point p (per volume) is, to second order,

    W_p = (1/4) sum_j pair_pj e_pj^2 + c_p theta_p^2,    c_p = ``dilatation_energy``,

so that ``linalg.stiffness`` assembles the Hessian of sum_p V_p W_p (any subset of the points
for ``energy_of``) as bond-pair blocks V_p pair_pj n n^T / 2 plus G^T diag(2 c V) G with
d theta_p / d e_pj = theta_coef_p weight_pj |xi_pj|. ``pair`` is attributed to the bond's
owner p, whereas ``extension`` is the whole bond's (both end points' energies): the
stiffness equals the linear force (K u = -V f_lin(u), checked by tests/invariants) when
extension_ij = (V_i pair_ij + V_j pair_ji) / (2 V_i) on every bond, V_i weight_ij = V_j weight_ji
and p_coef = 2 c theta_coef.

The nonlinear tangent (``linalg.tangent``) uses the same coefficients with the extension
r - |xi| of the deformed length r and the deformed bond direction: T = axial (P_i + P_j)
+ extension (r - |xi|), dT/dr = extension, plus the Jacobian of P when there is a
dilatation. This is exact for the force kernels of the materials shipped (PMB, LPS).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from peridyn.kernels.linear import bond_extension, lps_linear_force, scatter_along_bonds

#: The parts a material without dilatation (bond-based) leaves as None.
DILATATION_PARTS = ("weight", "theta_coef", "p_coef", "dilatation_energy")


@dataclass(frozen=True)
class BondLinearisation:
    """Coefficients of the linear form of the module docstring (all float64, read-only).

    Attributes
    ----------
    extension : (n_bonds,) N/m^4
        d t_ij / d e_ij: the bond's force per unit extension.
    pair : (n_bonds,) N/m^4
        Owner-attributed second derivative of the energy: point p's energy density holds
        pair_pj e_pj^2 / 4 for each of its bonds.
    weight : (n_bonds,) m^3 or None
        Influence weight w_ij (omega beta V_j); axial_ij = weight_ij |xi_ij|, m^4.
    theta_coef : (n_points,) 1/m^5 or None
        theta_i = theta_coef_i sum_j w_ij |xi_ij| e_ij (d / m_i for LPS).
    p_coef : (n_points,) Pa/m^5 or None
        P_i = p_coef_i theta_i.
    dilatation_energy : (n_points,) Pa or None
        c_p of the energy density term c_p theta_p^2.
    """

    extension: np.ndarray
    pair: np.ndarray
    weight: np.ndarray | None = None
    theta_coef: np.ndarray | None = None
    p_coef: np.ndarray | None = None
    dilatation_energy: np.ndarray | None = None

    def __post_init__(self):
        given = [getattr(self, name) is not None for name in DILATATION_PARTS]
        if any(given) and not all(given):
            missing = [name for name, g in zip(DILATATION_PARTS, given, strict=True) if not g]
            raise ValueError(
                f"a linearisation with a dilatation needs all of {DILATATION_PARTS}; missing {missing}"
            )
        for field in fields(self):
            value = getattr(self, field.name)
            if value is None:
                continue
            # a read-only float64 view: no copy where the material's array is float64 already
            array = np.asarray(value, dtype=np.float64).view()
            array.flags.writeable = False
            if array.ndim != 1:
                raise ValueError(
                    f"linearisation {field.name} must be one-dimensional, got shape {array.shape}"
                )
            object.__setattr__(self, field.name, array)
        per_bond = {"extension": self.extension, "pair": self.pair, "weight": self.weight}
        per_point = {
            "theta_coef": self.theta_coef,
            "p_coef": self.p_coef,
            "dilatation_energy": self.dilatation_energy,
        }
        for group in (per_bond, per_point):
            sizes = {name: len(a) for name, a in group.items() if a is not None}
            if len(set(sizes.values())) > 1:
                raise ValueError(f"linearisation arrays of one kind must have one length, got {sizes}")

    @property
    def has_dilatation(self) -> bool:
        """True for a state-based material whose bonds couple through a dilatation theta."""
        return self.weight is not None

    def force(self, points: np.ndarray, bonds, u: np.ndarray) -> np.ndarray:
        """Linear internal force density (n_points, 3), N/m^3, of ``u`` (n_points, 3), m, on the
        reference ``points`` (n_points, 3), m, and their ``bonds`` (``kernels.linear``)."""
        u = np.ascontiguousarray(u, dtype=np.float64)
        b = bonds
        if self.has_dilatation:  # the state-based kernel takes any material's dilatation coefficients
            return lps_linear_force(
                points,
                u,
                b.offsets,
                b.neighbours,
                b.length,
                self.weight,
                self.extension,
                b.intact,
                self.theta_coef,
                self.p_coef,
            )
        # bond-based: t = extension e, scattered along the bonds
        e = bond_extension(points, u, b.offsets, b.neighbours, b.length, b.intact, np.empty(b.n_bonds))
        t = self.extension * e
        return scatter_along_bonds(points, b.offsets, b.neighbours, b.length, t, np.empty_like(points))
