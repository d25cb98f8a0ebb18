"""Contact between points that are not (or no longer) bonded: the short-range force model.

Silling's short-range forces, as in Peridigm (Parks et al., Peridigm users' guide;
Littlewood 2010): two points closer than the contact distance d_c in the deformed
configuration, and not joined by an intact bond, repel each other with the force density

    f_i = -c_sr (d_c - |y_j - y_i|) / delta  V_j  (y_j - y_i) / |y_j - y_i|     (N/m^3),

zero beyond d_c and never attractive. The short-range constant is ``c_sr = factor * c``
with c the micromodulus of a PMB material of the same Young's modulus and a constant
influence function (3D: c = 18 K / (pi delta^4), K = E / (3 (1 - 2/4)); 2D: see
``peridyn.physics.materials.pmb``) whatever the body's material: the constant is defined by
that reference micromodulus (Peridigm's convention), so it imports ``pmb_micromodulus`` by
design and asks the model only for ``Model.E``. Peridigm's documentation and Silling's EMU use
``factor = 15``, the default here: a contact pair at overlap d is then about as stiff as
15 bonds of length delta stretched by d, so that closed crack faces carry compression
nearly as the intact material did, while the stable time step shrinks by only ~20 %
(see ``stiffness_bound``).

Neighbour search: candidate pairs within ``d_c + skin`` of each other in the deformed
configuration are found with a k-d tree (a Verlet list). The list is rebuilt only when
some point has moved more than ``skin / 2`` since the last build: until then no pair
outside the list can have come closer than d_c. ``rebuilds`` counts the builds.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from peridyn.errors import InputError
from peridyn.kernels.contact import add_contact_force, largest_squared_move, pair_bond_index
from peridyn.physics.materials.base import Model
from peridyn.physics.materials.pmb import pmb_micromodulus

#: Peridigm's / EMU's short-range force constant as a multiple of the PMB micromodulus.
DEFAULT_STIFFNESS_FACTOR = 15.0


class Contact:
    """Short-range repulsive forces between unbonded points of one model's body.

    Parameters
    ----------
    model : Model
        Supplies the body (positions, volumes, dimension), the bonds (``intact`` is read
        at every call, so bonds broken during a run start to take part in contact) and
        Young's modulus ``model.E`` for the short-range constant.
    radius : float, m
        Contact distance d_c: 0 < d_c <= horizon, or with ``beyond_horizon`` any positive one.
    stiffness_factor : float
        c_sr as a multiple of the PMB micromodulus (default 15, Peridigm).
    skin : float or None, m
        Verlet skin added to d_c for the candidate list (default 0.5 d_c).
    beyond_horizon : bool
        Allow d_c above the horizon (Peridigm's decks: every unbonded pair within d_c repels,
        points farther apart than the horizon too). One process only.
    """

    def __init__(
        self,
        model: Model,
        radius: float,
        stiffness_factor: float = DEFAULT_STIFFNESS_FACTOR,
        skin: float | None = None,
        beyond_horizon: bool = False,
    ):
        body, bonds = model.body, model.bonds
        delta = bonds.horizon
        if not (np.isfinite(radius) and radius > 0):
            raise InputError(f"contact radius must be positive, got {radius!r} m")
        if radius > delta * (1 + 1e-12) and not beyond_horizon:
            raise InputError(
                f"contact radius {radius:g} m is larger than the horizon {delta:g} m: "
                "short-range forces act within the horizon (use radius <= horizon)"
            )
        if not (np.isfinite(stiffness_factor) and stiffness_factor > 0):
            raise InputError(f"contact stiffness factor must be positive, got {stiffness_factor!r}")
        skin = 0.5 * radius if skin is None else skin
        if not (np.isfinite(skin) and skin > 0):
            raise InputError(f"contact skin must be positive, got {skin!r} m")
        self.model = model
        self.radius = float(radius)
        self.skin = float(skin)
        self.stiffness_factor = float(stiffness_factor)
        micromodulus = pmb_micromodulus(model.E, body.dim, delta, "constant", body.plane, body.thickness)
        #: c_sr / delta, N/m^7 (3D) — multiplies (d_c - |Y|) V_j
        self.stiffness = self.stiffness_factor * micromodulus / delta
        self.volumes = np.ascontiguousarray(body.volumes, dtype=np.float64)
        self.x = np.ascontiguousarray(body.points, dtype=np.float64)
        self.rebuilds = 0
        self.touching = 0
        self._u_built = None
        self._first = self._second = self._bond = np.zeros(0, dtype=np.int64)

    def __repr__(self) -> str:
        return (
            f"Contact(radius={self.radius:g} m, stiffness_factor={self.stiffness_factor:g}, "
            f"skin={self.skin:g} m, rebuilds={self.rebuilds})"
        )

    @property
    def n_candidates(self) -> int:
        """Number of pairs in the current Verlet list."""
        return len(self._first)

    def needs_rebuild(self, u: np.ndarray) -> bool:
        """True if no list exists or some point moved more than skin / 2 since the last build."""
        if self._u_built is None:
            return True
        return bool(largest_squared_move(u, self._u_built) > (0.5 * self.skin) ** 2)

    def rebuild(self, u: np.ndarray) -> None:
        """Rebuild the Verlet list at displacement ``u`` (n_points, 3), m."""
        y = self.x + u
        pairs = cKDTree(y).query_pairs(self.radius + self.skin, output_type="ndarray")
        pairs = pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))].astype(np.int64)
        self._first = np.ascontiguousarray(pairs[:, 0])
        self._second = np.ascontiguousarray(pairs[:, 1])
        b = self.model.bonds
        self._bond = pair_bond_index(b.offsets, b.neighbours, self._first, self._second)
        self._u_built = np.array(u, dtype=np.float64)
        self.rebuilds += 1

    def checkpoint_state(self) -> dict:
        """The neighbour list's build displacement (n_points, 3) m and the rebuild count, for a
        checkpoint (empty before the first build)."""
        if self._u_built is None:
            return {}
        return {"u_built": self._u_built, "rebuilds": self.rebuilds}

    def restore_state(self, saved: dict) -> None:
        """Rebuild the neighbour list where ``checkpoint_state`` saw it built, and take back
        the rebuild count."""
        if saved:
            self.rebuild(saved["u_built"])
            self.rebuilds = int(saved["rebuilds"])

    def add_force(self, u: np.ndarray, out: np.ndarray, positions: np.ndarray | None = None) -> np.ndarray:
        """Add the contact force density (N/m^3) at displacement ``u`` (m) to ``out`` in place.

        Both arrays are (n_points, 3); ``out`` may be float32 or float64. ``positions``: the
        deformed positions (n_points, 3) m as the solver formed them (Peridigm's order,
        ``ExplicitSolver``), else x + u. Returns ``out``.
        """
        u = np.asarray(u, dtype=np.float64)
        if self.needs_rebuild(u):
            self.rebuild(u)
        y = self.x + u if positions is None else positions
        self.touching = add_contact_force(
            y,
            self._first,
            self._second,
            self._bond,
            self.model.bonds.intact,
            self.volumes,
            self.stiffness,
            self.radius,
            out,
        )
        return out

    def stiffness_bound(self) -> np.ndarray:
        """(n_points,) N/m^4: bound of each point's contact stiffness row sum per volume.

        A touching pair adds c_sr V_j / delta to the diagonal block of i and the same to the
        off-diagonal one (the radial stiffness; the transverse one, c_sr (d_c - r) / (delta r),
        is smaller while r > d_c / 2). Every point within d_c of i in the reference
        configuration is counted as a possible contact partner (bonded ones too, as their
        bonds may break), so the bound is 2 c_sr / delta sum_{|x_j - x_i| <= d_c} V_j. Added
        to the material's bound it keeps the explicit step stable (Gershgorin) while the
        body stays near its reference configuration; it does not count partners that come
        from farther away (a closing gap, an impact) nor the transverse stiffness of pairs
        pressed closer than d_c / 2, so such runs may need a smaller ``safety``.
        """
        return contact_stiffness_bound(self.x, self.volumes, self.radius, self.stiffness)


def contact_stiffness_bound(
    x: np.ndarray, volumes: np.ndarray, radius: float, stiffness: float
) -> np.ndarray:
    """(n_points,) N/m^4: ``Contact.stiffness_bound`` of the points ``x`` (n_points, 3), m, with
    ``volumes`` (n_points,) m^3, contact distance ``radius`` (m) and ``stiffness`` c_sr / delta."""
    tree = cKDTree(x)
    pairs = tree.query_pairs(radius * (1 + 1e-9), output_type="ndarray")
    per_point = np.zeros(len(x))
    np.add.at(per_point, pairs[:, 0], volumes[pairs[:, 1]])
    np.add.at(per_point, pairs[:, 1], volumes[pairs[:, 0]])
    return 2.0 * stiffness * per_point
