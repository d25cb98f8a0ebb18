"""peridyn lamb: Lamb wave modes of a free isotropic plate (Rayleigh-Lamb theory)."""

from __future__ import annotations

import argparse
import sys

from peridyn.analysis.lamb import bulk_speeds, dispersion_curves, lamb_modes
from peridyn.cli.errors import writing
from peridyn.cli.options import add_common_flags
from peridyn.errors import InputError

#: The ``--plot`` figure spans 0 to this multiple of the highest ``--freq``.
PLOT_SPAN = 1.25


def register(subparsers) -> None:
    """Add the ``lamb`` subcommand."""
    parser = subparsers.add_parser(
        "lamb",
        help="Lamb wave modes of an isotropic plate (Rayleigh-Lamb theory)",
        description="Phase and group velocity and wavenumber of every propagating Lamb "
        "mode (S0, S1, ..., A0, A1, ...) of a free isotropic elastic plate.",
    )
    parser.add_argument("--E", type=float, required=True, help="Young's modulus, Pa")
    parser.add_argument("--nu", type=float, required=True, help="Poisson's ratio")
    parser.add_argument("--rho", type=float, required=True, help="density, kg/m^3")
    parser.add_argument("--thickness", type=float, required=True, help="plate thickness, m")
    parser.add_argument("--freq", required=True, help="comma-separated frequencies, Hz (e.g. 110e3,150e3)")
    parser.add_argument(
        "--max-order", type=int, default=None, metavar="N", help="list modes S0..SN, A0..AN only"
    )
    parser.add_argument(
        "--plot",
        metavar="FILE",
        help=f"save dispersion curves up to {PLOT_SPAN} x the highest frequency as PNG",
    )
    add_common_flags(parser)
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> dict:
    """Solve the Rayleigh-Lamb equations at ``--freq``; print a table unless ``--json``."""
    freqs = parse_frequencies(args.freq)
    plate = (args.E, args.nu, args.rho, args.thickness)
    modes = lamb_modes(*plate, freqs, args.max_order)
    cl, ct = bulk_speeds(args.E, args.nu, args.rho)
    summary = {
        "modes": [m.to_dict() for m in modes],
        "bulk_speeds_m_s": {"longitudinal": cl, "shear": ct},
    }
    if args.plot:
        from peridyn.plotting.lamb import plot_lamb_dispersion  # matplotlib only when asked

        curves = dispersion_curves(*plate, PLOT_SPAN * max(freqs), max_order=args.max_order)
        with writing(args.plot):
            plot_lamb_dispersion(curves, path=args.plot)
        print(f"wrote {args.plot}", file=sys.stderr)
    if not args.json:
        print(format_table(summary))
    return summary


def parse_frequencies(text: str) -> list[float]:
    """``"110e3,150e3"`` -> ``[110000.0, 150000.0]``; InputError naming ``--freq`` if bad."""
    try:
        return [float(item) for item in text.split(",")]
    except ValueError:
        raise InputError(
            f"--freq = {text!r}: expected comma-separated frequencies in Hz, e.g. 110e3,150e3"
        ) from None


def format_table(summary: dict) -> str:
    """The human-readable report of :func:`run`."""
    speeds = summary["bulk_speeds_m_s"]
    lines = [
        f"bulk speeds: longitudinal {speeds['longitudinal']:.1f} m/s, shear {speeds['shear']:.1f} m/s",
        f"{'f (kHz)':>10}  {'mode':>4}  {'c (m/s)':>10}  {'cg (m/s)':>10}  {'k (rad/m)':>11}",
    ]
    for m in summary["modes"]:
        lines.append(
            f"{m['frequency_hz'] / 1e3:10.3f}  {m['mode']:>4}  {m['phase_velocity_m_s']:10.1f}"
            f"  {m['group_velocity_m_s']:10.1f}  {m['wavenumber_rad_m']:11.2f}"
        )
    return "\n".join(lines)
