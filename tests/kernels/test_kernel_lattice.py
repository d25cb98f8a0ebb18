"""Lattice kernels (``peridyn.kernels.lattice``) against their NumPy references, and lattice
storage against bond lists on the same bodies (grids with holes and pre-cracks).

Tolerances: kernels vs references as ``kernel_inputs`` (1e-12 float64, 1e-5 float32, of the
sum of the terms' magnitudes). Lattice vs bond lists: the two store the reference bond
differently (per offset ``o h``, per bond ``x_j - x_i`` of rounded coordinates, differing by
~1e-16 of the coordinates), so forces agree to round-off, not bit for bit: 1e-12 of the largest
force at bond strains ~1e-3 (the acceptance of lattice storage).
"""

import numba
import numpy as np
import pytest
from kernel_inputs import TOL, assert_close

from peridyn.discretization import geometry
from peridyn.discretization.bonds import crossing_rectangle, crossing_segment, cut_bonds, find_bonds
from peridyn.discretization.lattice import build_lattice, cut_lattice, make_stencil
from peridyn.kernels import lattice as kern
from peridyn.kernels.reference import lattice as ref
from peridyn.physics.damage import BondDamage
from peridyn.physics.lattice_damage import LatticeDamage
from peridyn.physics.materials import make_model
from peridyn.physics.materials.lattice import make_lattice_model
from peridyn.solvers.explicit import ExplicitSolver

pytestmark = pytest.mark.kernels

DTYPES = [np.float64, np.float32]
H = 1e-3
#: Lattice against bond lists: relative to the largest force (module docstring).
STORAGE_RTOL = 1e-12


