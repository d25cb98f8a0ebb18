"""Linear peridynamic solid (LPS), state-based (Silling, Epton, Weckner, Xu, Askari 2007).

3D: bulk modulus K and shear modulus mu from E and nu; 2D (Le, Silling and
Bobaru 2014 form): the in-plane bulk modulus kappa (E / (2 (1 - nu)) in plane
stress, lambda + mu in plane strain) and mu, with dilatation
theta = (2 / m) sum w |xi| e and deviatoric coefficient 8 mu / m.
In d dimensions the energy density of point i is

    W_i = kappa theta_i^2 / 2 + (alpha_i / 2) sum_j w_ij (e_ij - theta_i |xi| / d)^2,

alpha = 15 mu / m (3D), 8 mu / m (2D), w = omega beta V_j, m_i = sum_j w_ij |xi|^2 over
the intact bonds at set-up (each point's own family, so surfaces are seen).

With ``surface_correction: energy`` each point weights its own bonds in the deviatoric
part with factors g_ij (``peridyn.physics.materials.lps_correction``):

    W_i = kappa theta_i^2 / 2 + (alpha_i / 2) [ sum_j g_ij w_ij e_ij^2 - m~_i theta_i^2 / d^2 ],

m~_i = sum_j g_ij w_ij |xi|^2 (set-up); g = 1 gives the form above. Its force is
t_ij = w |xi| P_i + alpha_i g_ij w e_ij with P_i = theta_i p_coef_i,
p_coef = d kappa / m - alpha m~ / (d m): the force kernels read the per-bond deviatoric
stiffness ``dev`` = w (alpha_i g_ij + alpha_j g_ji) and p_coef, and stiffness, tangent, block
operator and Bloch cell get the same coefficients from ``LPSModel.linearisation()``
(``peridyn.physics.materials.linearisation``): extension = dev, weight = w, theta_coef = d / m,
p_coef, pair = 2 alpha_i g_ij w (point i's deviatoric energy) and the dilatation energy
coefficient c = kappa / 2 - alpha m~ / (2 d^2) of W_i = c theta_i^2 + (alpha_i / 2) sum_j g_ij w e^2.
"""

from __future__ import annotations

import warnings

import numba
import numpy as np

from peridyn.discretization.body import Body
from peridyn.discretization.bonds import Bonds, family_sums, fused_plan, fused_ring_columns
from peridyn.errors import InputError
from peridyn.kernels.lps import (
    lps_deviatoric_energy,
    lps_dilatation,
    lps_dilatation_cf,
    lps_force_fused,
    lps_pair_force,
    lps_pair_force_cf,
    lps_stiffness_bound,
)
from peridyn.kernels.peridigm import peridigm_lps_force
from peridyn.physics.materials.base import Model, ParameterError
from peridyn.physics.materials.elastic import (
    dilatational_modulus,
    shear_modulus,
)
from peridyn.physics.materials.linearisation import BondLinearisation
from peridyn.physics.materials.lps_correction import energy_factors
from peridyn.physics.materials.registry import register_material

#: ``shear-factor``: Peridigm's former "Apply Shear Correction Factor" (see ``LPSModel``).
SURFACE_CORRECTIONS = ("none", "shear-factor", "energy")

#: Rows a block of the fused float64 force (``kernels.lps.lps_force_fused``; 256 measured as
#: fast as 1024 and faster than 64 or 2048 on the Lamb plate case, benchmarks/HISTORY.md, "Stored
#: bond vectors, the fused LPS force, ...").
FUSED_BLOCK_ROWS = 256
#: The fused force is used when each thread's ring holds at most this many bonds (32 B each:
#: 8 MiB), i.e. when the point order's index bandwidth keeps a block's bonds in the cache
#: between its dilatation and its force (the Lamb plate case: 131 k; the 49^3 bench cube,
#: bandwidth 7203 rows: 850 k, where the two passes are used).
FUSED_RING_BONDS = 2**18


