"""Peridynamic dispersion relations (peridyn.analysis.dispersion), their plots and ``peridyn dispersion``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import spherical_jn

from peridyn.analysis.dispersion import (
    MARAGING_STEEL,
    Medium,
    dispersion_relation,
    lattice_family,
    parse_direction,
    polarisations,
    study,
)
from peridyn.cli import build_parser, main
from peridyn.errors import InputError
from peridyn.plotting.dispersion import plot_dispersion, plot_study

H = 1e-3  # grid spacing of seed 001 (VALIDATION.md V3), m
RHO = MARAGING_STEEL.density
K = MARAGING_STEEL.dilatational_modulus(3)
MU = MARAGING_STEEL.shear
# Classical speeds of V3's maraging steel: sqrt((K + 4 mu/3)/rho) = 5499.96 (V3: 5500), sqrt(mu/rho) = 3200.
CL, CS = np.sqrt((K + 4 * MU / 3) / RHO), np.sqrt(MU / RHO)
INFLUENCES = ["constant", "inverse", "gaussian", "conical"]


def _limits(rel):
    return rel.branches["longitudinal"].long_wave_limit, rel.branches["shear_1"].long_wave_limit


def test_medium_from_moduli_is_v3_steel():
    # VALIDATION.md V3: K = 132.77 GPa, mu = 81.92 GPa, cL = 5500 m/s, cS = 3200 m/s.
    assert MARAGING_STEEL.dilatational_modulus(3) == pytest.approx(132.77e9, rel=1e-12)
    assert MARAGING_STEEL.shear == pytest.approx(81.92e9, rel=1e-12)
    assert MARAGING_STEEL.classical_speeds(3) == pytest.approx((5500.0, 3200.0), rel=1e-5)


@pytest.mark.parametrize("influence", INFLUENCES)
@pytest.mark.parametrize("horizon", [2e-3, 3e-3, 7e-3])
def test_continuous_lps_long_wave_limits_are_classical(influence, horizon):
    rel = dispersion_relation("lps", MARAGING_STEEL, horizon, H, influence, points=2)
    longitudinal, shear = _limits(rel)
    assert longitudinal == pytest.approx(CL, rel=1e-4)
    assert shear == pytest.approx(CS, rel=1e-4)
    assert rel.branches["shear_2"].long_wave_limit == pytest.approx(CS, rel=1e-4)


@pytest.mark.parametrize(
    ("model", "dim", "plane", "expected"),
    [
        # PMB implies nu = 1/4 (3D, plane strain) or 1/3 (plane stress): rho c^2 = (9/5) K and
        # (3/5) K with K = 2E/3 in 3D; 2D (3/2) kappa and kappa/2; 1D rho c^2 = E.
        ("pmb", 3, "stress", (np.sqrt(1.2 * MARAGING_STEEL.E / RHO), np.sqrt(0.4 * MARAGING_STEEL.E / RHO))),
        (
            "pmb",
            2,
            "stress",
            (np.sqrt(9 / 8 * MARAGING_STEEL.E / RHO), np.sqrt(3 / 8 * MARAGING_STEEL.E / RHO)),
        ),
        ("pmb", 2, "strain", (np.sqrt(1.2 * MARAGING_STEEL.E / RHO), np.sqrt(0.4 * MARAGING_STEEL.E / RHO))),
        ("pmb", 1, "stress", (np.sqrt(MARAGING_STEEL.E / RHO), None)),
        # LPS 2D: rho cL^2 = kappa + mu with the in-plane bulk modulus; 1D: the bar speed.
        ("lps", 2, "stress", MARAGING_STEEL.classical_speeds(2, "stress")),
        ("lps", 2, "strain", MARAGING_STEEL.classical_speeds(2, "strain")),
        ("lps", 1, "stress", (np.sqrt(MARAGING_STEEL.E / RHO), None)),
    ],
)
@pytest.mark.parametrize("influence", ["constant", "inverse", "gaussian"])
def test_continuous_long_wave_limits_other_models_and_dimensions(model, dim, plane, expected, influence):
    rel = dispersion_relation(model, MARAGING_STEEL, 3e-3, H, influence, dim=dim, plane=plane, points=2)
    assert rel.branches["longitudinal"].long_wave_limit == pytest.approx(expected[0], rel=1e-4)
    if expected[1] is not None:
        assert rel.branches["shear_1"].long_wave_limit == pytest.approx(expected[1], rel=1e-4)
    assert rel.classical[0] == pytest.approx(expected[0], rel=1e-12)


def test_continuous_lps_matches_closed_form_bessel_integrals():
    """Independent evaluation for a constant influence function: the angular integrals in
    closed form (spherical Bessel functions), the radial one by scipy's quad."""
    delta = 3e-3
    m = 4 * np.pi * delta**5 / 5
    alpha = 15 * MU / m

    def j(n, x):
        return spherical_jn(n, x)

    def longitudinal(k):
        pair = (
            4
            * np.pi
            * alpha
            * quad(lambda r: r**2 * 2 / 3 * (1 - j(0, k * r) + 2 * j(2, k * r)), 0, delta)[0]
        )
        g = 3 / m * 2 * np.pi * quad(lambda r: r**3 * 2 * j(1, k * r), 0, delta)[0]
        return pair + (K - 5 * MU / 3) * g**2

    def shear(k):
        return 2 * np.pi * alpha * quad(lambda r: r**2 * 4 / 3 * (1 - j(0, k * r) - j(2, k * r)), 0, delta)[0]

    k = np.array([300.0, 1000.0, 2000.0, 3000.0])
    rel = dispersion_relation("lps", MARAGING_STEEL, delta, H, wavenumbers=k)
    omega_l = np.sqrt([longitudinal(x) / RHO for x in k])
    omega_s = np.sqrt([shear(x) / RHO for x in k])
    assert rel.branches["longitudinal"].frequency == pytest.approx(omega_l, rel=1e-9)
    assert rel.branches["shear_1"].frequency == pytest.approx(omega_s, rel=1e-9)


