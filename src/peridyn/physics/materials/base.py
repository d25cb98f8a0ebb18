"""What every material model bound to a discretisation provides: the one interface through
which solvers, stiffness assembly, modal analysis, fatigue, damage and contact use a material.

A material is one class deriving from :class:`Model`, registered under its case-file name
with ``peridyn.physics.materials.registry.register_material``. It implements

- :meth:`Model.force` and :meth:`Model.energy_density` (the nonlinear law, explicit and
  static solvers, energies),
- :meth:`Model.stiffness_bound` (stable time step, preconditioner scale),
- :meth:`Model.critical_stretch` (damage from a fracture energy),
- :meth:`Model._linearise`, returning the :class:`BondLinearisation` of its small-displacement
  form (``peridyn.physics.materials.linearisation``): everything ``linalg.stiffness``,
  ``linalg.block_operator``, ``linalg.tangent``, the modal solvers and fatigue statics need;
- :meth:`Model.partial_stress` (the per-point stress of the output), whose default is built
  from the linearisation and is exact for every ordinary state-based or bond-based law
  (PMB, LPS); a material of another form overrides it;

and, if its constructor does not take the case parameters as keywords, :meth:`from_parameters`.
What is asked of the class before any body exists (a case being validated, estimated or
analysed) it answers as class methods and attributes: :meth:`Model.check_parameters` (the case
file's material keys), :attr:`Model.state_based`, :attr:`Model.bond_bytes` (the memory
estimate), :meth:`Model.implied_poisson_ratio`,
:meth:`Model.plane_wave_coefficients` (its linearisation on the family of one lattice point:
dispersion) and :meth:`Model.family_stiffness_bound` (the continuum stable step).
Code outside this package asks the model only through these methods and the attributes
documented on :class:`Model`; it never tests for a concrete material class
(``tests/unit/test_architecture.py``).
"""

from __future__ import annotations

import numpy as np

from peridyn.discretization.body import Body
from peridyn.discretization.bonds import Bonds
from peridyn.errors import InputError
from peridyn.kernels.bond_search import initial_bond_vectors
from peridyn.kernels.damage import damage_index
from peridyn.kernels.lps import lps_dilatation
from peridyn.kernels.stress import partial_stress
from peridyn.physics.materials.elastic import check_elastic
from peridyn.physics.materials.family import PointFamily
from peridyn.physics.materials.linearisation import BondLinearisation


class ParameterError(InputError):
    """A material parameter the material cannot take; ``key`` names it (``nu``,
    ``surface_correction``, ...), as the case file's ``material`` section spells it."""

    def __init__(self, key: str, message: str):
        self.key = key
        super().__init__(message)


