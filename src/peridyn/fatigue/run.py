"""The fatigue loop: equilibrium at the maximum load, remaining life, broken bonds, more cycles.

Each step: solve the linear static equilibrium with the bonds intact now (only after steps that
broke bonds: otherwise it has not changed), take the cyclic bond
strain from the load ratio, spend the step's cycles (``CycleMapping``) on every bond's remaining
life, break the bonds whose life ran out, switch families to phase II where the damage reached
phi_c, and track the crack tip.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from peridyn import interrupts
from peridyn.errors import InputError
from peridyn.fatigue.mapping import CycleMapping
from peridyn.fatigue.model import FatigueParameters, RemainingLife, cyclic_bond_strain
from peridyn.fatigue.statics import LinearStatics
from peridyn.fatigue.tip import crack_tip
from peridyn.io.case import FatigueTip
from peridyn.physics.damage import damage_field
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
    """

    cycles: np.ndarray
    crack_length: np.ndarray
    broken: np.ndarray
    u_max: np.ndarray
    damage: np.ndarray
    first_break: np.ndarray = field(repr=False)


def breakable_bonds(model: Model, no_damage_sets=()) -> np.ndarray:
    """(n_bonds,) bool: bonds with neither end in a no-damage node set."""
    protected = np.zeros(model.body.n_points, dtype=bool)
    for name in no_damage_sets:
        protected[model.body.node_set(name)] = True
    b = model.bonds
    return ~(protected[b.owners()] | protected[b.neighbours])


def run_fatigue(
    model: Model,
    loading: Loading,
    params: FatigueParameters,
    mapping: CycleMapping,
    *,
    load_ratio: float = 0.0,
    max_load_time: float = 1.0,
    no_damage_sets=(),
    tip: FatigueTip | None = None,
    solver: str = "auto",
    stop_length: float = np.inf,
    progress=None,
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
    tip : the crack-tip rule (``fatigue.tip.crack_tip``: growth axis, depth axis, damage
        threshold, start, sense), the case's ``fatigue.tip``; default ``FatigueTip()`` (along x,
        depth z, damage 0.385, from the low edge)
    solver : linear solver of the equilibrium (``fatigue.statics.LinearStatics``)
    stop_length : m, the run ends after the step at which the crack length reaches it
    progress : object with update(n) (e.g. a tqdm bar) or None
    """
    if not -1.0 <= load_ratio < 1.0:
        raise InputError(f"load ratio R must be in [-1, 1), got {load_ratio!r}")
    tip = FatigueTip() if tip is None else tip
    statics = LinearStatics(model, loading, max_load_time, solver)
    life = RemainingLife(model, params, breakable_bonds(model, no_damage_sets))
    points, spacing = model.body.points, model.body.spacing
    owners = model.bonds.owners()
    n_broken0 = int((~model.bonds.intact).sum())
    first_break = np.full(model.body.n_points, np.inf)
    life.update_phase(damage_field(model))  # pre-cracks may start families in phase II
    cycles, lengths, broken = [0.0], [], [0]

    def crack_length(phi):
        return crack_tip(points, phi, spacing, tip.axis, tip.depth_axis, tip.damage, tip.start, tip.sense)

    lengths.append(crack_length(damage_field(model)))
    n_cycles = 0.0
    u = None
    changed = True
    for dn in mapping.cycles_per_step():
        interrupts.check(where=f"cycling (at {n_cycles:.6g} cycles)")
        if changed:  # equilibrium only moves when bonds broke
            u = statics.solve()
            eps = cyclic_bond_strain(model, u, load_ratio)
        if mapping.adaptive:
            dn = min(dn, life.cycles_to_next_break(eps) * (1.0 + 1e-12))
        before = model.bonds.intact.copy()
        life.advance(eps, dn)
        n_cycles += dn
        lost = before & ~model.bonds.intact
        changed = bool(lost.any())
        hit = np.zeros(model.body.n_points, dtype=bool)
        hit[owners[lost]] = True
        first_break[hit & np.isinf(first_break)] = n_cycles
        phi = damage_field(model)
        life.update_phase(phi)
        cycles.append(n_cycles)
        lengths.append(crack_length(phi))
        broken.append(int((~model.bonds.intact).sum()) - n_broken0)
        if progress is not None:
            progress.update(1)
        if lengths[-1] >= stop_length:
            break
    return FatigueResult(
        np.array(cycles),
        np.array(lengths),
        np.array(broken, dtype=np.int64),
        (statics.solve() if changed else u) if u is not None else np.zeros_like(points),
        damage_field(model),
        first_break,
    )