def test_discrete_limits_within_1p5_percent_at_3_dx():
    # Seed 001 found 5539.8 and 3216.4 m/s for cL = 5500, cS = 3200 (VALIDATION.md V3); the
    # issue asks 1.5%. Partial volumes (the default) give +0.2%, -0.3%.
    rel = dispersion_relation("lps", MARAGING_STEEL, 3.015 * H, H, discrete=True, points=2)
    longitudinal, shear = _limits(rel)
    assert longitudinal == pytest.approx(5500.0, rel=0.015)
    assert shear == pytest.approx(3200.0, rel=0.015)


@pytest.mark.parametrize(
    ("factor", "partial", "p_error", "s_error"),
    [
        # VALIDATION.md, "BlochLattice facts" (P along x and S, percent).
        (1.4143, False, 0.0, 0.0),
        (2.015, False, 3.4, -5.3),
        (2.015, True, 0.7, -1.1),
        (3.015, False, -3.8, 5.4),
        (3.015, True, 0.2, -0.3),
        (5.015, False, -1.0, 1.5),
    ],
)
def test_discrete_lps_limits_reproduce_validation_table(factor, partial, p_error, s_error):
    rel = dispersion_relation(
        "lps", MARAGING_STEEL, factor * H, H, discrete=True, partial_volumes=partial, points=2
    )
    longitudinal, shear = _limits(rel)
    assert 100 * (longitudinal / CL - 1) == pytest.approx(p_error, abs=0.2)
    assert 100 * (shear / CS - 1) == pytest.approx(s_error, abs=0.2)


