"""Contact (short-range forces, ``peridyn.physics.contact``) on a rank's part of the body, with
the serial run's forces bit for bit.

The serial Verlet list holds the pairs (i, j), i < j, within ``radius + skin`` of each other in
the deformed configuration, sorted by (i, j); its kernel adds each touching pair's force to both
points in that order, so a point's contact force is summed over its partners in ascending
global index. A rank does the same for its owned points:

- at every rebuild (when some point of the whole body has moved more than skin / 2 since the
  last one: the largest move is reduced over the ranks, exact, so every rank rebuilds at the
  same step as the serial run) each rank sends the others the deformed positions of its owned
  points that lie within ``radius + skin`` of their owned points' bounding box; the pairs with
  an owned point are found among the owned and received points, oriented and sorted by global
  index, and the received points in a pair become the rank's contact ghosts, with their own
  halo (``peridyn.parallel.halo``) planned anew. Contact partners may thus come from anywhere
  in the body (a closing gap, an impact), not only from the bond ghosts;
- at every step the displacements of the contact ghosts are exchanged and the serial kernel
  runs on the owned points and contact ghosts, its force accumulated into a copy of the owned
  rows of the force (then copied back: copies are exact). A pair's bond is looked up in the
  owned point's family (whole on the rank), whose intact flag equals its reverse copy's.

The stiffness bound (stable time step) is the serial one computed on the whole body (every
rank holds the whole body's points), then restricted to the rank's points.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from peridyn.discretization.body import Body
from peridyn.kernels.contact import add_contact_force, largest_squared_move, pair_bond_index
from peridyn.parallel.domain import Domain
from peridyn.parallel.halo import Halo, plan_halo
from peridyn.physics.contact import Contact, contact_stiffness_bound
from peridyn.physics.materials.base import Model


class RankContact(Contact):
    """``Contact`` of one rank's part (see the module docstring).

    Parameters
    ----------
    model : Model
        The rank's part of the model (owned points, then bond ghosts).
    domain : Domain
    whole_body : Body
        The case's whole body (reference positions and volumes of any contact partner).
    radius, stiffness_factor, skin
        As for ``Contact``.

    ``rebuilds`` counts the builds of the whole body's list (the same on every rank and as in
    serial); ``touching`` is the number of touching pairs with an owned point on this rank.
    """

    def __init__(
        self,
        model: Model,
        domain: Domain,
        whole_body: Body,
        radius: float,
        stiffness_factor: float,
        skin: float | None = None,
    ):
        super().__init__(model, radius, stiffness_factor, skin)
        self.domain = domain
        self.whole_body = whole_body
        bonds = model.bonds
        #: global index of each bond's far end (the owned families keep the serial order)
        self._far = domain.global_ids[bonds.neighbours]
        self._ids = domain.global_ids[: domain.n_owned]
        self._halo: Halo | None = None
        self._u = self._x = self._f = np.zeros((0, 3))
        self._v = np.zeros(0)
        self._whole_built: np.ndarray | None = None

    def needs_rebuild(self, u: np.ndarray) -> bool:
        """True if no list exists or some point of the whole body moved more than skin / 2 since
        the last build (collective)."""
        if self._u_built is None:
            return True
        n = self.domain.n_owned
        return bool(self.domain.max(largest_squared_move(u[:n], self._u_built)) > (0.5 * self.skin) ** 2)

    def rebuild(self, u: np.ndarray) -> None:
        """Rebuild the list at the local displacement ``u`` (n_local, 3), m: owned rows read
        (collective)."""
        d, n = self.domain, self.domain.n_owned
        reach = self.radius + self.skin
        owned_u = np.array(u[:n], dtype=np.float64)
        y = self.x[:n] + owned_u
        ids, points, owner = self._candidates(y, reach)
        local = cKDTree(points).query_pairs(reach, output_type="ndarray")
        local = local[(local < n).any(axis=1)]
        g = ids[local]
        first, second = g.min(axis=1), g.max(axis=1)
        order = np.lexsort((second, first))
        first, second = first[order], second[order]
        ghosts = np.setdiff1d(np.union1d(first, second), self._ids)
        ghost_owner = owner[_positions(ids, ghosts)]
        by_owner = np.lexsort((ghosts, ghost_owner))
        ghosts, ghost_owner = ghosts[by_owner], ghost_owner[by_owner]
        contact_ids = np.concatenate([self._ids, ghosts])
        self._halo = Halo(d.comm, plan_halo(d.comm, self._ids, ghosts, ghost_owner))
        self._first = _positions(contact_ids, first)
        self._second = _positions(contact_ids, second)
        near = np.where(self._first < n, self._first, self._second)
        far = np.where(self._first < n, second, first)
        self._bond = pair_bond_index(self.model.bonds.offsets, self._far, near, far)
        self._x = np.ascontiguousarray(self.whole_body.points[contact_ids], dtype=np.float64)
        self._v = np.ascontiguousarray(self.whole_body.volumes[contact_ids], dtype=np.float64)
        self._u = np.zeros((len(contact_ids), 3))
        self._f = np.zeros((len(contact_ids), 3), dtype=self.model.dtype)
        self._u_built = owned_u
        self.rebuilds += 1

    def _candidates(self, y: np.ndarray, reach: float):
        """Global indices, deformed positions (m) and owner ranks of the owned points and of the
        other ranks' owned points within ``reach`` of this rank's box of ``y`` (collective)."""
        d = self.domain
        margin = reach * (1 + 1e-9)
        boxes = d.comm.allgather((y.min(axis=0) - margin, y.max(axis=0) + margin) if len(y) else None)
        sends = []
        for r, box in enumerate(boxes):
            inside = np.zeros(len(y), dtype=bool)
            if r != d.comm.rank and box is not None:
                inside = np.all((y >= box[0]) & (y <= box[1]), axis=1)
            sends.append((self._ids[inside], y[inside]))
        got = d.comm.alltoall(sends)  # nothing from this rank itself
        counts = [len(y), *(len(gid) for gid, _ in got)]
        return (
            np.concatenate([self._ids, *(gid for gid, _ in got)]),
            np.concatenate([y, *(p for _, p in got)]),
            np.repeat([d.comm.rank, *range(d.size)], counts),
        )

    def gather_built(self) -> None:
        """Gather the whole body's build displacement on rank 0 for ``checkpoint_state``
        (collective)."""
        self._whole_built = None if self._u_built is None else self.domain.gather(self._u_built)

    def checkpoint_state(self) -> dict:
        """As ``Contact.checkpoint_state``, for the whole body, on rank 0 after ``gather_built``."""
        if self._whole_built is None:
            return {}
        return {"u_built": self._whole_built, "rebuilds": self.rebuilds}

    def restore_state(self, saved: dict) -> None:
        """Rebuild where the whole body's ``saved`` list was built (collective)."""
        if saved:
            self.rebuild(saved["u_built"][self.domain.global_ids])
            self.rebuilds = int(saved["rebuilds"])

    def add_force(self, u: np.ndarray, out: np.ndarray) -> np.ndarray:
        """Add the contact force density (N/m^3) at the local displacement ``u`` (m) to the owned
        rows of ``out`` (both (n_local, 3)); collective. Returns ``out``."""
        n = self.domain.n_owned
        if self.needs_rebuild(u):
            self.rebuild(u)
        self._u[:n] = u[:n]
        self._halo.exchange(self._u)
        y = self._x + self._u
        if self._f.dtype != out.dtype:
            self._f = np.zeros(self._f.shape, dtype=out.dtype)
        f = self._f
        f[:n] = out[:n]
        f[n:] = 0.0
        self.touching = add_contact_force(
            y,
            self._first,
            self._second,
            self._bond,
            self.model.bonds.intact,
            self._v,
            self.stiffness,
            self.radius,
            f,
        )
        out[:n] = f[:n]
        return out

    def stiffness_bound(self) -> np.ndarray:
        """(n_local,) N/m^4: the serial bound of the whole body (``Contact.stiffness_bound``) at
        the rank's points."""
        body = self.whole_body
        x = np.ascontiguousarray(body.points, dtype=np.float64)
        volumes = np.ascontiguousarray(body.volumes, dtype=np.float64)
        return contact_stiffness_bound(x, volumes, self.radius, self.stiffness)[self.domain.global_ids]


def _positions(ids: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """(k,) int64: the position in ``ids`` (distinct) of each of ``wanted`` (all present)."""
    sorter = np.argsort(ids, kind="stable")
    return sorter[np.searchsorted(ids, wanted, sorter=sorter)].astype(np.int64)
