"""Explicit-step throughput with bond breaking and contact against the undamaged step.

Same grid as ``peridyn bench`` (``peridyn.jobs.bench``: cube of 46^3 points, 1 mm, horizon
3.015 h, no partial volumes), PMB float64. All rows start from the same random
velocity field (``--velocity``, default 1 m/s rms: strains just below the critical
stretch, few or no bonds break; 2 m/s: bonds break here and there all through the cube).
"undamaged": ExplicitSolver without damage or contact. "damaged + contact": a pre-crack
through the mid-plane x = L/2, critical-stretch damage (s_c = 1e-3) and contact (radius = h,
factor 15); "contact only": the pre-crack and contact without bond breaking, which isolates
the cost of contact; "damaged, no contact": the pre-crack and bond breaking. The rows are
copies of one model sharing its per-bond arrays (each has its own ``intact``), which keeps
the run under 2 GB. Rows are timed in interleaved rounds of ``--steps`` steps, best round
kept; throughput = steps / s. Two untimed steps first load the kernels, build the contact
list and do the first full stretch test of ``BondDamage``; later contact rebuilds and
full stretch tests are timed with the steps and counted.

    PYTHONPATH=src python benchmarks/bench_contact.py [--points-per-side 46] [--steps 10]
        [--rounds 3] [--velocity 1.0]
"""

import argparse
import copy
import time
from dataclasses import replace

import numpy as np

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.jobs.bench import DEFAULT_POINTS_PER_SIDE, DENSITY, HORIZON_FACTOR, SPACING, E
from peridyn.physics.contact import Contact
from peridyn.physics.damage import BondDamage
from peridyn.physics.loads import Loading
from peridyn.physics.materials import make_model
from peridyn.solvers import ExplicitSolver


def shared_model(side: int):
    """The benchmark's PMB model and the mask (n_bonds,) bool of the bonds that a pre-crack
    through the whole mid-plane x = L/2 cuts (bonds from a point on the plane are kept)."""
    body = geometry.box((side * SPACING,) * 3, SPACING)
    bonds = find_bonds(body, HORIZON_FACTOR * SPACING, partial_volumes=False)
    model = make_model("pmb", body, bonds, E=E, density=DENSITY)
    side_of = np.sign(body.points[:, 0] - 0.5 * side * SPACING).astype(np.int8)
    return model, side_of[bonds.owners()] * side_of[bonds.neighbours] < 0


def solver_for(model, precrack, damaged: bool, breaking: bool = True, contact: bool = True) -> ExplicitSolver:
    """A row's solver on a copy of ``model`` that shares its per-bond arrays (memory) but has
    bonds of its own to break."""
    model = copy.copy(model)
    model.bonds = replace(model.bonds, intact=np.ones(model.bonds.n_bonds, dtype=bool))
    if not damaged:
        return ExplicitSolver(model, Loading(model.body))
    model.bonds.intact[precrack] = False
    damage = BondDamage(model, critical_stretch=1e-3) if breaking else None
    return ExplicitSolver(
        model, Loading(model.body), damage=damage, contact=Contact(model, SPACING) if contact else None
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points-per-side", type=int, default=DEFAULT_POINTS_PER_SIDE)
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument(
        "--velocity",
        type=float,
        default=1.0,
        help="rms of the random initial velocities, m/s (2 breaks bonds here and there)",
    )
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    model, precrack = shared_model(args.points_per_side)
    rows = {
        "undamaged": solver_for(model, precrack, False),
        "damaged + contact": solver_for(model, precrack, True),
        "contact only": solver_for(model, precrack, True, breaking=False),
        "damaged, no contact": solver_for(model, precrack, True, contact=False),
    }
    v0 = rng.normal(scale=args.velocity / np.sqrt(3), size=(args.points_per_side**3, 3))
    states = {}
    for name, solver in rows.items():
        state = solver.initial_state()
        state.v[:] = v0
        solver.run(state, 2)  # JIT / cache load and first contact list
        states[name] = state
    damage = rows["damaged + contact"].damage
    untimed = (damage.full_tests, damage.partial_tests)
    best = dict.fromkeys(rows, np.inf)
    for _ in range(args.rounds):
        for name, solver in rows.items():
            start = time.perf_counter()
            solver.run(states[name], args.steps)
            best[name] = min(best[name], time.perf_counter() - start)
    n_bonds = rows["undamaged"].model.bonds.n_bonds
    print(f"grid {args.points_per_side}^3 = {args.points_per_side**3} points, {n_bonds} directed bonds")
    for name in rows:
        print(f"{name:>18}: {args.steps / best[name]:.3f} steps/s")
    contact = rows["damaged + contact"].contact
    broken = int((~rows["damaged + contact"].model.bonds.intact).sum()) - int(precrack.sum())
    print(
        f"contact: {contact.n_candidates} candidate pairs, {contact.touching} touching, "
        f"{contact.rebuilds} list builds; directed bonds broken besides the pre-crack's "
        f"{int(precrack.sum())}: {broken}"
    )
    print(
        f"stretch tests in the timed steps (damaged + contact): {damage.full_tests - untimed[0]} "
        f"full, {damage.partial_tests - untimed[1]} partial"
    )
    for name in ("damaged + contact", "contact only", "damaged, no contact"):
        print(f"ratio {name} / undamaged: {best['undamaged'] / best[name]:.3f}")


if __name__ == "__main__":
    main()