def _grid(rng, dtype, shape=(6, 5, 4), horizon=2.015):
    """A small lattice: random holes, random broken bonds (both bits of each, as the lattice
    keeps them: the pair kernels read one end's), displacement of strain ~1e-3."""
    spacing = np.array([H, 1.1 * H, 0.9 * H])
    stencil = make_stencil(spacing, horizon * H, 3)
    n = int(np.prod(shape))
    vol = np.where(rng.random(n) < 0.15, 0.0, spacing.prod()).astype(dtype)
    broken = np.zeros((-(-stencil.size // 64), n), dtype=np.uint64)
    g = np.arange(n)
    at = np.stack([g % shape[0], (g // shape[0]) % shape[1], g // (shape[0] * shape[1])], axis=1)
    for k, o in enumerate(stencil.offsets):
        far = at + o
        cut = np.all((far >= 0) & (far < shape), axis=1) & (rng.random(n) < 0.05)
        j = (far[cut, 2] * shape[1] + far[cut, 1]) * shape[0] + far[cut, 0]
        r = stencil.reverse[k]
        broken[k // 64, g[cut]] |= np.uint64(1) << np.uint64(k % 64)
        broken[r // 64, j] |= np.uint64(1) << np.uint64(r % 64)
    u = (rng.normal(size=(3, n)) * 1e-3 * H).astype(dtype)
    return np.array(shape, dtype=np.int64), stencil, vol, broken, u


def _written_rows(rng, vol):
    """(n_grid,) int32 rows of the force kernels' output: the grid points with material in a
    random order, -1 (not written) for holes; and an output of NaN, (n_grid, 3)."""
    point_of = rng.permutation(vol.size).astype(np.int32)
    point_of[vol == 0] = -1
    return point_of, np.full((vol.size, 3), np.nan, dtype=vol.dtype)


def _grid_order(point_of, f):
    """The kernels' output ``f`` (n_out, 3) back in grid order, (3, n_grid): NaN for holes,
    which must be left unwritten."""
    at_grid = np.full((3, len(point_of)), np.nan, dtype=f.dtype)
    at_grid[:, point_of >= 0] = f[point_of[point_of >= 0]].T
    written = np.zeros(len(f), dtype=bool)
    written[point_of[point_of >= 0]] = True
    assert np.isnan(f[~written]).all(), "a row no grid point maps to was written"
    return at_grid


def _tables(stencil, dtype):
    return stencil.xi.astype(dtype), stencil.length.astype(dtype)


def _magnitude(vol, broken, shape, offs, per_bond):
    """(n_grid,) sum over each point's counted bonds of |term| (the scale of a comparison)."""
    p, _, _, ok = ref.lattice_bonds(vol, broken, shape, offs)
    return np.bincount(p, np.where(ok, np.abs(per_bond), 0.0), minlength=np.asarray(vol).size)


@pytest.mark.parametrize("dtype", DTYPES)
def test_lattice_pmb_force_matches_reference(rng, dtype):
    """c V_j (1/|xi| - 1/|Y|) Y summed over counted bonds; both forms round relative to k |Y| / |xi|."""
    shape, s, vol, broken, u = _grid(rng, dtype)
    xi, length = _tables(s, dtype)
    coef = (1e20 * s.influence * s.volume_factor).astype(dtype)
    point_of, out = _written_rows(rng, vol)
    cf = dtype == np.float32
    kern.lattice_pmb_force(
        u, vol, broken, shape, s.offsets, *kern.pair_offsets(s.offsets), xi, length,
        (1 / length).astype(dtype), coef, cf, np.empty((3, vol.size), dtype), point_of, out,
    )  # fmt: skip
    f = _grid_order(point_of, out)
    expected = ref.lattice_pmb_force(u, vol, broken, shape, s.offsets, xi, length, coef, cf)
    p, q, k, _ = ref.lattice_bonds(vol, broken, shape, s.offsets)
    scale = _magnitude(
        vol, broken, shape, s.offsets, coef[k] * vol[q] * np.linalg.norm(xi[k], axis=1) / length[k]
    )
    assert f.dtype == dtype
    held = vol > 0
    assert_close(f.T[held], expected.T[held], TOL[dtype], scale[held])


@pytest.mark.parametrize("dtype", DTYPES)
def test_lattice_lps_dilatation_and_force_match_reference(rng, dtype):
    """theta and the pair force sum w |xi| (P_i + P_j) + w (alpha_i + alpha_j) e over counted bonds."""
    shape, s, vol, broken, u = _grid(rng, dtype)
    xi, length = _tables(s, dtype)
    weight = (s.influence * s.volume_factor).astype(dtype)
    n = vol.size
    cf = dtype == np.float32
    theta_coef = (rng.random(n) * 3e14).astype(dtype)
    pairs = kern.pair_offsets(s.offsets)
    theta = kern.lattice_lps_dilatation(
        u, vol, broken, shape, s.offsets, *pairs, xi, length, weight, cf, theta_coef, np.empty(n, dtype)
    )
    expected = ref.lattice_lps_dilatation(
        u, vol, broken, shape, s.offsets, xi, length, weight, theta_coef, cf
    )
    p, q, k, _ = ref.lattice_bonds(vol, broken, shape, s.offsets)
    w = weight[k].astype(np.float64) * vol[q]
    y = xi[k].astype(np.float64) + (u[:, q] - u[:, p]).T.astype(np.float64)
    extension = np.linalg.norm(y, axis=1) - length[k]
    scale = theta_coef * _magnitude(vol, broken, shape, s.offsets, w * length[k] * extension)
    held = vol > 0  # a hole's sums count no pair (the model's coefficients are 0 there)
    assert_close(theta[held], expected[held], TOL[dtype], scale[held])
    assert not theta[~held].any()
    alpha = (rng.random(n) * 1e25).astype(dtype)
    pressure = (rng.normal(size=n) * 1e22).astype(dtype)
    point_of, out = _written_rows(rng, vol)
    kern.lattice_lps_force(
        u, vol, broken, shape, s.offsets, *pairs, xi, length, weight, cf, alpha, pressure,
        np.empty((3, n), dtype), point_of, out,
    )  # fmt: skip
    f = _grid_order(point_of, out)
    expected = ref.lattice_lps_force(
        u, vol, broken, shape, s.offsets, xi, length, weight, alpha, pressure, cf
    )
    size = w * (
        length[k] * (np.abs(pressure[p]) + np.abs(pressure[q])) + (alpha[p] + alpha[q]) * np.abs(extension)
    )
    scale = _magnitude(vol, broken, shape, s.offsets, size)
    assert_close(f.T[held], expected.T[held], TOL[dtype], scale[held])


def test_pair_kernels_give_the_same_bits_on_any_number_of_threads(rng):
    """Each point adds its pairs in an order set by the grid and the stencil alone (slabs of y
    planes, the even ones then the odd ones: ``kernels.lattice``), so the PMB force, the LPS
    dilatation and the LPS force are the same bits on 1, 2 and 3 numba threads (7 slabs)."""
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one numba thread available: nothing to compare")
    shape, s, vol, broken, u = _grid(rng, np.float64, shape=(8, 13, 6))
    xi, length = _tables(s, np.float64)
    pairs = kern.pair_offsets(s.offsets)
    assert pairs[1] == 2 and -(-13 // pairs[1]) == 7
    n = vol.size
    weight = s.influence * s.volume_factor
    alpha, theta_coef = rng.random(n) * 1e25, rng.random(n) * 3e14
    point_of, _ = _written_rows(rng, vol)
    head = (u, vol, broken, shape, s.offsets, *pairs, xi, length)

    def evaluate():
        pmb = kern.lattice_pmb_force(
            *head, 1 / length, 1e20 * weight, False, np.empty((3, n)), point_of, np.full((n, 3), np.nan)
        )
        theta = kern.lattice_lps_dilatation(*head, weight, False, theta_coef, np.empty(n))
        lps = kern.lattice_lps_force(
            *head, weight, False, alpha, 1e8 * theta, np.empty((3, n)), point_of, np.full((n, 3), np.nan)
        )
        return pmb, theta, lps

    before = numba.get_num_threads()
    try:
        results = []
        for threads in range(1, min(3, numba.config.NUMBA_NUM_THREADS) + 1):
            numba.set_num_threads(threads)
            results.append(evaluate())
    finally:
        numba.set_num_threads(before)
    for other in results[1:]:
        for a, b in zip(results[0], other, strict=True):
            np.testing.assert_array_equal(a, b)


def test_lattice_sums_and_energy_match_reference(rng):
    """The set-up sums (intact or every bond, pair sums) and the energy sums, float64."""
    shape, s, vol, broken, u = _grid(rng, np.float64)
    n = vol.size
    coef = s.influence * s.length**2
    for every in (False, True):
        got = kern.lattice_bond_sum(vol, broken, shape, s.offsets, coef, every, np.empty(n))
        expected = ref.lattice_bond_sum(vol, broken, shape, s.offsets, coef, every)
        assert_close(got, expected, TOL[np.float64], np.abs(expected))
    a, b = rng.random(n), rng.random(n)
    got = kern.lattice_pair_sum(vol, broken, shape, s.offsets, coef, a, b, np.empty(n))
    expected = ref.lattice_pair_sum(vol, broken, shape, s.offsets, coef, a, b)
    assert_close(got, expected, TOL[np.float64], np.abs(expected))
    theta = rng.normal(size=n) * 1e-3
    got = kern.lattice_energy_sum(
        u, vol, broken, shape, s.offsets, s.xi, s.length, coef, theta, 3.0, np.empty(n)
    )
    expected = ref.lattice_energy_sum(u, vol, broken, shape, s.offsets, s.xi, s.length, coef, theta, 3.0)
    # each square's extension |Y| - |xi| ~ 1e-3 |xi| keeps ~1e-13 of its value: TOL64 of the sum
    assert_close(got, expected, TOL[np.float64], np.abs(expected))


def test_lattice_stretch_test_and_scatter_match_reference(rng):
    """Bonds past |xi| (1 + s_c) break from both ends; unbreakable points keep theirs; the room
    left per row is the smallest over the bonds left intact."""
    shape, s, vol, broken, u = _grid(rng, np.float64)
    n = vol.size
    limit = s.length * (1 + 1e-3)
    breakable = rng.random(n) > 0.1
    expected, count, room = ref.lattice_stretch_test(u, vol, broken, shape, s.offsets, s.xi, limit, breakable)
    got = broken.copy()
    rows = int(shape[1] * shape[2])
    got_room = np.empty(rows)
    args = (limit, breakable, np.empty(rows, dtype=np.int64), got_room)
    assert kern.lattice_stretch_test(u, vol, got, shape, s.offsets, s.xi, *args) == count
    assert count > 0
    np.testing.assert_array_equal(got, expected)
    np.testing.assert_array_equal(got_room, room)  # the same subtractions of the same |Y|
    index = rng.permutation(n)[: n // 2]
    up = rng.normal(size=(len(index), 3))
    ug = kern.lattice_scatter(up, index, np.zeros((3, n)))
    np.testing.assert_array_equal(ug, ref.lattice_scatter(up, index, n))


# -- lattice storage against bond lists on the same body ------------------------------------


def _box_with_hole_and_crack():
    """A 10 x 9 x 7 box at 1 mm with a spherical hole and a rectangular pre-crack."""
    body = geometry.box((0.010, 0.009, 0.007), H)
    body = body.remove(lambda x: np.sum((x - [0.0055, 0.0045, 0.0035]) ** 2, axis=1) < 0.0013**2)
    return body, lambda a, b: crossing_rectangle(a, b, (0.0025, -1, -1), (0, 3, 0), (0, 0, 3))


def _surface_plate():
    """The seed plate's layout: 3 surface layers 1 mm apart, 0.8 mm in plane, a crack segment."""
    body = geometry.plate(0.0096, 0.0064, 0.002, spacing=0.8e-3, layers=3, layer_placement="surface")
    return body, lambda a, b: crossing_rectangle(a, b, (0.0048, 0.0, -1), (0, 0.0032, 0), (0, 0, 3))


def _rectangle_2d():
    """A plane-stress rectangle with a centre slit."""
    body = geometry.rectangle(0.014, 0.010, H, 0.001)
    return body, lambda a, b: crossing_segment(a, b, (0.007, 0.003), (0.007, 0.007))


BODIES = {
    "box_hole_crack": _box_with_hole_and_crack,
    "surface_plate": _surface_plate,
    "rectangle": _rectangle_2d,
}


def _both(make, name, partial_volumes, dtype=np.float64):
    """(body, bond-list model, lattice model, (bonds cut, lattice bonds cut)); ``name`` a
    material, or ``material/surface correction``."""
    name, _, correction = name.partition("/")
    body, crossing = make()
    horizon = 3.015 * body.spacing
    bonds = find_bonds(body, horizon, partial_volumes=partial_volumes)
    lattice = build_lattice(body, horizon, partial_volumes=partial_volumes)
    cut = (cut_bonds(body, bonds, crossing), cut_lattice(body, lattice, crossing))
    kw = {"E": 70e9, "density": 2700.0, "nu": None if name == "pmb" else 0.3, "dtype": dtype}
    kw["surface_correction"] = correction or "none"
    return body, make_model(name, body, bonds, **kw), make_lattice_model(name, body, lattice, **kw), cut


@pytest.mark.parametrize("dtype", DTYPES)
def test_explicit_solver_forces_into_the_acceleration_when_the_model_can(rng, dtype):
    """A float64 lattice force writes every body point's row of its output (no NaN left), so the
    explicit solver hands it the state's acceleration and keeps no force array (24 B a point);
    not in float32 (the state is float64) nor on bond lists (``force_overwrites_out`` False)."""
    body, bonded, latticed, _ = _both(BODIES["box_hole_crack"], "pmb", False, dtype)
    f = latticed.force(
        rng.normal(size=(body.n_points, 3)) * 1e-3 * body.spacing, np.full_like(latticed.x, np.nan)
    )
    assert np.isfinite(f).all()
    assert latticed.force_fills_acceleration == (dtype == np.float64)
    assert not bonded.force_fills_acceleration
    for model in (bonded, latticed):
        assert (ExplicitSolver(model)._force is None) == model.force_fills_acceleration


@pytest.mark.parametrize("which", sorted(BODIES))
def test_owned_bond_counts_match_bond_lists(which):
    """What a run's summary counts of a rank's owned points (the first n body points): their
    directed bonds and the broken ones (the pre-crack's), the same on both storages for any n."""
    body, bonded, latticed, _ = _both(BODIES[which], "pmb", False)
    for n in (0, body.n_points // 3, body.n_points):
        assert latticed.lattice.owned_bond_counts(n) == bonded.bonds.owned_bond_counts(n)
    assert latticed.lattice.owned_bond_counts(body.n_points) == (
        bonded.bonds.n_bonds,
        latticed.lattice.n_broken(),
    )
    assert latticed.lattice.n_broken() > 0


@pytest.mark.parametrize("partial_volumes", [False, True])
@pytest.mark.parametrize("material", ["pmb", "lps", "lps/shear-factor"])
@pytest.mark.parametrize("which", sorted(BODIES))
def test_lattice_storage_matches_bond_lists(rng, which, material, partial_volumes):
    """Same bonds, same cut bonds; force, energy density and stiffness bound within round-off."""
    body, bonded, latticed, (cut_b, cut_l) = _both(BODIES[which], material, partial_volumes)
    assert latticed.lattice.n_bonds == bonded.bonds.n_bonds
    np.testing.assert_array_equal(latticed.lattice.family_sizes(), np.diff(bonded.bonds.offsets))
    assert cut_l == cut_b > 0
    u = rng.normal(size=(body.n_points, 3)) * 1e-3 * body.spacing
    if body.dim == 2:
        u[:, 2] = 0.0
    # the shear-factor tests shear by 1e-6, where |Y| - |xi| keeps ~1e-16 / 1e-6 of itself: each
    # storage's factors carry ~1e-10 of rounding, which scales the deviatoric forces
    factor = np.abs(latticed.shear_factor / bonded.shear_factor - 1).max() if "shear" in material else 0.0
    assert factor <= 1e-9
    rtol = STORAGE_RTOL + factor
    f = bonded.force(u)
    assert np.abs(latticed.force(u) - f).max() <= rtol * np.abs(f).max()
    w = bonded.energy_density(u)
    assert np.abs(latticed.energy_density(u) - w).max() <= rtol * np.abs(w).max()
    bound = bonded.stiffness_bound()
    assert np.abs(latticed.stiffness_bound() - bound).max() <= rtol * bound.max()
    np.testing.assert_allclose(latticed.damage_index(), bonded.damage_index(), rtol=0, atol=1e-14)
    assert latticed.critical_stretch(100.0) == bonded.critical_stretch(100.0)


def test_lattice_float32_force_is_the_float64_force_in_float32(rng):
    """float32 (cancellation-free) against float64 lattice forces: float32 rounding of the
    terms (TOL32 of the largest force) at strain 1e-3."""
    body, crossing = _box_with_hole_and_crack()
    lattice = build_lattice(body, 3.015 * H)
    kw = {"E": 70e9, "density": 2700.0, "nu": 0.3}
    u = rng.normal(size=(body.n_points, 3)) * 1e-3 * H
    f64 = make_lattice_model("lps", body, lattice, **kw).force(u)
    f32 = make_lattice_model("lps", body, lattice, dtype=np.float32, **kw).force(u)
    assert f32.dtype == np.float32
    assert np.abs(f32 - f64).max() <= TOL[np.float32] * np.abs(f64).max()


def _broken_pairs_bonds(model):
    b = model.bonds
    owners = b.owners()
    return {(int(i), int(j)) for i, j in zip(owners[~b.intact], b.neighbours[~b.intact], strict=True)}


def _broken_pairs_lattice(model):
    lat = model.lattice
    p, q, _, ok = ref.lattice_bonds(lat.volume, lat.broken, lat.shape, lat.stencil.offsets)
    point_of = np.full(lat.n_grid, -1)
    point_of[lat.grid_index] = np.arange(lat.n_points)
    return {(int(i), int(j)) for i, j in zip(point_of[p[~ok]], point_of[q[~ok]], strict=True)}


def test_lattice_damage_breaks_the_bonds_bond_lists_break(rng):
    """A stretched box with a hole: the same directed bonds break at critical stretch 2e-3 (a
    bond whose stretch lies within 1e-12 of it may differ by round-off: it is named)."""
    body, bonded, latticed, _ = _both(_box_with_hole_and_crack, "pmb", True)
    u = np.zeros((body.n_points, 3))
    u[:, 0] = 3e-3 * body.points[:, 0] + rng.normal(size=body.n_points) * 1e-3 * H
    got = LatticeDamage(latticed, critical_stretch=2e-3).update(u)
    expected = BondDamage(bonded, critical_stretch=2e-3).update(u)
    differ = _broken_pairs_bonds(bonded) ^ _broken_pairs_lattice(latticed)
    near = []
    for i, j in differ:
        stretch = (
            np.linalg.norm(body.points[j] + u[j] - body.points[i] - u[i])
            / np.linalg.norm(body.points[j] - body.points[i])
            - 1
        )
        near.append(abs(stretch - 2e-3) <= 1e-12)
    assert all(near), f"bonds broken by one storage only, not at their threshold: {sorted(differ)}"
    assert got > 0 and abs(got - expected) == len(differ)
    np.testing.assert_allclose(latticed.damage_index(), bonded.damage_index(), rtol=0, atol=1e-14)


def test_lattice_damage_skips_only_tests_that_break_nothing(rng):
    """Over a loading history, the damage that skips tests while no point has moved half the
    room breaks the same bits at the same calls as one that tests every bond at every call."""
    body, _, latticed, _ = _both(_box_with_hole_and_crack, "pmb", False)
    _, _, other, _ = _both(_box_with_hole_and_crack, "pmb", False)
    skin, every = LatticeDamage(latticed, critical_stretch=2e-3), LatticeDamage(other, critical_stretch=2e-3)
    noise = rng.normal(size=(body.n_points, 3)) * 1e-4 * H
    for t in np.linspace(0.0, 1.0, 40):
        u = t * (np.array([3e-3, 0.0, 0.0]) * body.points + noise)
        every.reset()
        assert skin.update(u) == every.update(u)
    np.testing.assert_array_equal(latticed.lattice.broken, other.lattice.broken)
    assert latticed.lattice.n_broken() > 0 and skin.full_tests < every.full_tests
