"""Remaining-life fatigue model: closed forms of thesis seed 002 eqs. 7.3-7.6 and 7.15 (V5)."""

import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.errors import InputError
from peridyn.fatigue import CycleMapping, FatigueParameters, crack_tip, run_fatigue, scale_A_II
from peridyn.physics.loads import BoundaryCondition, Loading
from peridyn.physics.materials import make_model
from peridyn.physics.timefunctions import Constant

#: V5 steel parameters (VALIDATION.md V5, thesis table 7.1).
V5 = FatigueParameters(A_I=426.0, m_I=2.77, eps_inf=0.00186, A_II=25237.48, m_II=4.0, phi_c=0.385)
SPACING = 1e-3


def _bar(strain, n=20):
    """A one-point-thick bar along x whose every point is held at u_x = strain x (uniform strain)."""
    body = geometry.box((n * SPACING, SPACING, SPACING), SPACING)
    body = body.with_node_set("all", np.ones(body.n_points, dtype=bool))
    bonds = find_bonds(body, 3.001 * SPACING)
    model = make_model("pmb", body, bonds, E=189.9e9, density=7850.0)
    profile = np.column_stack([strain * body.points[:, 0], np.zeros((body.n_points, 2))])
    loading = Loading(body, [BoundaryCondition("all", "displacement", "xyz", Constant(1.0), profile)])
    return model, loading


@pytest.mark.parametrize("strain", [0.004, 0.006])
def test_bar_loses_all_bonds_at_the_closed_form_life(strain):
    """Eq. 7.4 integrated at constant strain: every bond breaks at N = 1 / (A_I (eps - eps_inf)^m_I),
    within one cycle-mapping step (R = 0, so the cyclic strain is the bond strain)."""
    model, loading = _bar(strain)
    n_life = V5.phase_one_life(strain)
    step = n_life / 37.3  # steps not aligned with the life
    mapping = CycleMapping(((60, 1.0 / step),))
    result = run_fatigue(model, loading, V5, mapping, load_ratio=0.0)
    done = np.flatnonzero(result.broken == model.bonds.n_bonds)  # directed bonds
    assert done.size and not model.bonds.intact.any()
    n_break = result.cycles[done[0]]
    assert 0.0 <= n_break - n_life < step
    assert result.broken[done[0] - 1] == 0  # none before: uniform strain, one life for all


def test_each_broken_bond_is_recorded_once_with_the_cycle_it_broke():
    """A strain rising along the bar breaks its bonds at different cycles: the run's list of
    broken bonds is the model's broken bonds, each once; the directed bonds broken by each step
    of the history are twice those listed by then; each point's first break is the earliest of
    its bonds' (the monitoring job's bond transfer reads this list: docs/monitoring.md)."""
    model, loading = _bar(0.0)
    x = model.body.points[:, 0]
    profile = np.column_stack([0.006 * x * x / x.max(), np.zeros((len(x), 2))])  # strain 0 to 0.012
    loading = Loading(model.body, [BoundaryCondition("all", "displacement", "xyz", Constant(1.0), profile)])
    n_life = V5.phase_one_life(0.012)
    result = run_fatigue(model, loading, V5, CycleMapping(((40, 0.25 / n_life),)), load_ratio=0.0)
    b = model.bonds
    owners = b.owners()
    broken = ~b.intact
    want = {(int(i), int(j)) for i, j in zip(owners[broken], b.neighbours[broken], strict=True) if i < j}
    pairs = [tuple(p) for p in result.broken_pairs.tolist()]
    assert len(pairs) == len(set(pairs)) == len(want) > 0 and set(pairs) == want
    assert 1 < len(np.unique(result.break_cycle))  # not all at once
    listed_by = [2 * int(np.sum(result.break_cycle <= n)) for n in result.cycles]
    np.testing.assert_array_equal(listed_by, result.broken)
    earliest = np.full(model.body.n_points, np.inf)
    for end in (0, 1):
        np.minimum.at(earliest, result.broken_pairs[:, end], result.break_cycle)
    np.testing.assert_array_equal(earliest, result.first_break)


def test_no_bond_breaks_at_or_below_the_fatigue_limit():
    """Eq. 7.4: d lambda / dN = 0 for eps <= eps_inf, however many cycles."""
    model, loading = _bar(V5.eps_inf)
    result = run_fatigue(model, loading, V5, CycleMapping(((10, 1e-9),)), load_ratio=0.0)
    assert result.cycles[-1] == pytest.approx(1e10)
    assert result.broken[-1] == 0 and model.bonds.intact.all()


