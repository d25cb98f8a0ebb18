"""Other decks of Peridigm's test suite (tests/data/peridigm_other, sources in its README):
those peridyn runs, each checked against an independent fact of the physics it was built to
verify; the others refused with a CaseFileError naming the deck parameter that peridyn cannot
run, before any mesh is looked for (docs/peridigm.md lists them)."""

import dataclasses
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from exodiff_comp import compare_meshes
from test_peridigm_decks import DATA, run_deck

from peridyn.errors import CaseFileError
from peridyn.io.exodus import read_exodus
from peridyn.io.exodus_write import ExodusWriter
from peridyn.io.peridigm_case import convert_deck
from peridyn.io.peridigm_deck import read_deck

OTHER = Path(__file__).parents[1] / "data" / "peridigm_other"


def pair_frequency(bulk: float, density: float, length: float) -> float:
    """Angular frequency (rad/s) of the stretch e of two LPS points joined by one bond of
    ``length`` L (m) and nothing else: each has m = L^2 V and dilatation theta = 3 e / L, so
    the deviatoric extension is 0 and the bond's force density on each is 2 (3 K theta L / m) V
    = 18 K e / L^2 (Peridigm's ``computeInternalForceLinearElastic``, omega = 1); the points
    move apart with e'' = -36 K e / (rho L^2)."""
    return math.sqrt(36.0 * bulk / (density * length**2))


def test_bond_breaking_initial_velocity(tmp_path):
    """Peridigm's BondBreakingInitialVelocity (older deck form): two vertical pairs of points,
    L = 1 m apart along y (the box families of horizon 0.51 m reach one cell along y and none
    along x, spacing 1.05 m), pulled apart at +-v. A pair's stretch is e/L = (2 v / omega L)
    sin(omega t): the critical stretch s_c = 0.02 is reached for v > v_c = omega L s_c / 2 =
    244.949 m/s, which the deck brackets with 244.939 m/s (the pair at x = 0.525 m holds) and
    244.959 m/s (the pair at x = 1.575 m breaks at t_b = asin(v_c / v) / omega = 63.8 us, and
    flies apart at sqrt(v^2 - v_c^2), energy conservation).

    Tolerances: Verlet at omega dt = 2.4e-4 has amplitude and phase errors of (omega dt)^2
    ~ 6e-8 relative over the run (rtol 1e-6); the break is found within one step of the
    crossing, in which the speed changes by at most the acceleration at the critical stretch,
    omega^2 L s_c / 2, times dt."""
    deck = read_deck(OTHER / "BondBreakingInitialVelocity.xml")
    material = deck["Materials"]["My Linear Elastic Material"]
    bulk, density = material["Bulk Modulus"], material["Density"]
    stretch = deck["Damage Models"]["My Critical Stretch Damage Model"]["Critical Stretch"]
    dt = deck["Solver"]["Verlet"]["Fixed dt"]
    length = 1.0
    omega = pair_frequency(bulk, density, length)
    v_c = omega * length * stretch / 2
    speeds = {0.525: 244.939, 1.575: 244.959}  # the deck's Initial Velocity values by column x
    assert speeds[0.525] < v_c < speeds[1.575]

    out = read_exodus(run_deck(OTHER / "BondBreakingInitialVelocity.xml", tmp_path))
    t = out.times
    uy, vy = out.nodal_variables["DisplacementY"], out.nodal_variables["VelocityY"]
    damage, theta = out.element_variables["Damage"], out.element_variables["Dilatation"]
    np.testing.assert_allclose(out.element_variables["Weighted_Volume"], length**2 * 1.05, rtol=1e-14)
    x, y = out.coordinates[:, 0], out.coordinates[:, 1]
    for column, v in speeds.items():
        points = np.flatnonzero(np.isclose(x, column))
        sign = np.where(y[points] > 1.0, 1.0, -1.0)  # the upper point moves up
        assert len(points) == 2
        intact = np.ones(len(t), bool) if v < v_c else t < math.asin(v_c / v) / omega
        expected = np.outer((v / omega) * np.sin(omega * t[intact]), np.ones(2))
        np.testing.assert_allclose(uy[intact][:, points] * sign, expected, rtol=1e-6, atol=0)
        np.testing.assert_allclose(theta[intact][:, points], 3 * 2 * expected / length, rtol=1e-6)
        assert np.all(damage[intact][:, points] == 0)
        if v < v_c:
            continue
        assert not intact[-1] and np.all(damage[~intact][:, points] == 1)
        v_free = math.sqrt(v**2 - v_c**2)
        np.testing.assert_allclose(vy[~intact][:, points] * sign, v_free, rtol=0, atol=omega * v_c * dt)