def test_lattice_family_is_the_find_bonds_family():
    # Integer points with i^2 + j^2 + k^2 <= 9: 123 (Gauss's sphere problem), less the centre.
    family = lattice_family(H, 3.0 * H, partial_volumes=False)
    assert len(family.xi) == 122
    assert family.volume == pytest.approx(np.full(122, H**3))
    # With partial volumes the family's volume is the ball's, less the centre cell (to the
    # midpoint quadrature of bonds.find_bonds, 8 x 8 samples per boundary cell).
    partial = lattice_family(H, 3.0 * H)
    assert partial.volume.sum() == pytest.approx(4 / 3 * np.pi * (3 * H) ** 3 - H**3, rel=2e-3)


def test_chain_partial_volumes_cover_the_segment_exactly():
    # 1D: the cells' length fractions add up to the segment [-delta, delta] less the own cell.
    family = lattice_family(H, 2.6 * H, dim=1)
    assert family.volume.sum() == pytest.approx(2 * 2.6 * H - H, rel=1e-12)


CONFIGURATIONS = [
    pytest.param("lps", 3, "x", False, id="lps-3d-continuous"),
    pytest.param("lps", 3, "x", True, id="lps-3d-lattice-x"),
    pytest.param("lps", 3, "xy", True, id="lps-3d-lattice-xy"),
    pytest.param("lps", 3, (1.0, 0.3, 0.2), True, id="lps-3d-lattice-oblique"),
    pytest.param("pmb", 3, "xyz", True, id="pmb-3d-lattice-xyz"),
    pytest.param("lps", 2, "xy", True, id="lps-2d-lattice-xy"),
    pytest.param("pmb", 2, "x", False, id="pmb-2d-continuous"),
    pytest.param("lps", 1, "x", True, id="lps-1d-chain"),
    pytest.param("pmb", 1, "x", False, id="pmb-1d-continuous"),
]


@pytest.mark.parametrize(("model", "dim", "direction", "discrete"), CONFIGURATIONS)
def test_group_velocity_is_the_derivative_of_omega(model, dim, direction, discrete):
    k = np.linspace(200.0, 2800.0, 14)
    dk = 1e-4 * np.pi / H
    grid = np.sort(np.concatenate([k - dk, k, k + dk]))
    rel = dispersion_relation(
        model, MARAGING_STEEL, 3.015 * H, H, dim=dim, direction=direction, discrete=discrete, wavenumbers=grid
    )
    for branch in rel.branches.values():
        omega = branch.frequency.reshape(-1, 3)
        central = (omega[:, 2] - omega[:, 0]) / (2 * dk)
        analytic = branch.group_velocity.reshape(-1, 3)[:, 1]
        assert np.max(np.abs(analytic - central)) < 1e-4 * branch.long_wave_limit


def test_group_velocity_is_zero_at_the_zone_edge():
    # A lattice relation is even about pi/h along x: d omega/dk = 0 there.
    rel = dispersion_relation("lps", MARAGING_STEEL, 3.015 * H, H, discrete=True, points=50)
    for branch in rel.branches.values():
        assert abs(branch.group_velocity[-1]) < 1e-9 * branch.long_wave_limit


def test_negative_group_velocity_onset_scales_with_the_horizon():
    """What this module finds (docs/dispersion.md, study table; the seed reports negative group
    velocity near 1000 rad/m above about 3 spacings with two of its three weight functions):
    on the discrete LPS with partial volumes the longitudinal group velocity turns negative
    at k delta = 4.8 (constant) to 5.2 (1/|xi|, Gaussian) whatever the grid, i.e. inside the
    Brillouin zone as soon as delta exceeds about 1.6 h; at delta = 5 mm it is near
    1000 rad/m for all three."""
    for influence in ("constant", "inverse", "gaussian"):
        for delta in (3e-3, 5e-3, 7e-3):
            onset = dispersion_relation(
                "lps", MARAGING_STEEL, delta, H, influence, discrete=True, points=200
            ).branches["longitudinal"]
            assert 4.6 < onset.negative_group_velocity_from * delta < 5.4
        rel = dispersion_relation("lps", MARAGING_STEEL, 5e-3, H, influence, discrete=True)
        assert rel.to_dict()["negative_group_velocity_from_rad_m"]["longitudinal"] == pytest.approx(
            1000.0, rel=0.05
        )