class Model:
    """A material law over the bonds of one body (abstract).

    Subclasses set their per-bond and per-point coefficient arrays in their constructor and
    implement :meth:`force`, :meth:`energy_density`, :meth:`stiffness_bound`,
    :meth:`critical_stretch` and :meth:`_linearise`.

    Attributes
    ----------
    name : str
        The case-file name the class is registered under (``material.model``).
    is_linear : bool
        True when the force is linear in u (its tangent is its stiffness at rest).
    body : Body
    bonds : Bonds
        ``bonds.intact`` is shared and updated in place when bonds break.
    E : float or (n_points,) float64, Pa
        Young's modulus (damage's critical bond stress, contact's short-range constant); per
        point in a body of several blocks (docs/blocks.md).
    dtype : numpy dtype
        Floating type of the kernels (float64 or float32).
    x : (n_points, 3) dtype, m
        Reference positions in the kernel dtype.
    density : (n_points,) float64, kg/m^3
    bond_volume : (n_bonds,) float64, m^3
        Neighbour volume times the bond's partial-volume factor.
    """

    name = "model"
    # a material whose force is linear in u (linear_lps) sets it: its tangent stiffness is the
    # same at every state (linalg.tangent takes it at rest)
    is_linear = False
    #: True when points couple through a dilatation (a state-based law): the stiffness then
    #: reaches two horizons and a factorisation carries one more unknown per point (asked of
    #: the class; a bound model answers :attr:`has_dilatation` from its linearisation).
    state_based = False
    #: Bytes per directed bond of the model's own arrays in float64 (the memory estimate of a
    #: case, ``setup.estimate``): PMB 1/length, stiffness and surface factor; LPS weight,
    #: deviatoric coefficient and the shear factor's share.
    bond_bytes = 24.0
    #: True when ``force(u, out)`` writes every row of ``out`` whatever it held.
    force_overwrites_out = False
    #: The ``surface_correction`` names the material takes (case key ``material.surface_correction``).
    surface_corrections: tuple[str, ...] = ("none",)

    def __init__(self, body: Body, bonds: Bonds, E, density, dtype=np.float64):
        self.body = body
        self.bonds = bonds
        self.E = float(E) if np.ndim(E) == 0 else per_point(E, body.n_points, "E")
        self.dtype = np.dtype(dtype)
        self.x = np.ascontiguousarray(body.points, dtype=self.dtype)
        n = body.n_points
        self.density = (
            np.full(n, float(density)) if np.ndim(density) == 0 else per_point(density, n, "density")
        )
        self.neighbours = bonds.neighbours
        self.offsets = bonds.offsets
        # neighbour volume times its volume factor, (n_bonds,) m^3
        self.bond_volume = body.volumes[bonds.neighbours] * bonds.volume_factor
        self._linearisation: BondLinearisation | None = None
        self._bond_vectors: np.ndarray | None = None

    @classmethod
    def from_parameters(
        cls,
        body: Body,
        bonds: Bonds,
        *,
        E,
        density,
        nu=None,
        surface_correction: str = "none",
        dtype=np.float64,
    ) -> Model:
        """The material bound to ``body`` and ``bonds`` from the case's material parameters.

        E (Pa), density (kg/m^3), Poisson's ratio ``nu`` (None: not given), the name of a
        ``surface_correction`` and the kernel ``dtype``; each material checks them and raises
        ``InputError`` for values it cannot take. E, density and nu are numbers, or (n_points,)
        arrays for a body of several blocks (``peridyn.physics.materials.blocks``). By default
        the constructor takes them as keywords.
        """
        return cls(
            body, bonds, E=E, density=density, nu=nu, surface_correction=surface_correction, dtype=dtype
        )

    @classmethod
    def check_parameters(cls, *, E, density, nu=None, surface_correction: str = "none") -> None:
        """Refuse case parameters the material cannot take whatever the body: E (Pa) and density
        (kg/m^3) positive, nu (None: not given) in (-1, 1/2) (``elastic.check_elastic``), a
        surface correction among :attr:`surface_corrections`. Asked when a case file is
        validated (``io.case``); a material with other needs (nu required, ...) extends it.

        Raises
        ------
        InputError
            Naming the parameter and what it must be (a :class:`ParameterError`, with the
            parameter's ``key``, for what the case file's schema alone does not refuse).
        """
        check_elastic(E, nu, density)
        if surface_correction not in cls.surface_corrections:
            raise ParameterError(
                "surface_correction",
                f"{cls.name} surface_correction must be one of {cls.surface_corrections}, "
                f"got {surface_correction!r}",
            )

    @classmethod
    def plane_wave_coefficients(cls, family: PointFamily, E: float, nu: float | None):
        """The material's linearisation on one point's ``family`` of an infinite homogeneous
        medium of Young's modulus ``E`` (Pa) and Poisson ratio ``nu``: the coefficients of its
        acoustic tensor (``peridyn.analysis.dispersion``),

            D(k) = sum pair n n^T (1 - cos k x) + dilatation_modulus g g^T,
            g(k) = sum dilatation n sin(k x),

        Returns
        -------
        pair : (n,) float64, Pa/m^2
        dilatation : (n,) float64, 1/m (zeros for a bond-based material)
        dilatation_modulus : float, Pa (0 for a bond-based material)
        """
        raise InputError(f"material {cls.name!r} gives no plane-wave coefficients (dispersion)")

    @classmethod
    def family_stiffness_bound(cls, family: PointFamily, E, nu) -> float:
        """Block-Gershgorin bound B (N/m^5 in 3D) of the stiffness row of a point whose bonds
        are ``family``, the continuum form of :meth:`stiffness_bound` (``setup.stable_step``:
        dt = 2 / sqrt(B / rho)). ``E`` (Pa) and ``nu`` are sequences, one value per material of
        the body (its blocks); the bound holds for all of them.

        This default is that of a bond-based law, B = 2 sum pair (``plane_wave_coefficients``
        with the largest E); a state-based material overrides it.
        """
        if cls.state_based:
            raise InputError(f"material {cls.name!r} gives no stable-step estimate without its bonds")
        pair = cls.plane_wave_coefficients(family, max(E), None)[0]
        return float(2.0 * np.sum(pair))

    @classmethod
    def implied_poisson_ratio(cls, dim: int, plane: str | None = None) -> float | None:
        """The Poisson ratio the material has on a body of dimension ``dim`` (2D: ``plane``
        "stress" or "strain") whatever ``nu`` it is given (bond-based materials), or None when
        it takes the ``nu`` given (the default)."""
        return None

    @classmethod
    def check_nu(cls, nu, dim: int, plane: str | None = None) -> None:
        """Refuse a Poisson ratio ``nu`` (a number, per-point values or None) that the material
        cannot have on a body of dimension ``dim`` (``implied_poisson_ratio``): what the model's
        construction refuses, asked before anything is built (``peridyn validate``).

        Raises
        ------
        InputError
            Naming ``nu`` and the ratio the material has.
        """
        implied = cls.implied_poisson_ratio(dim, plane)
        if implied is not None and nu is not None and np.any(np.abs(np.asarray(nu) - implied) > 1e-3):
            raise InputError(
                f"nu = {nu}: a bond-based {cls.name.upper()} material has Poisson ratio {implied:.4g} here "
                "(1/4 in 3D and plane strain, 1/3 in plane stress): omit nu or use lps"
            )

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n_points={self.body.n_points}, dtype={self.dtype.name})"

    @property
    def bond_vectors(self) -> np.ndarray:
        """(n_bonds, 3) float64, m: the reference vector ``xi = x_j - x_i`` of every bond.

        The float64 force kernels read it instead of gathering the neighbours' positions
        (``peridyn.kernels``): 24 bytes a bond, computed on the first call and kept. One-off
        computations use :meth:`bond_vectors_once` instead.
        """
        if self._bond_vectors is None:
            self._bond_vectors = self.bond_vectors_once()
        return self._bond_vectors

    def bond_vectors_once(self) -> np.ndarray:
        """:attr:`bond_vectors` without keeping them: the kept array once the force has made it,
        else a new one, freed after its use. For the float64 computations done once or at
        records (corrections, energies, stresses) of models whose force may never read the
        bond vectors (float32 kernels, modal analyses), which should not hold 24 B a bond."""
        if self._bond_vectors is not None:
            return self._bond_vectors
        x = np.ascontiguousarray(self.body.points, dtype=np.float64)
        return initial_bond_vectors(x, self.offsets, self.neighbours, np.empty((len(self.neighbours), 3)))

    def _as_state(self, u: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(u, dtype=self.dtype)

    @property
    def force_fills_acceleration(self) -> bool:
        """True when ``force(u, a)`` may write a state's float64 acceleration ``a`` (n_points, 3)
        in place (the explicit solver then keeps no force array of its own, 24 B a point): the
        force overwrites every row of its output (``force_overwrites_out``) in float64."""
        return self.force_overwrites_out and self.dtype == np.float64

    def force(self, u: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Internal force density (n_points, 3), N/m^3, at displacement ``u`` (n_points, 3), m."""
        raise NotImplementedError

    def force_from_positions(self, y: np.ndarray, out: np.ndarray) -> np.ndarray:
        """Internal force density (n_points, 3), N/m^3, into ``out`` from the deformed positions
        ``y`` (n_points, 3), m, in Peridigm's order of operations (``solver.arithmetic:
        peridigm``, docs/peridigm.md). A material without that order refuses it."""
        raise InputError(
            f"solver.arithmetic: peridigm takes Peridigm's force order, which the {self.name} "
            "material lacks (it has the LPS one): use arithmetic peridyn"
        )

    def force_overlapped(
        self, u: np.ndarray, out: np.ndarray, clear_rows, n_owned: int, finish
    ) -> np.ndarray:
        """``force(u, out)`` on the rows ``0 .. n_owned - 1`` of a rank's part (``peridyn.parallel``)
        while the ghost rows of ``u`` (rows ``n_owned ..``) are on their way: ``finish()`` waits
        for them. The rows that need no ghost value (the first ``clear_rows[0]`` rows for a
        force that reads the families of a point's neighbours, else ``clear_rows[1]``; see
        ``Domain.clear_rows``) are computed before ``finish()``, the others after, each row by
        the same kernel arithmetic as ``force``; the ghost rows of ``out`` are left zero.

        This default waits first, then computes ``force``.
        """
        finish()
        return self.force(u, out)

    def _refresh_ghosts(self, state: np.ndarray, u: np.ndarray, n_owned: int) -> np.ndarray:
        """``state`` (``_as_state(u)`` taken before the ghost rows of ``u`` arrived) with them:
        ``u`` itself if it was not copied, else the copy with its ghost rows converted again."""
        if state is not u:
            state[n_owned:] = u[n_owned:]
        return state

    def energy_density(self, u: np.ndarray) -> np.ndarray:
        """Strain energy density (n_points,), J/m^3."""
        raise NotImplementedError

    def strain_energy(self, u: np.ndarray) -> float:
        """Total strain energy, J (a pairwise sum in a fixed order, as ``Domain.dot``)."""
        return float(np.sum(self.energy_density(u) * self.body.volumes))

    def stiffness_bound(self) -> np.ndarray:
        """(n_points,) N/m^4: an upper bound of each point's block row sum of the stiffness per volume.

        By the block Gershgorin theorem the largest eigenvalue of M^-1 K is at
        most ``max(stiffness_bound / density)``; for PMB this is the bound of
        Silling and Askari (2005).
        """
        raise NotImplementedError

    def critical_stretch(self, fracture_energy: float):
        """Critical bond stretch for a fracture energy ``fracture_energy`` (J/m^2): a float, or
        (n_points,) for a body of several blocks (each point's from its own constants)."""
        raise NotImplementedError

    def linearisation(self) -> BondLinearisation:
        """The small-displacement form of the material (``materials.linearisation``), float64.

        Built once from the set-up coefficients and kept: consumers read ``bonds.intact``
        themselves, so it stays valid while bonds break.
        """
        if self._linearisation is None:
            self._linearisation = self._linearise()
        return self._linearisation

    def _linearise(self) -> BondLinearisation:
        """Build the :class:`BondLinearisation` (called once by :meth:`linearisation`)."""
        raise NotImplementedError

    def partial_stress(self, u: np.ndarray) -> np.ndarray:
        """Peridynamic partial stress of every point (n_points, 3, 3), Pa, at ``u`` (n_points, 3), m.

        sigma_i = sum_j T_ij (x) xi_ij V_j over the intact bonds, T_ij the force state of point
        i on bond ij (force per volume squared) and xi_ij the reference bond: the "partial
        stress" of Peridigm (its ``Partial_Stress``), i.e. the peridynamic stress tensor of
        Lehoucq and Silling (2008) in the limit of a small horizon, nu_0 = int T<xi> (x) xi dV_xi
        (Silling and Lehoucq 2010, "Peridynamic theory of solid mechanics", sec. 8). It is a
        first Piola-Kirchhoff (nominal) stress: force per reference area, not symmetric under
        finite rotations. In 2D its out-of-plane components are 0.

        The default takes the force state of point i as the derivative of its own energy in
        the linearisation (``materials.linearisation``: W_i = sum_j pair_ij e_ij^2 / 4 +
        c_i theta_i^2), with the deformed extension ``e = |Y| - |xi|`` and direction ``Y / |Y|`` as the
        nonlinear tangent does::

            T_ij V_j = [weight_ij |xi_ij| P_i + (pair_ij / 2) e_ij] Y_ij / |Y_ij|,
            P_i = p_coef_i theta_i,  theta_i = theta_coef_i sum_j weight_ij |xi_ij| e_ij,

        exact for the ordinary state-based and bond-based forces (PMB: ``k e / (2 |xi|)``, half
        the pair force; LPS: ``t = w |xi| P_i + alpha_i g_ij w e``). Computed in float64 whatever
        the kernel dtype; broken bonds carry no force.
        """
        b, lin = self.bonds, self.linearisation()
        x = self.body.points
        u = np.ascontiguousarray(u, dtype=np.float64)
        n = self.body.n_points
        if lin.has_dilatation:
            xi = self.bond_vectors_once()
            theta = lps_dilatation(
                xi, u, b.offsets, b.neighbours, b.length, lin.weight, b.intact, lin.theta_coef, np.empty(n)
            )
            p, axial = lin.p_coef * theta, lin.weight * b.length
        else:
            p, axial = np.zeros(n), np.zeros(b.n_bonds)
        return partial_stress(
            x, u, b.offsets, b.neighbours, b.length, axial, 0.5 * lin.pair, b.intact, p, np.empty((n, 3, 3))
        )

    def damage_index(self) -> np.ndarray:
        """Damage index phi (n_points,): 1 - the intact share of each family's bond volume
        (neighbour volume times partial-volume factor); 0 for a point without bonds."""
        b = self.bonds
        return damage_index(b.offsets, self.bond_volume, b.intact, np.empty(self.body.n_points))

    @property
    def has_dilatation(self) -> bool:
        """True when points couple through a dilatation (state-based): the stiffness then
        reaches two horizons and a factorisation carries one more unknown per point."""
        return self.linearisation().has_dilatation

    def critical_time_step(
        self, extra_bound: np.ndarray | None = None, points: np.ndarray | None = None
    ) -> float:
        """Largest stable velocity-Verlet step, s: 2 / sqrt(max stiffness_bound / density).

        ``extra_bound`` ((n_points,) N/m^4): stiffness added to the material's (e.g. contact);
        ``points``: take the maximum over these point indices only (e.g. a periodic cell).
        """
        bound = self.stiffness_bound() / self.density
        if extra_bound is not None:
            bound = bound + extra_bound / self.density
        if points is not None:
            bound = bound[points]
        return float(2.0 / np.sqrt(np.max(bound)))


def per_point(value, n_points: int, name: str) -> np.ndarray:
    """(n_points,) float64 copy of a per-point material constant ``value`` (an array of that shape)."""
    array = np.array(value, dtype=np.float64)
    if array.shape != (n_points,):
        raise InputError(
            f"material {name}: a number or one value per point ({n_points},), got shape {array.shape}"
        )
    return array
