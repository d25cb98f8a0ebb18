"""peridyn dispersion: plane-wave dispersion of a peridynamic medium (PMB or LPS)."""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from peridyn.analysis.dispersion import Medium, dispersion_relation, parse_direction
from peridyn.cli.errors import writing
from peridyn.cli.options import add_common_flags, add_set_flag
from peridyn.discretization.bonds import INFLUENCE_FUNCTIONS
from peridyn.errors import InputError
from peridyn.physics.materials.registry import MODELS

#: Rows of the human-readable table per branch.
TABLE_ROWS = 8


def register(subparsers) -> None:
    """Add the ``dispersion`` subcommand."""
    parser = subparsers.add_parser(
        "dispersion",
        help="dispersion of plane waves in a peridynamic medium (PMB or LPS)",
        description="omega(k), phase and group velocity of the longitudinal and shear "
        "branches of an infinite linear peridynamic medium: the continuous relation "
        "(integral over the horizon) or, with --discrete, the lattice sum of a simple cubic "
        "(square) grid as a simulation uses it. Numbers are SI: Pa, kg/m^3, m.",
    )
    parser.add_argument(
        "case",
        nargs="?",
        help="a box or plate case file: Bloch-wave "
        "dispersion of its discrete model (see docs/bloch.md); needs --frequencies",
    )
    parser.add_argument(
        "--frequencies", metavar="F1,F2,...", help="with a case: frequencies in Hz, e.g. 110e3,150e3,225e3"
    )
    add_set_flag(
        parser, "with a case: override a case entry, e.g. discretization.spacing=0.0004 (repeatable)"
    )
    parser.add_argument("--model", help=f"material model: {' or '.join(sorted(MODELS))}")
    parser.add_argument("--rho", help="density, kg/m^3")
    parser.add_argument("--bulk-modulus", help="bulk modulus K, Pa (with --shear-modulus)")
    parser.add_argument("--shear-modulus", help="shear modulus G, Pa (with --bulk-modulus)")
    parser.add_argument("--E", help="Young's modulus, Pa (with --nu)")
    parser.add_argument("--nu", help="Poisson's ratio (with --E)")
    parser.add_argument("--horizon", help="horizon delta, m")
    parser.add_argument("--spacing", help="grid spacing h, m")
    parser.add_argument(
        "--influence",
        default="constant",
        help=f"influence function: {', '.join(INFLUENCE_FUNCTIONS)} (default constant)",
    )
    parser.add_argument("--dimension", default="3", help="1, 2 or 3 (default 3)")
    parser.add_argument("--plane", default="stress", help="2D only: stress or strain (default stress)")
    parser.add_argument(
        "--direction", default="x", help="propagation direction: x, xy, xyz or 'a,b,c' (default x)"
    )
    parser.add_argument(
        "--discrete", action="store_true", help="lattice sum of the grid instead of the continuous integral"
    )
    parser.add_argument(
        "--partial-volumes",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="with --discrete: weigh neighbours by the fraction of their cell "
        "inside the horizon (default on)",
    )
    parser.add_argument(
        "--k-max", help="largest wavenumber, rad/m (default: the zone edge pi / (h max|d_i|))"
    )
    parser.add_argument("--points", default="400", help="number of wavenumbers (default 400)")
    parser.add_argument("--plot", metavar="FILE", help="save omega(k), phase and group velocity as PNG")
    add_common_flags(parser)
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> dict:
    """Compute the relation; print a report unless ``--json``."""
    if args.case is not None:
        return run_case_file(args)
    dim = _choice("--dimension", args.dimension, ("1", "2", "3"))
    relation = dispersion_relation(
        _choice("--model", args.model, tuple(sorted(MODELS))),
        medium_from_args(args),
        horizon=_positive("--horizon", args.horizon),
        spacing=_positive("--spacing", args.spacing),
        influence=_choice("--influence", args.influence, tuple(INFLUENCE_FUNCTIONS)),
        dim=int(dim),
        direction=_direction(args.direction, int(dim)),
        discrete=args.discrete,
        partial_volumes=args.partial_volumes,
        k_max=None if args.k_max is None else _positive("--k-max", args.k_max),
        points=_points(args.points),
        plane=_choice("--plane", args.plane, ("stress", "strain")),
    )
    summary = relation.to_dict()
    if args.plot:
        from peridyn.plotting.dispersion import plot_dispersion  # matplotlib only when asked

        with writing(args.plot):
            plot_dispersion(relation, path=args.plot)
        print(f"wrote {args.plot}", file=sys.stderr)
    if not args.json:
        print(format_report(summary))
    return summary