@register_material("lps")
class LPSModel(Model):
    """LPS material bound to a body and its bonds.

    Parameters
    ----------
    body, bonds : Body, Bonds
    E : float or (n_points,), Pa
    nu : float or (n_points,)
        Required (an LPS material has any Poisson ratio in (-1, 1/2)).
    density : float or (n_points,), kg/m^3
    surface_correction : {"none", "shear-factor", "energy"}
        ``shear-factor`` scales each point's deviatoric coefficient alpha by
        Peridigm's shear correction factor (see ``_shear_correction_factor``);
        ``energy`` sets per-bond deviatoric factors (module docstring).
    dtype : float64 or float32

    Per-point E, nu and density describe a body of several blocks (docs/blocks.md): each
    point's kappa, mu, alpha and P_i then come from its own block, and a bond's deviatoric
    stiffness w (alpha_i g_ij + alpha_j g_ji) sums its two ends' as it always does.

    Attributes (beyond ``Model``'s)
    -------------------------------
    alpha : (n,) Pa/m^5, theta_coef : (n,) 1/m^5, weighted_volume m : (n,) m^5
    dev_factor : (n_bonds,) g_ij of the owner's deviatoric part (1 unless ``energy``)
    dev_weighted_volume : (n,) m~, m^5
    dev : (n_bonds,) kernel dtype, w (alpha_i g_ij + alpha_j g_ji), the bond's deviatoric
        stiffness read by every force and stiffness routine
    """

    state_based = True
    surface_corrections = SURFACE_CORRECTIONS

    @classmethod
    def check_parameters(cls, *, E, density, nu=None, surface_correction="none"):
        """As ``Model.check_parameters``; nu is required (an LPS material has any Poisson ratio
        in (-1, 1/2))."""
        if nu is None:
            raise ParameterError("nu", "an LPS material needs Poisson's ratio nu")
        super().check_parameters(E=E, density=density, nu=nu, surface_correction=surface_correction)

    @classmethod
    def plane_wave_coefficients(cls, family, E, nu):
        """Pair ``2 alpha w``, dilatation ``(dim / m) w |xi|`` and ``kappa - alpha m / dim^2``
        (``Model.plane_wave_coefficients``): alpha = dim (dim + 2) mu / m (15 mu / m in 3D,
        8 mu / m in 2D, 3 mu / m in 1D), m = sum w |xi|^2, kappa the bulk modulus (3D), the
        in-plane one (2D) or E (1D: a bar of unit cross-section)."""
        length, w, dim = family.length, family.weight, family.dim
        m = float(np.sum(w * length**2))
        alpha = dim * (dim + 2) * shear_modulus(E, nu) / m
        kappa = dilatational_modulus(E, nu, dim, family.plane)
        return 2.0 * alpha * w, dim / m * w * length, kappa - alpha * m / dim**2

    @classmethod
    def family_stiffness_bound(cls, family, E, nu):
        """B = sum_j (4 alpha w_j + 2 K (d / m) w_j |xi_j| S) + 2 K S^2, S = (d / m) sum w |xi|
        (``Model.family_stiffness_bound``), with the largest mu and K over the materials and
        the neighbours' alpha, m and S equal to the point's own."""
        xi, w, dim = family.length, family.weight, family.dim
        mu = max(shear_modulus(e, n) for e, n in zip(E, nu, strict=True))
        bulk = max(dilatational_modulus(e, n, dim, family.plane) for e, n in zip(E, nu, strict=True))
        m = np.sum(w * xi**2)
        alpha = (15.0 if dim == 3 else 8.0) * mu / m
        s = dim / m * np.sum(w * xi)
        return float(np.sum(4.0 * alpha * w + 2.0 * bulk * (dim / m) * w * xi * s) + 2.0 * bulk * s**2)

    def __init__(
        self,
        body: Body,
        bonds: Bonds,
        E: float,
        nu: float | None,
        density: float,
        surface_correction: str = "none",
        dtype=np.float64,
    ):
        self.check_parameters(E=E, density=density, nu=nu, surface_correction=surface_correction)
        super().__init__(body, bonds, E=E, density=density, dtype=dtype)
        dim = body.dim
        self.nu, self.dim = (float(nu) if np.ndim(nu) == 0 else np.asarray(nu, dtype=float)), dim
        self.shear = shear_modulus(E, nu)
        self.bulk = dilatational_modulus(E, nu, dim, body.plane)
        b = bonds
        w = b.influence * self.bond_volume
        self.weighted_volume = family_sums(b.offsets, np.where(b.intact, w * b.length**2, 0.0))
        # a point without any bond (``discretization.points_without_bonds: warn``) has no force
        # and no dilatation: its coefficients are 0 (divided by m = 1 and zeroed); one whose
        # bonds are all cut has no weighted volume to divide by: refused
        alone = np.diff(b.offsets) == 0
        cut = (self.weighted_volume <= 0) & ~alone
        if np.any(cut):
            raise InputError(
                f"point {int(np.flatnonzero(cut)[0])} has no intact bond: its weighted volume is zero"
            )
        m = np.where(alone, 1.0, self.weighted_volume)
        self.alpha = np.where(alone, 0.0, (15.0 if dim == 3 else 8.0) * self.shear / m)
        self.theta_coef = np.where(alone, 0.0, dim / m)
        self.shear_factor = np.ones(body.n_points)
        if surface_correction == "shear-factor":
            self.shear_factor = self._shear_correction_factor(w)
            self.alpha = self.alpha * self.shear_factor
        self.dev_factor = np.ones(b.n_bonds)
        if surface_correction == "energy":
            owners = b.owners()
            n_vec = (body.points[b.neighbours] - body.points[owners]) / b.length[:, None]
            self.dev_factor = energy_factors(
                owners,
                n_vec,
                b.length,
                np.where(b.intact, w, 0.0),
                self.alpha,
                self.shear,
                dim,
                body.n_points,
            )
            negative = int(np.count_nonzero(self.dev_factor[b.intact] <= 0.0))
            if negative:
                warnings.warn(
                    f"LPS energy surface correction: {negative} bonds need a negative deviatoric "
                    "weight (the horizon reaches across most of the body); the energy may lose "
                    "positivity: use a smaller horizon or another surface_correction",
                    stacklevel=2,
                )
        # m~_i = sum_j g_ij w |xi|^2, m^5, and alpha_i g_ij; without the energy correction g = 1:
        # m~ is m and alpha_i g_ij is alpha_i bit for bit (products by 1), not formed again
        point_dev = self.alpha[b.owners()]
        self.dev_weighted_volume = m
        if surface_correction == "energy":
            self.dev_weighted_volume = family_sums(
                b.offsets, np.where(b.intact, self.dev_factor * w * b.length**2, 0.0)
            )
            point_dev = point_dev * self.dev_factor
        # k_ij = w (alpha_i g_ij + alpha_j g_ji), the bond's deviatoric stiffness (both energies)
        self.dev = (w * (point_dev + point_dev[b.reverse()])).astype(self.dtype)
        self.length = b.length.astype(self.dtype, copy=False)  # float64: the bonds' own array
        self.w = w.astype(self.dtype)
        self._theta_coef = self.theta_coef.astype(self.dtype)
        # P_i = theta_i * p_coef_i, see peridyn.kernels.lps
        self._p_coef = (dim * self.bulk / m - self.alpha * self.dev_weighted_volume / (dim * m)).astype(
            self.dtype
        )
        self._theta = np.zeros(body.n_points, dtype=self.dtype)
        self._p = np.zeros(body.n_points, dtype=self.dtype)
        self._rows_read_cache: dict[int, int] = {}
        self._fused_cache: dict = {}
        self._peridigm_p = None  # Peridigm's p of force_from_positions, made on its first call

    def _shear_correction_factor(self, w: np.ndarray) -> np.ndarray:
        """Peridigm's shear correction factor (``shear_correction_factor``) over the bonds."""
        body, b = self.body, self.bonds
        x, xi = body.points, self.bond_vectors_once()
        n = body.n_points
        family = (b.offsets, b.neighbours, b.length, w, b.intact)

        def dilatation(u):
            return lps_dilatation(xi, u, *family, self.theta_coef, np.empty(n))

        def deviatoric_norm(u, theta):
            return lps_deviatoric_energy(x, u, *family, theta, float(self.dim), np.empty(n))

        return shear_correction_factor(x, self.dim, self.weighted_volume, dilatation, deviatoric_norm)

    def _dilatation(self, u: np.ndarray, first: int = 0, stop: int = -1) -> np.ndarray:
        """theta into the rows ``first .. stop - 1`` (``stop`` < 0: to the last row) of
        ``self._theta``; ``u`` already in the kernel dtype and layout."""
        b = self.bonds
        if self.dtype == np.float32:
            args = (self.x, u, b.offsets, b.neighbours, self.w, b.intact, self._theta_coef, self._theta)
            return lps_dilatation_cf(*args, first, stop)
        return lps_dilatation(
            self.bond_vectors,
            u,
            b.offsets,
            b.neighbours,
            self.length,
            self.w,
            b.intact,
            self._theta_coef,
            self._theta,
            first,
            stop,
        )

    def _pair_force(self, u: np.ndarray, out: np.ndarray, first: int = 0, stop: int = -1) -> np.ndarray:
        """The pair-force kernel of the dtype, from ``self._p``, into the rows ``first .. stop - 1``
        of ``out``."""
        b = self.bonds
        p = self._p
        if self.dtype == np.float32:
            args = (self.x, u, b.offsets, b.neighbours, self.w, self.dev, b.intact, p, out)
            return lps_pair_force_cf(*args, first, stop)
        args = (self.bond_vectors, u, b.offsets, b.neighbours, self.length, self.w, self.dev, b.intact)
        return lps_pair_force(*args, p, out, first, stop)

    def dilatation(self, u) -> np.ndarray:
        """Dilatation theta (n_points,), dimensionless."""
        return self._dilatation(self._as_state(u)).copy()

    def force(self, u, out=None):
        """Internal force density (see ``Model.force``): two passes over the bonds, or in float64
        where :meth:`_fused` allows, the fused kernel (the same bits, one go).

        float64 uses the stored ``length``; float32 the cancellation-free kernels, which
        recompute |xi| from ``x`` (see ``peridyn.kernels``). Both read ``bonds.intact``
        on every call, so broken bonds need no notification.
        """
        out = np.empty_like(self.x) if out is None else out
        u = self._as_state(u)
        n = self.body.n_points
        if self._fused(n) is None:
            np.multiply(self._dilatation(u), self._p_coef, out=self._p)
            return self._pair_force(u, out)
        return self._force_fused(u, n, out)

    def force_from_positions(self, y, out):
        """See ``Model.force_from_positions``: ``kernels.peridigm.peridigm_lps_force`` with this
        model's weighted volumes and alpha (shear correction included) and Peridigm's
        p = 3 K / m - alpha / 3 of the dilatation term. 3D float64 bodies without partial
        volumes nor the energy surface correction (Peridigm has neither); the dilatation it
        forms is kept in ``self._theta``."""
        if self._peridigm_p is None:
            if self.dim != 3 or self.dtype != np.float64:
                raise InputError("solver.arithmetic: peridigm takes a 3D float64 LPS body (Peridigm's)")
            if np.any(self.bonds.volume_factor != 1.0) or np.any(self.dev_factor != 1.0):
                raise InputError(
                    "solver.arithmetic: peridigm takes an LPS body without partial volumes and "
                    "without the energy surface correction (Peridigm's force has neither)"
                )
            m, bulk = self.weighted_volume, np.broadcast_to(self.bulk, (self.body.n_points,))
            alone = m == 0.0  # a point without bonds: p is never read
            self._peridigm_p = np.where(alone, 0.0, 3.0 * bulk / np.where(alone, 1.0, m) - self.alpha / 3.0)
        b = self.bonds
        peridigm_lps_force(
            self.x,
            np.ascontiguousarray(y, dtype=np.float64),
            b.offsets,
            b.neighbours,
            self.body.volumes,
            b.influence,
            b.intact,
            self.weighted_volume,
            np.ascontiguousarray(np.broadcast_to(self.alpha, (self.body.n_points,))),
            self._peridigm_p,
            self._theta,
            out,
        )
        return out

    def _force_fused(self, u: np.ndarray, rows: int, out: np.ndarray) -> np.ndarray:
        """The fused kernel's theta, p and force of the first ``rows`` rows (where :meth:`_fused`
        has a plan), whose neighbours' theta and p are among them or already in ``self._theta``,
        ``self._p``; the other rows of ``out`` are not written."""
        b = self.bonds
        plan, ring = self._fused(rows)
        args = (self.bond_vectors, u, b.offsets, b.neighbours, self.length, self.w, self.dev, b.intact)
        return lps_force_fused(*args, self._theta_coef, self._p_coef, *plan, ring, self._theta, self._p, out)

    def _fused(self, rows: int):
        """(``FusedPlan``, ring (n_threads, 4, columns) float64) of ``kernels.lps.lps_force_fused``
        over the first ``rows`` rows, for numba's present number of threads, made once per
        number and ``rows``; None where the two passes are used instead: float32, no rows, or a
        ring above ``FUSED_RING_BONDS``."""
        threads = numba.get_num_threads()
        if self.dtype != np.float64 or rows == 0:
            return None
        key = (threads, rows)
        if key not in self._fused_cache:
            offsets = self.bonds.offsets[: rows + 1]
            plan = fused_plan(offsets, self.bonds.neighbours[: offsets[-1]], threads, FUSED_BLOCK_ROWS)
            columns = fused_ring_columns(offsets, plan)
            ring = np.empty((threads, 4, columns)) if columns <= FUSED_RING_BONDS else None
            self._fused_cache[key] = None if ring is None else (plan, ring)
        return self._fused_cache[key]

    def force_overlapped(self, u, out, clear_rows, n_owned, finish):
        """See ``Model.force_overlapped``. The dilatation of the first ``clear_rows[0]`` rows
        and the force of the first ``clear_rows[1]`` (whose neighbours are all among the
        former) need no ghost value; after ``finish()`` the dilatation of the other rows that
        an owned row's force reads (its neighbours', layer-1 ghosts included: ``_rows_read``)
        and the other owned rows' force."""
        clear, clear_force = clear_rows[0], clear_rows[1]
        theta, p, p_coef = self._theta, self._p, self._p_coef
        state = self._as_state(u)
        # with the fused force of rows 0 .. clear_force - 1, the dilatation of the rows after
        # them that they read comes first; else that of all rows 0 .. clear - 1
        fused = self._fused(clear_force) is not None
        first = clear_force if fused else 0
        self._dilatation(state, first, clear)
        np.multiply(theta[first:clear], p_coef[first:clear], out=p[first:clear])
        if fused:
            self._force_fused(state, clear_force, out)
        else:
            self._pair_force(state, out, 0, clear_force)
        finish()
        state = self._refresh_ghosts(state, u, n_owned)
        read = self._rows_read(n_owned)  # the ghosts after it (layer 2) are read by no owned row
        self._dilatation(state, clear, read)
        np.multiply(theta[clear:read], p_coef[clear:read], out=p[clear:read])
        self._pair_force(state, out, clear_force, n_owned)
        out[n_owned:] = 0.0
        return out

    def _rows_read(self, n_owned: int) -> int:
        """1 + the last row that a family of the rows ``0 .. n_owned - 1`` holds (at least
        ``n_owned``): the rows whose dilatation their forces read end there."""
        if n_owned not in self._rows_read_cache:
            held = self.bonds.neighbours[: self.bonds.offsets[n_owned]]
            self._rows_read_cache[n_owned] = max(n_owned, int(held.max()) + 1 if len(held) else 0)
        return self._rows_read_cache[n_owned]

    def energy_density(self, u):
        b = self.bonds
        u64 = np.ascontiguousarray(u, dtype=np.float64)
        x64 = self.body.points
        w64 = self.w.astype(np.float64)
        theta = lps_dilatation(
            self.bond_vectors_once(),
            u64,
            b.offsets,
            b.neighbours,
            b.length,
            w64,
            b.intact,
            self.theta_coef,
            np.empty(self.body.n_points),
        )
        # sum_j g w e^2 (the kernel with theta = 0), then the m~ theta^2 / d^2 of the energy
        squares = lps_deviatoric_energy(
            x64,
            u64,
            b.offsets,
            b.neighbours,
            b.length,
            w64 * self.dev_factor,
            b.intact,
            np.zeros_like(theta),
            float(self.dim),
            np.empty(self.body.n_points),
        )
        dev = squares - self.dev_weighted_volume * theta**2 / self.dim**2
        return 0.5 * self.bulk * theta**2 + 0.5 * self.alpha * dev

    def _linearise(self):
        """State-based: the coefficients of the module docstring, in float64 from the kernel
        dtype's ``w``, ``dev`` and p_coef (the linear form of the kernels' numbers)."""
        b = self.bonds
        w = np.asarray(self.w, dtype=np.float64)  # no copy in float64
        d = self.dim
        return BondLinearisation(
            extension=np.asarray(self.dev, dtype=np.float64),
            pair=2.0 * self.alpha[b.owners()] * self.dev_factor * w,
            weight=w,
            theta_coef=self.theta_coef,
            p_coef=np.asarray(self._p_coef, dtype=np.float64),
            dilatation_energy=0.5 * self.bulk - self.alpha * self.dev_weighted_volume / (2 * d * d),
        )

    def stiffness_bound(self):
        """Block-Gershgorin bound of the LPS stiffness (see ``Model.stiffness_bound``).

        The energy is bounded above by dropping the -theta |xi| / d part of the
        deviatoric extension; the bound's Hessian has bond blocks of norm
        w (alpha_i + alpha_j) and, for each point k's dilatation, rank-one
        blocks kappa V_k g_k g_k^T with |g_k,j| = (d / m_k) w |xi| and
        sum_j |g_k,j| <= 2 S_k, S_k = (d / m_k) sum_j w |xi|.
        """
        b, n = self.bonds, self.body.n_points
        bulk = np.ascontiguousarray(np.broadcast_to(self.bulk, (n,)), dtype=np.float64)
        w = b.influence * self.bond_volume
        args = (b.offsets, b.neighbours, b.intact, w, b.length, self.dev, bulk, self.theta_coef)
        return lps_stiffness_bound(*args, np.empty(n), np.empty(n))

    def critical_stretch(self, fracture_energy):
        """s_c from G_c for LPS with a constant influence function (Madenci and Oterkus 2014).

        3D: s_c = sqrt(G / ((3 mu + (3/4)^4 (K - 5 mu / 3)) delta));
        2D: s_c = sqrt(G / ((6 mu / pi + 16 / (9 pi^2) (kappa - 2 mu)) delta)).
        Per point, (n_points,), from each point's own mu and kappa in a body of several blocks.
        """
        delta, mu, k = self.bonds.horizons(), self.shear, self.bulk
        if self.dim == 3:
            denom = (3.0 * mu + (0.75**4) * (k - 5.0 * mu / 3.0)) * delta
        else:
            denom = (6.0 * mu / np.pi + 16.0 / (9.0 * np.pi**2) * (k - 2.0 * mu)) * delta
        s_c = np.sqrt(fracture_energy / denom)
        return float(s_c) if np.ndim(s_c) == 0 else s_c