def test_load_ratio_scales_the_cyclic_strain():
    """Eq. 7.1 for proportional loading: eps = (1 - R) |s+|; R = 0.5 at s+ = 0.008 is eps = 0.004."""
    model, loading = _bar(0.008)
    n_life = V5.phase_one_life(0.004)
    step = n_life / 20.5
    result = run_fatigue(model, loading, V5, CycleMapping(((30, 1.0 / step),)), load_ratio=0.5)
    first = result.cycles[np.argmax(result.broken > 0)]
    assert 0.0 <= first - n_life < step


def test_adaptive_mapping_breaks_at_the_life_itself():
    """With adaptive steps the break lands on the closed-form life (relative 1e-9)."""
    model, loading = _bar(0.005)
    n_life = V5.phase_one_life(0.005)
    result = run_fatigue(model, loading, V5, CycleMapping(((5, 1.0 / (3 * n_life)),), adaptive=True))
    first = result.cycles[np.argmax(result.broken > 0)]
    assert first == pytest.approx(n_life, rel=1e-9)


def test_A_II_horizon_scaling_reproduces_the_thesis_value():
    """Eq. 7.15: 16 823 863 * 0.0015001^((4 - 2) / 2) = 25 237.48 (thesis table 7.1)."""
    hat = 16823863.0
    assert scale_A_II(hat, 1.0, 0.0015001, 4.0) == pytest.approx(25237.48, rel=1e-6)
    assert scale_A_II(25237.48, 0.0015001, 0.0006001, 4.0) == pytest.approx(hat * 0.0006001, rel=1e-6)


def test_crack_tip_needs_damage_through_the_whole_depth():
    """Section 7.2: the tip is the largest x whose whole column through z has phi >= 0.385."""
    body = geometry.box((0.010, 0.004, 0.003), SPACING)
    x, y, z = body.points.T
    phi = np.where((x < 0.006) & (y < 0.001), 0.5, 0.0)  # columns at x = 0.5 ... 5.5 mm
    assert crack_tip(body.points, phi, SPACING) == pytest.approx(0.0055, abs=1e-12)
    phi[(x > 0.004) & (x < 0.005) & (z < 0.001)] = 0.1  # a weak point behind the tip: no change
    assert crack_tip(body.points, phi, SPACING) == pytest.approx(0.0055, abs=1e-12)
    phi[(x > 0.005) & (z < 0.001)] = 0.1  # the 5.5 mm column is no longer cracked through
    assert crack_tip(body.points, phi, SPACING) == pytest.approx(0.0035, abs=1e-12)


def test_crack_tip_from_a_notch_root_inside_the_body_growing_towards_minus_x():
    """A crack that starts at a notch root inside the body (x = 8 mm) and grows towards -x has
    the length from the root to its farthest column cracked through the depth; columns on the
    other side of the root (the notch's own damaged rim) do not count; without a start the
    length runs from the edge the crack grows from (the high edge, 10 mm)."""
    body = geometry.box((0.010, 0.004, 0.003), SPACING)
    x, y, z = body.points.T
    phi = np.where((x > 0.005) & (y < 0.001), 0.5, 0.0)  # columns at x = 5.5 ... 9.5 mm
    assert crack_tip(body.points, phi, SPACING, start=0.008, sense="-") == pytest.approx(0.0025, abs=1e-12)
    assert crack_tip(body.points, phi, SPACING, sense="-") == pytest.approx(0.0045, abs=1e-12)
    assert crack_tip(body.points, np.where(x > 0.008, 0.5, 0.0), SPACING, start=0.008, sense="-") == 0.0
    with pytest.raises(InputError, match="sense must be"):
        crack_tip(body.points, phi, SPACING, sense="down")


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"A_I": -1.0}, "A_I must be positive"),
        ({"m_II": 0.0}, "m_II must be positive"),
        ({"eps_inf": -1e-3}, "eps_inf must be >= 0"),
        ({"phi_c": 1.5}, "phi_c must be in (0, 1]"),
    ],
)
def test_bad_parameters_are_refused(kwargs, message):
    values = dict(A_I=426.0, m_I=2.77, eps_inf=0.00186, A_II=25237.48, m_II=4.0) | kwargs
    with pytest.raises(InputError, match=message.replace("(", r"\(").replace(")", r"\)")):
        FatigueParameters(**values)


def test_bad_load_ratio_and_zero_load_are_refused():
    model, loading = _bar(0.004)
    with pytest.raises(InputError, match=r"load ratio R must be in \[-1, 1\), got 1.0"):
        run_fatigue(model, loading, V5, CycleMapping(((1, 1.0),)), load_ratio=1.0)
    model, loading = _bar(0.0)
    with pytest.raises(InputError, match="needs a cyclic load"):
        run_fatigue(model, loading, V5, CycleMapping(((1, 1.0),)))
    with pytest.raises(InputError, match="tau > 0"):
        CycleMapping(((3, 0.0),))
