"""K_I of the modelled single-edge-notch specimen from its compliance (V5, thesis eqs. 7.12-7.13).

The Paris slope of a fatigue run is m_II only against the specimen's own dK. These tests measure
K(a) of two 2D plane-stress LPS specimens by the compliance method (``fatigue.specimen``) and
compare it with eq. 7.12.
"""

import numpy as np
import pytest

from peridyn.discretization.bonds import crossing_segment
from peridyn.errors import InputError
from peridyn.fatigue.calibration import stress_intensity
from peridyn.fatigue.specimen import compliance_energy, compliance_stress_intensity
from peridyn.io.case import parse_yaml, validate_case
from peridyn.setup.build import build

E, STRESS, T = 189.9e9, 50e6, 3e-3


def _specimen(width, height, spacing):
    """2D SEN strip, 50 MPa as forces on the points within one horizon of the y faces."""
    band = 3.0005 * spacing
    force = STRESS * width * T
    raw = parse_yaml(f"""
name: sen_k
geometry: {{type: rectangle, size: [{width}, {height}], thickness: {T}, plane: stress}}
discretization: {{spacing: {spacing}, horizon: 3.0005}}
material: {{model: lps, E: {E}, nu: 0.3, density: 7850}}
node_sets:
  top: {{type: face, face: y+, depth: {band}}}
  bottom: {{type: face, face: y-, depth: {band}}}
boundary_conditions:
  - {{set: top, kind: force, components: y, value: {force}}}
  - {{set: bottom, kind: force, components: y, value: {-force}}}
solver: {{type: static}}
""")
    return build(validate_case(raw))


def _k_ratio(width, height, spacing, a_over_b):
    """K_compliance / K_eq7.12 at the crack lengths a_over_b * width."""
    s = _specimen(width, height, spacing)
    x, own, nb = s.body.points, s.bonds.owners(), s.bonds.neighbours
    a = np.asarray(a_over_b) * width

    def cut(length):
        return crossing_segment(x[own], x[nb], [-1.0, height / 2], [length, height / 2])

    before = s.bonds.intact.copy()
    k = compliance_stress_intensity(a, compliance_energy(s.model, s.loading, a, cut), T, E)
    assert np.array_equal(s.bonds.intact, before)  # the cuts are undone
    return a, k, k / stress_intensity(STRESS, a, width)


def test_tall_sen_strip_has_the_stress_intensity_of_eq_7_12():
    """A SEN strip 10 mm wide and 20 mm tall (load far from the crack, as eqs. 7.12-7.13 assume:
    Brown and Srawley's polynomial for a/b <= 0.6) at 0.5 mm spacing: the compliance K averaged
    over a/b = 0.25-0.45 is eq. 7.12's within 10 % (measured 1.07)."""
    _, _, ratio = _k_ratio(0.010, 0.020, 0.5e-3, np.arange(0.20, 0.501, 0.05))
    assert np.mean(ratio[1:-1]) == pytest.approx(1.0, abs=0.10)


def test_thesis_sen_geometry_is_not_the_eq_7_12_specimen():
    """The thesis's 50 x 8 mm specimen, loaded on its long faces 4 mm from the crack, bends its two
    arms like cantilevers under a uniform load q = sigma t: Euler-Bernoulli beam theory gives
    G = 3 sigma^2 a^4 / (E h^3) (h = 4 mm), K = sqrt(3) sigma a^2 / h^1.5, growing as a^2, while
    eq. 7.12 grows as a^0.82 over a = 6-14 mm. At 1 mm spacing the compliance K is 3.7-6.4 times
    eq. 7.12 and grows as a^1.5 (0.2 mm spacing, 2D: a^1.57, 3-5.5 times): plotted against eq. 7.12
    a Paris law of exponent 4 shows a slope near 4 x 1.9 = 7.6."""
    a, k, ratio = _k_ratio(0.050, 0.008, 1e-3, np.arange(0.12, 0.281, 0.02))
    assert np.all(ratio > 3.0)
    growth = np.polyfit(np.log(a), np.log(k), 1)[0]
    assert 1.3 < growth < 2.0  # beam limit 2 (a >> h); eq. 7.12: 0.82
    h = 0.004
    k_beam = np.sqrt(3.0) * STRESS * a**2 / h**1.5  # root rotation only adds compliance
    assert np.all(k > 0.9 * k_beam)


def test_compliance_k_needs_increasing_crack_lengths():
    s = _specimen(0.010, 0.020, 1e-3)
    with pytest.raises(InputError, match="at least 3 increasing crack lengths"):
        compliance_energy(s.model, s.loading, [2e-3, 1e-3, 3e-3], lambda a: np.zeros(1, bool))


def test_straight_crack_cut_lengthens_a_2d_segment_precrack():
    """The pre-crack of a 2D case (a segment given by two coordinates) lengthened to a cuts the
    bonds crossing y = H/2 at x < a (crack length from the low edge), and no others. Booleans, compared
    exactly: no point lies on y = H/2 and no bond crosses it near x = 4.2 mm."""
    from peridyn.fatigue.specimen import straight_crack_cut
    from peridyn.io.case import Precrack

    s = _specimen(0.010, 0.020, 1e-3)
    x, own, nb = s.body.points, s.bonds.owners(), s.bonds.neighbours
    crack = Precrack(type="segment", start=[-0.001, 0.010], end=[0.002, 0.010])
    cut = straight_crack_cut(x, 1e-3, s.bonds, crack, 0)(4.2e-3)  # no bond crosses at x = 4.2 mm
    y0, y1 = x[own, 1], x[nb, 1]
    across = (y0 - 0.010) * (y1 - 0.010) < 0
    x_cross = x[own, 0] + (0.010 - y0) / (y1 - y0 + ~across) * (x[nb, 0] - x[own, 0])
    assert cut.sum() > 0 and np.array_equal(cut, across & (x_cross < 4.2e-3))