@pytest.mark.parametrize(
    ("influence", "delta", "shear_negative"),
    [
        # Shear branch (study table): constant influence from k delta = 7.8-8.0; 1/|xi| never
        # below the zone edge; Gaussian only from 7 spacings.
        ("constant", 3e-3, True),
        ("inverse", 7e-3, False),
        ("gaussian", 5e-3, False),
        ("gaussian", 7e-3, True),
    ],
)
def test_shear_group_velocity_sign_by_influence_function(influence, delta, shear_negative):
    rel = dispersion_relation("lps", MARAGING_STEEL, delta, H, influence, discrete=True)
    onset = rel.to_dict()["negative_group_velocity_from_rad_m"]["shear"]
    assert (onset is not None) == shear_negative


def test_small_horizon_keeps_group_velocity_positive():
    # 18-neighbour lattice (1.4143 h) and 2 h with 1/|xi| or Gaussian weights: none in the zone.
    for influence, factor in (("constant", 1.4143), ("inverse", 2.0), ("gaussian", 2.0)):
        rel = dispersion_relation(
            "lps", MARAGING_STEEL, factor * H, H, influence, discrete=True, partial_volumes=factor > 1.5
        )
        assert rel.to_dict()["negative_group_velocity_from_rad_m"] == {"longitudinal": None, "shear": None}


def test_directions_and_polarisations():
    assert parse_direction("xy", 3) == pytest.approx([2**-0.5, 2**-0.5, 0.0])
    assert parse_direction([0, 0, 2], 3) == pytest.approx([0.0, 0.0, 1.0])
    basis = polarisations(parse_direction("xyz", 3), 3)
    assert basis @ basis.T == pytest.approx(np.eye(3))
    assert basis[1] == pytest.approx([-(2**-0.5), 2**-0.5, 0.0])
    assert polarisations(parse_direction("z", 3), 3)[1] == pytest.approx([1.0, 0.0, 0.0])


@pytest.mark.parametrize(
    ("direction", "dim"), [("xz", 2), ("y", 1), ("xq", 3), ("xx", 3), ([0, 0, 0], 3), ([1, 2], 3)]
)
def test_bad_directions_are_refused(direction, dim):
    with pytest.raises(InputError, match="direction"):
        parse_direction(direction, dim)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"horizon": -1e-3}, "horizon"),
        ({"spacing": 0.0}, "spacing"),
        ({"dim": 4}, "dimension"),
        ({"points": 1}, "points"),
        ({"wavenumbers": [2.0, 1.0]}, "wavenumbers"),
        ({"model": "bond"}, "model"),
        ({"influence": "cubic"}, "influence"),
    ],
)
def test_bad_arguments_are_refused(kwargs, match):
    args = {"model": "lps", "medium": MARAGING_STEEL, "horizon": 3e-3, "spacing": H} | kwargs
    with pytest.raises(InputError, match=match):
        dispersion_relation(**args)


def test_bad_media_are_refused():
    with pytest.raises(InputError, match="bulk modulus"):
        Medium.from_moduli(-1.0, 1e9, 1000.0)
    with pytest.raises(InputError, match="nu"):
        Medium(1e9, 0.5, 1000.0)


def test_study_table_and_figures(tmp_path):
    result = study(
        influences=("constant", "gaussian"), horizons=(2e-3, 3e-3), spacings=(1e-3, 1.5e-3), points=60
    )
    rows = result.table
    assert len(rows) == 2 * (2 + 2 - 1)  # the base case (3 mm, 1 mm) once per influence
    assert {
        "influence",
        "horizon_m",
        "spacing_m",
        "longitudinal_error",
        "shear_error",
        "longitudinal_band_rad_m",
        "negative_longitudinal_rad_m",
    } <= set(rows[0])
    assert "delta = 3 mm" in "".join(result.sweep("horizon"))
    assert "constant" in result.negative_group_velocity_summary()
    paths = plot_study(result, tmp_path)
    assert [p.name for p in paths] == [
        "dispersion_influence.png",
        "dispersion_horizon.png",
        "dispersion_spacing.png",
    ]
    assert all(p.stat().st_size > 10_000 for p in paths)