def test_compression_init_disp_2x1x1(tmp_path):
    """Peridigm's CompressionInitDisp_2x1x1 (older deck form): two points L = 2 m apart (x),
    displaced by +-1e-5 m towards each other and let go. Velocity Verlet on the pair's stretch
    e'' = -omega^2 e (``pair_frequency``) gives exactly e_n = e_0 cos(n phi) with cos phi =
    1 - (omega dt)^2 / 2 (from e_0 at rest, e_1 = e_0 (1 - (omega dt)^2 / 2), then the central
    difference), and the rates by the trapezoidal sums of a_n = -omega^2 e_n; the force
    density is rho a / 2 on each point, the dilatation 3 e / L and the weighted volume L^2 V,
    V = 2 m^3. The whole run is linear in e (the bond stays on the x axis), so only round-off
    separates the run from these: the extension |y| - |xi| of the 2 m bond shortened by 2e-5 m
    carries one rounding of |y| (eps |xi| = 4.4e-16 m), 2.2e-11 of itself (rtol 1e-10)."""
    deck = read_deck(OTHER / "CompressionInitDisp_2x1x1.xml")
    material = deck["Materials"]["My Elastic Material"]
    dt, density, length, volume = deck["Solver"]["Verlet"]["Fixed dt"], material["Density"], 2.0, 2.0
    omega = pair_frequency(material["Bulk Modulus"], density, length)
    out = read_exodus(run_deck(OTHER / "CompressionInitDisp_2x1x1.xml", tmp_path))
    steps = np.arange(len(out.times))
    np.testing.assert_allclose(out.times, steps * dt, rtol=1e-12)
    phi = math.acos(1 - (omega * dt) ** 2 / 2)
    e = -2e-5 * np.cos(steps * phi)  # the deck's +-1e-5 m: the pair starts 2e-5 m short
    a = -(omega**2) * e
    rate = np.concatenate([[0.0], np.cumsum(dt / 2 * (a[:-1] + a[1:]))])
    right = np.argmax(out.coordinates[:, 0])  # the point at x = +1 m moves with +e/2
    sign = np.where(np.arange(2) == right, 1.0, -1.0)
    for name, expected in (("Displacement", e / 2), ("Velocity", rate / 2), ("Acceleration", a / 2)):
        got = out.nodal_variables[f"{name}X"]
        np.testing.assert_allclose(
            got * sign, np.outer(expected, [1, 1]), rtol=1e-10, atol=1e-25, err_msg=name
        )
    np.testing.assert_allclose(
        out.nodal_variables["Force_DensityX"] * sign, np.outer(density * a / 2, [1, 1]), rtol=1e-10
    )
    np.testing.assert_allclose(
        out.element_variables["Dilatation"], np.outer(3 * e / length, [1, 1]), rtol=1e-10
    )
    np.testing.assert_allclose(out.element_variables["Weighted_Volume"], length**2 * volume, rtol=1e-14)
    assert out.element_variables["ID"].tolist() == [[0.0, 1.0]] * len(steps)


def reordered(mesh, order: np.ndarray):
    """An Exodus file read (``read_exodus``, one element per point) with its points in ``order``."""
    return dataclasses.replace(
        mesh,
        coordinates=mesh.coordinates[order],
        nodal_variables={k: v[:, order] for k, v in mesh.nodal_variables.items()},
        element_variables={k: v[:, order] for k, v in mesh.element_variables.items()},
    )


def test_compression_qs_3x2x2_matches_its_text_file_twin(tmp_path):
    """Peridigm's Compression_QS_3x2x2 (older deck form: PdQuickGrid, 0-based node ids) is the
    problem of its twin Compression_QS_3x2x2_TextFile (the same 12 points, unit volumes,
    horizon, spherical families, material, node sets and quasi-static load steps, on a text
    mesh): its result matches the twin's gold file (Peridigm's, tests/data/peridigm), point by
    point once the points are matched by their coordinates, within the twin's exodiff
    tolerances (Compression_QS_3x2x2_TextFile.comp)."""
    twin = DATA / "Compression_QS_3x2x2_TextFile"
    gold = read_exodus(twin / "Compression_QS_3x2x2_TextFile_gold.e")
    mine = read_exodus(run_deck(OTHER / "Compression_QS_3x2x2.xml", tmp_path))
    distance = np.linalg.norm(gold.coordinates[:, None, :] - mine.coordinates[None, :, :], axis=2)
    order = np.argmin(distance, axis=1)
    assert sorted(order.tolist()) == list(range(12)) and np.all(distance.min(axis=1) < 1e-12)
    excess = compare_meshes(gold, reordered(mine, order), twin / "Compression_QS_3x2x2_TextFile.comp")
    assert set(excess) >= {"DisplacementX", "VelocityX", "Force_DensityX", "Dilatation", "Weighted_Volume"}
    assert {k: v for k, v in excess.items() if v > 0} == {}