def shear_correction_factor(points, dim: int, weighted_volume, dilatation, deviatoric_norm) -> np.ndarray:
    """Shear correction factor (Peridigm's former "Apply Shear Correction Factor"), (n_points,).

    For the pure shears of amplitude gamma in the planes xy, xz, yz (xy only in 2D),
    u_a = gamma x_b, u_b = gamma x_a, each point's deviatoric norm
    S = sum_j w (e - theta |xi| / d)^2 is compared with its bulk value
    S_bulk = 4 gamma^2 m / 15 (3D; 4 gamma^2 m / 8 in 2D), and alpha is
    multiplied by S_bulk / max(S): the point's stiffest pure-shear response is
    brought to the bulk value. This reproduces the independent assembly of
    VALIDATION.md V4 to all printed digits (40 000 points, 1.4143 h).

    ``points`` (n_points, 3) m; ``weighted_volume`` m (n_points,) m^5; ``dilatation(u)`` the
    points' theta at u (n_points, 3) m and ``deviatoric_norm(u, theta)`` their S, m^5, over
    the storage of the bonds (bond lists or a lattice).
    """
    gamma = 1e-6
    planes = [(0, 1), (0, 2), (1, 2)] if dim == 3 else [(0, 1)]
    largest = np.zeros(len(points))
    for a, c in planes:
        u = np.zeros_like(points)
        u[:, a] = gamma * points[:, c]
        u[:, c] = gamma * points[:, a]
        largest = np.maximum(largest, deviatoric_norm(u, dilatation(u)))
    bulk = 4.0 * gamma**2 * weighted_volume / (15.0 if dim == 3 else 8.0)
    return bulk / largest