def test_plot_of_one_relation(tmp_path):
    rel = dispersion_relation("lps", MARAGING_STEEL, 3.015 * H, H, discrete=True, direction="xy", points=40)
    fig = plot_dispersion(rel, tmp_path / "one.png")
    assert len(fig.axes) == 9  # three branches (shear_2 differs along xy), three panels
    assert (tmp_path / "one.png").is_file()


STEEL_ARGS = [
    "dispersion",
    "--model",
    "lps",
    "--rho",
    "8000",
    "--bulk-modulus",
    "132.77e9",
    "--shear-modulus",
    "81.92e9",
    "--horizon",
    "3.015e-3",
    "--spacing",
    "1e-3",
]


def test_cli_json(capsys, tmp_path):
    plot = tmp_path / "d.png"
    assert main([*STEEL_ARGS, "--discrete", "--points", "50", "--plot", str(plot), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert {"long_wave_limit_m_s", "negative_group_velocity_from_rad_m", "nyquist_rad_m", "branches"} <= set(
        out
    )
    assert set(out["long_wave_limit_m_s"]) >= {"longitudinal", "shear"}
    assert set(out["negative_group_velocity_from_rad_m"]) == {"longitudinal", "shear"}
    assert out["nyquist_rad_m"] == pytest.approx(np.pi / 1e-3)
    assert set(out["branches"]) == {"longitudinal", "shear_1", "shear_2"}
    assert len(out["branches"]["longitudinal"]["group_velocity_m_s"]) == 50
    # V3: within 1.5% of 5500 and 3200 m/s at 3 spacings (partial volumes by default).
    assert out["long_wave_limit_m_s"]["longitudinal"] == pytest.approx(5500.0, rel=0.015)
    assert plot.is_file()


def test_cli_report_and_young_modulus_input(capsys):
    assert (
        main(
            [
                "dispersion",
                "--model",
                "pmb",
                "--rho",
                "8000",
                "--E",
                "200e9",
                "--nu",
                "0.25",
                "--horizon",
                "3e-3",
                "--spacing",
                "1e-3",
                "--dimension",
                "2",
                "--direction",
                "1,1,0",
                "--points",
                "20",
            ]
        )
        == 0
    )
    report = capsys.readouterr().out
    assert "long-wave limits" in report and "Nyquist" in report


@pytest.mark.parametrize(
    ("extra", "flag"),
    [
        (["--rho", "-1"], "--rho"),
        (["--horizon", "abc"], "--horizon"),
        (["--spacing", "0"], "--spacing"),
        (["--influence", "cubic"], "--influence"),
        (["--model", "bond"], "--model"),
        (["--dimension", "4"], "--dimension"),
        (["--direction", "xq"], "--direction"),
        (["--plane", "shell"], "--plane"),
        (["--points", "1"], "--points"),
        (["--k-max", "-5"], "--k-max"),
        (["--E", "1e9", "--nu", "0.3"], "exactly one"),
    ],
)
def test_cli_bad_input_names_the_argument(extra, flag, capsys):
    args = build_parser().parse_args([*STEEL_ARGS, *extra])
    with pytest.raises(InputError, match=flag):
        args.func(args)
    assert main([*STEEL_ARGS, *extra]) == 1
    assert flag in capsys.readouterr().err


def test_cli_missing_model_and_case_form():
    args = build_parser().parse_args(["dispersion", "--rho", "1"])
    with pytest.raises(InputError, match="--model"):
        args.func(args)
    args = build_parser().parse_args(["dispersion", "case.yaml"])
    with pytest.raises(InputError, match="--frequencies"):
        args.func(args)