def one_layer_mesh(path: Path) -> None:
    """The mesh of Peridigm's ElasticBondBased2D.jou (its .g is binary and not available): a bar
    1 m (x) by 6 m (y) by 0.25 m (z) of 0.25 m cubes in one layer, blocks 1, 2 and 3 its lower
    1.5 m, middle 3 m and upper 1.5 m, node set 1 all of it; written with peridyn's writer as
    Peridigm makes points of hexes, one per cube at its centre with its volume."""
    side = 0.25
    x, y = np.meshgrid(np.arange(-0.375, 0.5, side), np.arange(-2.875, 3.0, side), indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    y = points[:, 1]
    blocks = [
        (1, "block_1", np.flatnonzero(y < -1.5)),
        (2, "block_2", np.flatnonzero(np.abs(y) < 1.5)),
        (3, "block_3", np.flatnonzero(y > 1.5)),
    ]
    n = len(points)
    all_points = {"nodelist_1": np.arange(n)}
    ExodusWriter(path, points, blocks, all_points, volumes=np.full(n, side**3)).append(0.0)


@pytest.mark.parametrize("plane", ["Stress", "Strain"])
def test_elastic_bond_based_2d(tmp_path, plane):
    """Peridigm's ElasticBondBased2DPlane{Stress,Strain} on its mesh (``one_layer_mesh``): every
    point is given u = (0, 0.001 y t / 1e-8); the reported sums of the force (N) over blocks 3
    and 1 (Top_ and Bottom_Reaction_Force) are those of Peridigm's 2D bond-based force, computed
    here from its source (``computeInternalForceElasticBondBased``: c = 12 K / (pi h delta^3),
    in plane stress and plane strain alike, f = c s V_j along the deformed bond for
    |xi| <= delta, force = f V_i), to round-off (rtol 1e-12); the two sums are opposite, pull
    the stretched ends back towards the middle, and have no x component (the bar's symmetries)."""
    deck_path = tmp_path / f"ElasticBondBased2DPlane{plane}.yaml"
    shutil.copy(OTHER / deck_path.name, deck_path)
    one_layer_mesh(tmp_path / "ElasticBondBased2D.g")
    material = read_deck(deck_path)["Materials"]["My Elastic Bond Based Material"]
    bulk, height, horizon = material["Bulk Modulus"], material["Height"], 0.751
    out = read_exodus(run_deck(deck_path, tmp_path / "out"))
    mesh = read_exodus(tmp_path / "ElasticBondBased2D.g")
    x, volume = mesh.coordinates[:, :2], mesh.blocks[0].attributes[0, 1]
    xi = x[None, :, :] - x[:, None, :]
    length = np.linalg.norm(xi, axis=2)
    bonded = (length > 0) & (length <= horizon)
    c = 12.0 * bulk / (math.pi * height * horizon**3)
    for k, t in enumerate(out.times):
        u = np.column_stack([np.zeros(len(x)), 0.001 * x[:, 1] * t / 1.0e-8])
        eta = xi + u[None, :, :] - u[:, None, :]
        deformed = np.linalg.norm(eta, axis=2)
        stretch = np.where(bonded, deformed - length, 0.0) / np.where(bonded, length, 1.0)
        pull = np.where(bonded, c * stretch * volume / np.where(bonded, deformed, 1.0), 0.0)
        force = np.einsum("ij,ijk->ik", pull, eta) * volume
        for label, block in (("Top", "block_3"), ("Bottom", "block_1")):
            (members,) = [b for b in mesh.blocks if b.name == block]
            expected = force[members.connectivity[:, 0]].sum(axis=0)
            got = np.array([out.global_variables[f"{label}_Reaction_Force{a}"][k] for a in "XY"])
            np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12 * abs(expected[1]) + 1e-300)
    top, bottom = (out.global_variables[f"{label}_Reaction_ForceY"][-1] for label in ("Top", "Bottom"))
    assert top < 0 and abs(top + bottom) <= 1e-12 * abs(top)
    assert abs(out.global_variables["Top_Reaction_ForceX"][-1]) <= 1e-12 * abs(top)


@pytest.mark.parametrize(
    "deck, key, value",
    [
        (
            "LinearLPSBar.yaml",
            "Materials.Linearized LPS Material.Material Model",
            "Linear LPS Partial Volume",
        ),
        ("Compression_3x1x1.xml", "Output.Output Variables.Strain_Energy", True),
        ("Compression_2x1x1.xml", "Problem", None),
    ],
)
def test_other_peridigm_decks_are_refused_by_parameter(deck, key, value):
    with pytest.raises(CaseFileError) as err:
        convert_deck(OTHER / deck)
    assert (err.value.key, err.value.value) == (key, value)