def run_case_file(args: argparse.Namespace) -> dict:
    """Bloch-wave wavenumbers of a case's discrete model against theory (``{"modes": [...]}``)."""
    from peridyn.analysis.bloch import (
        BlochLattice,
        bloch_cell,
        negative_group_velocity_from,
        zone_edge,
    )
    from peridyn.analysis.bloch_study import predict
    from peridyn.io.case import load_case

    if args.frequencies is None:
        raise InputError("--frequencies is required with a case file, e.g. --frequencies 150e3")
    freqs = [_positive("--frequencies", item) for item in args.frequencies.split(",")]
    case = load_case(args.case, args.overrides)
    disc = BlochLattice.from_case(case)
    cell = bloch_cell(disc)
    summary = {"case": case.name, "modes": predict(disc, freqs, cell), "zone_edge_rad_m": zone_edge(cell)}
    if disc.kind == "block":  # one-point lattice: exact long-wave limits along x
        speeds = cell.long_wave_speeds((1.0, 0.0, 0.0))
        summary["long_wave_limit_m_s"] = {"longitudinal": float(speeds[2]), "shear": float(speeds[0])}
        summary["negative_group_velocity_from_rad_m"] = {
            name: negative_group_velocity_from(cell, np.eye(3)[:, [axis]])
            for name, axis in (("longitudinal", 0), ("shear", 1))
        }
    if args.plot:
        from peridyn.plotting.bloch import plot_bloch  # matplotlib only when asked

        with writing(args.plot):
            plot_bloch(disc, path=args.plot, frequencies=freqs)
        print(f"wrote {args.plot}", file=sys.stderr)
    if not args.json:
        print(format_modes(summary))
    return summary


def format_modes(summary: dict) -> str:
    """The human-readable report of :func:`run_case_file`."""
    lines = [
        f"{summary['case']}: Bloch-wave wavenumbers of the discrete model (zone edge "
        f"{summary['zone_edge_rad_m']:.1f} rad/m)",
        f"{'mode':>5} {'f (kHz)':>9} {'k (rad/m)':>11} {'theory (rad/m)':>15} {'error':>8}",
    ]
    for m in summary["modes"]:
        k, k0, err = m["wavenumber_rad_m"], m["theory_wavenumber_rad_m"], m["error"]
        lines.append(
            f"{m['mode']:>5} {m['frequency_hz'] / 1e3:9.1f} "
            f"{'-' if k is None else f'{k:11.2f}':>11} "
            f"{'-' if k0 is None else f'{k0:15.2f}':>15} "
            f"{'-' if err is None else f'{100 * err:+7.2f}%':>8}"
        )
    if "long_wave_limit_m_s" in summary:
        lines.append(
            "long-wave limits along x: "
            + ", ".join(f"{k} {v:.1f} m/s" for k, v in summary["long_wave_limit_m_s"].items())
        )
        lines.append(
            "negative group velocity from: "
            + ", ".join(
                f"{k} {'none' if v is None else f'{v:.1f} rad/m'}"
                for k, v in summary["negative_group_velocity_from_rad_m"].items()
            )
        )
    return "\n".join(lines)


