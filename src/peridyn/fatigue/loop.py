"""The fatigue loop: equilibrium at the maximum load, remaining life, broken bonds, more cycles.

Each step: solve the linear static equilibrium with the bonds intact now (only after steps that
broke bonds: otherwise it has not changed), take the cyclic bond
strain from the load ratio, spend the step's cycles (``CycleMapping``) on every bond's remaining
life, break the bonds whose life ran out, switch families to phase II where the damage reached
phi_c, and track the crack tip.

Under MPI (a ``Domain`` of several ranks) each rank runs the loop on its part of the body (owned
points, ghosts filled by the halo exchange): the equilibrium by the distributed CG
(``fatigue.distributed.RankStatics``), strains, lives and breaking on the part's bonds
(``RemainingLife``), the adaptive step as the minimum over the ranks, the crack tip on the damage
gathered on rank 0 (its length broadcast), the bonds broken counted over the owned families.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from peridyn import interrupts
from peridyn.errors import InputError
from peridyn.fatigue.distributed import RankStatics
from peridyn.fatigue.mapping import CycleMapping
from peridyn.fatigue.model import FatigueParameters, RemainingLife, cyclic_bond_strain
from peridyn.fatigue.statics import LinearStatics
from peridyn.fatigue.tip import crack_tip
from peridyn.io.case import CrackPlane, FatigueTip
from peridyn.parallel.domain import Domain
from peridyn.physics.damage import damage_field, protected_points
from peridyn.physics.loads import Loading
from peridyn.physics.materials.base import Model


@dataclass
class FatigueResult:
    """History of a fatigue run.

    Attributes
    ----------
    cycles : (n_steps + 1,) float64, cycles at the end of each step (0 first)
    crack_length : (n_steps + 1,) float64, m
    broken : (n_steps + 1,) int64, directed bonds broken by the cycles so far (each bond
        counts twice, as in ``Bonds.n_bonds``; pre-cracks not counted)
    u_max : (n_points, 3) float64, m, displacement at the maximum load after the last step
    damage : (n_points,) float64, final damage index
    first_break : (n_points,) float64, cycle at which each point first lost a bond (inf if none)
    broken_pairs : (n_broken, 2) int64, the bonds the cycles broke, each once: its two points
        (the smaller index first), sorted
    break_cycle : (n_broken,) float64, cycle at which each of ``broken_pairs`` broke

    Under MPI every rank holds the history (``cycles``, ``crack_length``, ``broken``); the
    per-point and per-bond arrays are the whole body's in global point order on rank 0, None on
    the others.
    """

    cycles: np.ndarray
    crack_length: np.ndarray
    broken: np.ndarray
    u_max: np.ndarray | None
    damage: np.ndarray | None
    first_break: np.ndarray | None = field(repr=False)
    broken_pairs: np.ndarray | None = field(default=None, repr=False)
    break_cycle: np.ndarray | None = field(default=None, repr=False)


def breakable_bonds(
    model: Model, no_damage_sets=(), domain: Domain | None = None, plane: CrackPlane | None = None
) -> np.ndarray:
    """(n_bonds,) bool: bonds with neither end in a no-damage node set (and, with a ``plane``,
    the case's ``fatigue.crack_plane``, whose ends lie strictly on opposite sides of it).

    Under MPI (``domain`` of several ranks) ``model`` is a rank's part, which may hold none of a
    set's points: each set must be known and hold points somewhere in the body (collective)."""
    body = model.body
    if domain is not None and domain.size > 1:
        for name in no_damage_sets:
            if domain.count(len(body.node_sets.get(name, ()))) == 0:
                raise InputError(f"no-damage node set {name!r} is unknown or holds no point")
        no_damage_sets = [name for name in no_damage_sets if len(body.node_sets[name])]
    protected = protected_points(body, no_damage_sets)
    b = model.bonds
    owners = b.owners()
    breakable = ~(protected[owners] | protected[b.neighbours])
    if plane is not None:
        side = body.points[:, "xyz".index(plane.axis)] - plane.at
        breakable &= side[owners] * side[b.neighbours] < 0
    return breakable


def run_fatigue(
    model: Model,
    loading: Loading,
    params: FatigueParameters,
    mapping: CycleMapping,
    *,
    load_ratio: float = 0.0,
    max_load_time: float = 1.0,
    no_damage_sets=(),
    crack_plane: CrackPlane | None = None,
    tip: FatigueTip | None = None,
    solver: str = "auto",
    stop_length: float = np.inf,
    progress=None,
    domain: Domain | None = None,
) -> FatigueResult:
    """Run the fatigue loop on ``model`` (its ``bonds.intact`` is updated in place).

    Parameters
    ----------
    model, loading : the model and the case's loads; the loads' value at ``max_load_time``
        (s) is the maximum load
    params : the remaining-life parameters
    mapping : cycles per step
    load_ratio : R = min load / max load, in [-1, 1)
    no_damage_sets : node sets whose bonds never break
    crack_plane : only the bonds across this plane may break (None: any bond)
    tip : the crack-tip rule (``fatigue.tip.crack_tip``: growth axis, depth axis, damage
        threshold, start, sense), the case's ``fatigue.tip``; default ``FatigueTip()`` (along x,
        depth z, damage 0.385, from the low edge)
    solver : linear solver of the equilibrium (``fatigue.statics.LinearStatics``)
    stop_length : m, the run ends after the step at which the crack length reaches it
    progress : object with update(n) (e.g. a tqdm bar) or None
    domain : the rank's place in the body under MPI (``model`` and ``loading`` are its part; the
        solver is then the distributed CG: ``solver`` "auto" or "amg"); None: one process.
        Collective: every rank calls it.
    """
    if not -1.0 <= load_ratio < 1.0:
        raise InputError(f"load ratio R must be in [-1, 1), got {load_ratio!r}")
    tip = FatigueTip() if tip is None else tip
    domain = Domain.serial(model.body.n_points) if domain is None else domain
    if domain.size == 1:
        statics = LinearStatics(model, loading, max_load_time, solver)
    elif solver in ("auto", "amg"):
        statics = RankStatics(model, loading, domain, max_load_time)
    else:
        raise InputError(f"an MPI fatigue run solves by CG with AMG (solver auto or amg), not {solver!r}")
    life = RemainingLife(model, params, breakable_bonds(model, no_damage_sets, domain, crack_plane), domain)
    points, spacing = domain.gather(model.body.points), model.body.spacing
    owners = model.bonds.owners()
    owned_bonds = slice(0, model.bonds.offsets[domain.n_owned])  # the owned points' families

    def n_broken():
        return domain.count(int((~model.bonds.intact[owned_bonds]).sum()))

    n_broken0 = n_broken()
    first_break = np.full(model.body.n_points, np.inf)
    breaks = []  # per step that broke bonds: (global point pairs of the owned bonds, cycle)
    life.update_phase(damage_field(model))  # pre-cracks may start families in phase II
    cycles, lengths, broken = [0.0], [], [0]

    def crack_length(phi):
        whole = domain.gather(phi)
        length = domain.on_root(
            crack_tip, points, whole, spacing, tip.axis, tip.depth_axis, tip.damage, tip.start, tip.sense
        )
        return domain.comm.bcast(length)

    lengths.append(crack_length(damage_field(model)))
    n_cycles = 0.0
    u = None
    changed = True
    for dn in mapping.cycles_per_step():
        interrupts.check(where=f"cycling (at {n_cycles:.6g} cycles)", agree=domain.max)
        if changed:  # equilibrium only moves when bonds broke
            u = statics.solve()
            eps = cyclic_bond_strain(model, u, load_ratio)
        if mapping.adaptive:
            dn = min(dn, domain.min(life.cycles_to_next_break(eps)) * (1.0 + 1e-12))
        before = model.bonds.intact.copy()
        life.advance(eps, dn)
        n_cycles += dn
        lost = before & ~model.bonds.intact
        changed = bool(domain.max(bool(lost.any())))
        hit = np.zeros(model.body.n_points, dtype=bool)
        hit[owners[lost]] = True
        first_break[hit & np.isinf(first_break)] = n_cycles
        mine = np.flatnonzero(lost[owned_bonds])
        if mine.size:
            pair = domain.global_ids[np.column_stack([owners[mine], model.bonds.neighbours[mine]])]
            breaks.append((np.sort(pair, axis=1), n_cycles))
        phi = damage_field(model)
        life.update_phase(phi)
        cycles.append(n_cycles)
        lengths.append(crack_length(phi))
        broken.append(n_broken() - n_broken0)
        if progress is not None:
            progress.update(1)
        if lengths[-1] >= stop_length:
            break
    u_max = (statics.solve() if changed else u) if u is not None else np.zeros_like(model.body.points)
    pairs = domain.comm.gather(breaks) if domain.size > 1 else [breaks]
    return FatigueResult(
        np.array(cycles),
        np.array(lengths),
        np.array(broken, dtype=np.int64),
        *domain.gather_many(u_max, damage_field(model), first_break) or (None, None, None),
        *(_first_breaks([b for rank in pairs for b in rank]) if pairs is not None else (None, None)),
    )


def _first_breaks(breaks: list) -> tuple[np.ndarray, np.ndarray]:
    """(n, 2) int64 point pairs, each bond once (sorted), and (n,) the cycle of its first break,
    from ``breaks``: (pairs (k, 2) with the smaller index first, cycle) of every step and rank."""
    if not breaks:
        return np.zeros((0, 2), dtype=np.int64), np.zeros(0)
    pairs = np.concatenate([p for p, _ in breaks])
    cycle = np.concatenate([np.full(len(p), c) for p, c in breaks])
    order = np.lexsort((cycle, pairs[:, 1], pairs[:, 0]))
    pairs, cycle = pairs[order], cycle[order]
    first = np.ones(len(pairs), dtype=bool)
    first[1:] = np.any(pairs[1:] != pairs[:-1], axis=1)
    return pairs[first], cycle[first]
