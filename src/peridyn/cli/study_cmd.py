"""peridyn study CASE.yaml: spacing x horizon convergence study of a modal case.

Every (spacing, horizon) combination is a level, solved as a modal run of a sweep (each in
OUT/runs/<id>/, collected in OUT/dataset.nc; --executor runs them in parallel, and a second
study into the same folder skips the levels already complete); modes are matched by type
across levels and each series is extrapolated to zero spacing by Richardson extrapolation
(observed order p, continuum value f_inf, grid convergence index).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

from peridyn.cli.errors import writing
from peridyn.cli.options import (
    DeprecatedAlias,
    add_case_arguments,
    add_common_flags,
    add_executor_flags,
    add_max_memory,
    add_output_flag,
    add_rerun_flag,
)
from peridyn.errors import InputError

#: The sweep's summary keys the study's summary keeps (under ``sweep``).
SWEEP_KEYS = ("runs", "completed", "failed", "skipped", "dataset", "executor", "workers", "threads")


def register(sub) -> None:
    """Add the ``study`` subcommand."""
    p = sub.add_parser(
        "study", help="spacing x horizon convergence study of a modal case", description=__doc__
    )
    add_case_arguments(p)
    p.add_argument(
        "--spacing", required=True, metavar="H1,H2,...", help="grid spacings in m, e.g. 2e-3,1.5e-3,1e-3"
    )
    p.add_argument(
        "--horizon",
        required=True,
        metavar="M1,M2,...",
        help="horizons as multiples of the spacing, e.g. 1.4143,3.001",
    )
    p.add_argument("--modes", type=int, default=None, help="modes per run (rigid included)")
    p.add_argument(
        "--series",
        default="delta-m",
        metavar="S1,S2",
        help="series to fit: delta-m (horizon factor fixed, spacing -> 0; default), "
        "delta (spacing fixed, horizon -> 0), m (horizon in m fixed, spacing -> 0)",
    )
    p.add_argument(
        "--finest",
        type=int,
        default=None,
        metavar="K",
        help="fit only the K finest runs of each series (K >= 3; default all): "
        "leave coarse runs outside the asymptotic range out of the fit",
    )
    p.add_argument(
        "--reference",
        action="append",
        default=[],
        metavar="MODE=HZ",
        help="a reference frequency, e.g. '1st bending=1706.1' (repeatable): "
        "errors of the finest run and of the extrapolation against it",
    )
    add_executor_flags(p, "levels")
    add_output_flag(p, "output folder (default: peridyn-out/<case name>-study); a second study resumes it")
    p.add_argument("--out", dest="output", action=DeprecatedAlias, new="--output")
    add_rerun_flag(p, "levels")
    p.add_argument(
        "--plot",
        metavar="FILE",
        help="also save the figure to FILE (PNG); study.png is always written in the output folder",
    )
    add_common_flags(p)
    add_max_memory(p)
    p.set_defaults(func=run)


def run(args) -> dict:
    """Run the grid, fit, write the tables and the figure; print the table unless --json."""
    from peridyn.io.case import load_case
    from peridyn.io.job_files import job_files
    from peridyn.io.provenance import provenance
    from peridyn.jobs.study import SERIES
    from peridyn.setup.estimate import check_memory, largest_study_run

    start = time.perf_counter()
    spacings = _positive_list("--spacing", args.spacing)
    factors = _positive_list("--horizon", args.horizon)
    series = [s.strip() for s in args.series.split(",") if s.strip()]
    bad = [s for s in series if s not in SERIES]
    if bad or not series:
        raise InputError(f"--series = {args.series!r}: expected some of {', '.join(SERIES)}")
    if args.modes is not None and args.modes < 1:
        raise InputError(f"--modes = {args.modes}: expected a positive integer")
    references = _references(args.reference)
    if args.finest is not None and args.finest < 3:
        raise InputError(f"--finest = {args.finest}: a Richardson fit needs at least three runs")
    case = load_case(args.case, args.overrides)  # fail early on a bad case or override
    check_memory(largest_study_run(case, spacings, factors), args.max_memory, Path(args.case).parent)
    out = Path(args.output or Path("peridyn-out") / f"{case.name}-study")
    if out.exists() and not out.is_dir():
        raise InputError(f"output folder {str(out)!r} is a file, not a folder: choose another --output")
    out.mkdir(parents=True, exist_ok=True)
    with job_files(out, provenance(args.case, case=case)):
        return _study(args, case, out, spacings, factors, series, references, start)


def _study(args, case, out, spacings, factors, series, references, start) -> dict:
    """The grid, fits, tables and figure of ``run`` in its checked output folder."""
    from peridyn.cli.run_cmd import command_line
    from peridyn.jobs.study import check_enough_levels, fit_series, run_levels, write_study
    from peridyn.plotting.convergence import plot_convergence

    def say(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    runs, sweep = run_levels(
        args.case,
        spacings,
        factors,
        out,
        args.modes,
        args.overrides,
        executor=args.executor,
        workers=args.workers,
        threads=args.threads,
        scheduler=args.scheduler,
        overwrite=args.overwrite,
        progress=say,
        command=command_line(),
    )
    if sweep["skipped"]:
        say(f"{sweep['skipped']} of {sweep['runs']} levels already complete in {out}: not run again")
    for r in runs:
        for note in r.notes:
            say(f"note: spacing {r.spacing * 1e3:g} mm, horizon {r.horizon_factor:g} h: {note}")
    check_enough_levels(runs, series)
    fits = fit_series(runs, series, references, args.finest)
    meta = {
        "case": case.name,
        "spacings_m": spacings,
        "horizon_factors": factors,
        "series": series,
        "finest": args.finest,
        "sweep": {k: sweep[k] for k in SWEEP_KEYS},
    }
    out.mkdir(parents=True, exist_ok=True)
    plots = [out / "study.png", *([Path(args.plot)] if args.plot else [])]
    figure = plot_convergence(runs, fits, title=f"{case.name}: delta-m convergence")
    for path in plots:
        with writing(path):
            figure.savefig(path, dpi=110)
    summary = write_study(out, runs, fits, meta, start, plots)
    if not args.json:
        print(format_table(summary))
    return summary


def format_table(summary: dict) -> str:
    """The human-readable report: per series and group, frequencies per run, f_inf, p, GCI;
    a mode without a limit gets the fit's reason on the line below."""
    lines = []
    skipped = [r for r in summary["runs"] if r["skipped"]]
    for r in skipped:
        lines.append(
            f"level spacing {r['spacing_m'] * 1e3:g} mm, horizon {r['horizon_factor']:g} h left out: "
            f"{r['skipped']}"
        )
    if skipped:
        lines.append(f"the fits use the other {len(summary['runs']) - len(skipped)} levels")
    previous = None
    for fit in summary["fits"]:
        if (fit["series"], fit["group"]) != previous:
            previous = (fit["series"], fit["group"])
            unit = "h (mm)" if fit["variable"] == "spacing_m" else "delta (mm)"
            xs = sorted({x for f in summary["fits"] if (f["series"], f["group"]) == previous for x in f["x"]})
            lines.append(
                f"\n{fit['series']} convergence, {fit['group']}; {unit}: "
                + ", ".join(f"{x * 1e3:g}" for x in xs)
                + (f" (fits on the {summary['finest']} finest)" if summary["finest"] else "")
            )
            lines.append(
                f"  {'mode':<26}{'frequencies (Hz), finest first':>34} {'f_inf (Hz)':>11} {'p':>6} {'GCI':>7}"
            )
        freqs = " ".join(f"{f:8.1f}" for f in fit["frequencies_hz"])
        if "value_hz" in fit:
            result = f"{fit['value_hz']:11.1f} {fit['order']:6.2f} {100 * fit['gci']:6.2f}%"
        else:
            result = "  no fit: " + fit["error"].split(":")[0]
        line = f"  {fit['mode']:<26}{freqs:>34} {result}"
        if fit.get("reference_hz") is not None:
            line += f"  (reference {fit['reference_hz']:.1f} Hz: finest {100 * fit['finest_error']:+.2f}%"
            if fit.get("value_error") is not None:
                line += f", f_inf {100 * fit['value_error']:+.2f}%"
            line += ")"
        lines.append(line)
        if "value_hz" not in fit:
            lines.append(f"    {fit['error']}")  # why there is no limit, with the numbers
    lines.append(
        f"\nresults written to {summary['output_dir']} (study.csv, runs.csv, study.json, study.png; "
        "the levels in runs/, their dataset dataset.nc)"
    )
    return "\n".join(lines)


def _positive_list(flag: str, text: str) -> list[float]:
    values = []
    for item in text.split(","):
        try:
            value = float(item)
        except ValueError:
            raise InputError(f"{flag} = {text!r}: {item!r} is not a number") from None
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"{flag} = {text!r}: expected positive numbers, got {item!r}")
        values.append(value)
    if len(set(values)) != len(values):
        raise InputError(f"{flag} = {text!r}: a value is repeated")
    return values


def _references(items) -> dict[str, float]:
    references = {}
    for item in items:
        label, sep, value = item.rpartition("=")
        try:
            hz = float(value)
        except ValueError:
            hz = float("nan")
        if not sep or not label.strip() or not (math.isfinite(hz) and hz > 0):
            raise InputError(f"--reference {item!r}: expected MODE=HZ, e.g. '1st bending=1706.1'")
        references[label.strip()] = hz
    return references