def medium_from_args(args: argparse.Namespace) -> Medium:
    """The medium of ``--rho`` and either ``--bulk-modulus``/``--shear-modulus`` or ``--E``/``--nu``."""
    rho = _positive("--rho", args.rho)
    moduli = args.bulk_modulus is not None or args.shear_modulus is not None
    young = args.E is not None or args.nu is not None
    if moduli == young:
        raise InputError(
            "give the material as --bulk-modulus and --shear-modulus, or as --E and "
            "--nu (exactly one of the two pairs)"
        )
    if moduli:
        return Medium.from_moduli(
            _positive("--bulk-modulus", args.bulk_modulus),
            _positive("--shear-modulus", args.shear_modulus),
            rho,
        )
    nu = _number("--nu", args.nu)
    if not -1.0 < nu < 0.5:
        raise InputError(f"--nu = {args.nu!r}: Poisson's ratio must lie in (-1, 0.5)")
    return Medium(_positive("--E", args.E), nu, rho)


def _number(flag: str, text) -> float:
    if text is None:
        raise InputError(f"{flag} is required")
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"{flag} = {text!r}: expected a number") from None
    if not math.isfinite(value):
        raise InputError(f"{flag} = {text!r}: expected a finite number")
    return value


def _positive(flag: str, text) -> float:
    value = _number(flag, text)
    if value <= 0:
        raise InputError(f"{flag} = {text!r}: expected a positive number")
    return value


def _points(text: str) -> int:
    if not text.isdigit() or int(text) < 2:
        raise InputError(f"--points = {text!r}: expected an integer of at least 2")
    return int(text)


def _choice(flag: str, value, choices: tuple) -> str:
    if value is None:
        raise InputError(f"{flag} is required: one of {', '.join(choices)}")
    if value not in choices:
        raise InputError(f"{flag} = {value!r}: expected one of {', '.join(choices)}")
    return value


def _direction(text: str, dim: int):
    """``x``/``xy``/``xyz`` letters, or three comma-separated numbers."""
    value = text.split(",") if "," in text else text
    if isinstance(value, list):
        value = [_number("--direction", item) for item in value]
    try:
        return parse_direction(value, dim)
    except InputError as exc:
        raise InputError(f"--direction: {exc}") from None


def format_report(summary: dict) -> str:
    """The human-readable report of :func:`run`."""
    limits = summary["long_wave_limit_m_s"]
    onsets = summary["negative_group_velocity_from_rad_m"]
    kind = "discrete" if summary["discrete"] else "continuous"
    lines = [
        f"{summary['model'].upper()} {summary['dimension']}D, {kind}, {summary['influence']} "
        f"influence, horizon {summary['horizon_m']:g} m, spacing {summary['spacing_m']:g} m",
        "long-wave limits: " + ", ".join(f"{k} {v:.1f} m/s" for k, v in limits.items() if v is not None),
        "negative group velocity from: "
        + ", ".join(f"{k} {'none' if v is None else f'{v:.1f} rad/m'}" for k, v in onsets.items()),
        f"Nyquist wavenumber pi/h: {summary['nyquist_rad_m']:.1f} rad/m",
    ]
    for name, branch in summary["branches"].items():
        lines.append(f"{name}: {'k (rad/m)':>12} {'omega (rad/s)':>14} {'c (m/s)':>9} {'cg (m/s)':>9}")
        n = len(branch["wavenumber_rad_m"])
        for i in sorted({round(j * (n - 1) / (TABLE_ROWS - 1)) for j in range(TABLE_ROWS)}):
            lines.append(
                f"{'':{len(name) + 1}} {branch['wavenumber_rad_m'][i]:12.1f} "
                f"{branch['frequency_rad_s'][i]:14.4g} {branch['phase_velocity_m_s'][i]:9.1f} "
                f"{branch['group_velocity_m_s'][i]:9.1f}"
            )
    return "\n".join(lines)
