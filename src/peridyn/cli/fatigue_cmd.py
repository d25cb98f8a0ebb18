"""peridyn fatigue CASE.yaml: remaining-life fatigue run (crack length against cycles, optional
modal analyses before and after); peridyn fatigue calibrate: fit the parameters from data.

Calibration inputs (CSV with a header row):
  --strain-life: cycles, strain (cyclic strain to failure)  -> A_I, m_I, eps_inf (eqs. 7.7-7.9)
  --paris: delta_k_mpa_sqrt_m, da_dn_m_per_cycle            -> m_II (Paris exponent)
  --trial: crack_length.csv of a single-edge-notch run with A_II = --trial-a-ii, with --stress
           (Pa) and --width (m) -> A_II (eq. 7.11) and a plot of simulated against experimental da/dN
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from peridyn.cli.logs import progress_bar
from peridyn.cli.options import (
    add_case_arguments,
    add_common_flags,
    add_max_memory,
    add_output_flag,
    add_overwrite_flag,
    add_progress_flags,
)
from peridyn.errors import InputError


def register(sub) -> None:
    """Add the ``fatigue`` subcommand (``fatigue calibrate`` when the case is the word calibrate)."""
    p = sub.add_parser(
        "fatigue",
        help="fatigue run of a case, or 'fatigue calibrate'",
        description=__doc__,
        formatter_class=_raw(),
    )
    add_case_arguments(p)
    add_output_flag(
        p,
        "output folder (default: the case's output.directory or peridyn-out/<case name>; "
        "calibrate: peridyn-out/fatigue-calibration)",
    )
    p.add_argument(
        "--modal",
        action="store_true",
        help="modal analyses before and after (default: when the case has fatigue.modal_after)",
    )
    add_progress_flags(p)
    add_max_memory(p)
    add_overwrite_flag(p)
    g = p.add_argument_group("calibrate")
    g.add_argument("--strain-life", help="CSV: cycles, strain")
    g.add_argument("--paris", help="CSV: delta_k_mpa_sqrt_m, da_dn_m_per_cycle")
    g.add_argument("--trial", help="crack_length.csv of a trial single-edge-notch run")
    g.add_argument("--trial-a-ii", type=float, help="A_II of the trial run")
    g.add_argument("--stress", type=float, help="maximum remote stress of the trial run, Pa")
    g.add_argument("--width", type=float, help="specimen width b of the trial run, m")
    g.add_argument("--load-ratio", type=float, default=0.0, help="load ratio R of the trial run")
    add_common_flags(p)
    p.set_defaults(func=run)


def _raw():
    import argparse

    return argparse.RawDescriptionHelpFormatter


def run(args) -> dict:
    """Run a fatigue case (over the MPI ranks under ``mpiexec -n N``), or calibrate when the case
    argument is ``calibrate`` (one process)."""
    from peridyn.parallel.comm import world

    if args.case == "calibrate":
        if world().size > 1:
            raise InputError(
                "'peridyn fatigue calibrate' does not run over MPI ranks: run it without mpiexec"
            )
        return calibrate(args)
    from peridyn.io.case import load_case
    from peridyn.jobs.dispatch import job_function, run_job

    job_function("fatigue")  # its modules loaded before the case is read, as before the dispatch
    case = load_case(args.case, args.overrides)
    summary = run_job(
        "fatigue",
        case,
        args.output,
        base_dir=Path(args.case).parent,
        modal=True if args.modal else None,
        progress=progress_bar(args.progress, f"{case.name} fatigue steps"),
        overwrite=args.overwrite,
        comm=world(),
        max_memory=args.max_memory,
        case_path=args.case,
    )
    if not args.json:
        print(
            f"{summary['points']} points, {summary['cycles']:.6g} cycles, crack length "
            f"{1e3 * summary['crack_length_m']:.3f} mm, {summary['fatigue_broken_bonds']} directed bonds "
            f"broken by the cycles, {summary['seconds']:.1f} s"
        )
        if summary["paris_slope"] is not None:
            print(f"Paris slope {summary['paris_slope']:.3f}")
        if "modal" in summary:
            _print_modal(summary["modal"])
        print(f"results written to {summary['output_dir']}")
    return summary


def _print_modal(modal: dict) -> None:
    before = [m for m in modal["before"] if m["type"] != "rigid"]
    after = [m for m in modal["after"] if m["type"] != "rigid"]
    print("  mode  before (Hz)  type                      after (Hz)  type                   MAC   df")
    for pair in modal["matches"]:
        b, a = before[pair["before"]], after[pair["after"]]
        print(
            f"  {pair['before'] + 1:4d}  {b['frequency_hz']:11.2f}  {b['label']:24s}  "
            f"{a['frequency_hz']:11.2f}  {a['label']:20s}  {pair['mac']:.3f} "
            f"{100 * pair['frequency_change']:+.2f}%"
        )


def _read_csv(path: str, n_cols: int) -> np.ndarray:
    try:
        data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read {path}: {exc}") from None
    if data.shape[1] < n_cols:
        raise InputError(f"{path}: expected at least {n_cols} columns, got {data.shape[1]}")
    return data


def calibrate(args) -> dict:
    """Fit phase I, m_II and A_II from the CSV files given; plot da/dN when a trial run is given."""
    from peridyn.fatigue import calibration as cal

    if not (args.strain_life or args.paris):
        raise InputError("fatigue calibrate needs --strain-life and/or --paris CSV files")
    summary: dict = {}
    if args.strain_life:
        d = _read_csv(args.strain_life, 2)
        fit = cal.fit_phase_one(d[:, 0], d[:, 1])
        summary["phase_one"] = {
            "A_I": fit.A_I,
            "m_I": fit.m_I,
            "eps_inf": fit.eps_inf,
            "r_squared": fit.r_squared,
        }
    if args.paris:
        p = _read_csv(args.paris, 2)
        dk_exp, rate_exp = p[:, 0] * 1e6, p[:, 1]
        summary["m_II"] = cal.paris_fit(dk_exp, rate_exp)[0]
        if args.trial:
            if args.trial_a_ii is None or args.stress is None or args.width is None:
                raise InputError("--trial needs --trial-a-ii, --stress (Pa) and --width (m)")
            h = _read_csv(args.trial, 2)
            a_mid, rate = cal.growth_rates(h[:, 0], h[:, 1])
            if rate.size < 2:
                raise InputError(f"{args.trial}: the crack grew fewer than 3 times; run the trial longer")
            dk_sim = (1.0 - args.load_ratio) * cal.stress_intensity(args.stress, a_mid, args.width)
            summary["A_II"] = cal.calibrate_A_II(args.trial_a_ii, dk_sim, rate, dk_exp, rate_exp)
            summary["simulated_slope"] = cal.paris_fit(dk_sim, rate)[0]
            from peridyn.plotting.fatigue import plot_paris

            out = Path(args.output or "peridyn-out/fatigue-calibration")
            out.mkdir(parents=True, exist_ok=True)
            summary["plots"] = [
                str(
                    plot_paris(
                        dk_sim,
                        rate,
                        dk_exp,
                        rate_exp,
                        out / "paris.png",
                        f"simulated (A_II' = {args.trial_a_ii:g})",
                    )
                )
            ]
    if not args.json:
        for key, value in summary.items():
            print(f"{key}: {value}")
    return summary
