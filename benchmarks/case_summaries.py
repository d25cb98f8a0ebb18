"""Summaries of every shipped case, shortened, to prove that a refactoring changes no number.

Each case of ``cases/`` runs through the command line (``peridyn run``, and ``peridyn fatigue``
for the fatigue cases with their mapping cut to a few steps), shortened as the shipped-case test
does. What is kept of a run: its JSON summary without the machine-dependent keys (timings,
memory, paths), and a SHA-256 digest of every numeric dataset of its ``results.h5``, so that a
single changed bit anywhere in the results shows.

    python benchmarks/case_summaries.py record benchmarks/case_summaries.json
    python benchmarks/case_summaries.py compare benchmarks/case_summaries.json

``--lattice`` runs the explicit cases only, on ``discretization.storage: auto`` (lattice storage
wherever a case allows it; the summary's ``storage`` says which ran), against its own table:

    python benchmarks/case_summaries.py compare --lattice benchmarks/case_summaries_lattice.json

``compare`` prints one line per case (``same`` or the values that differ) and exits 1 when
anything differs. It uses only the command line and h5py, so it runs unchanged across a
reorganisation of the package.

One part of the results is not reproducible from run to run, and is compared with a tolerance
instead: the eigensolver (ARPACK) starts from a random vector, so mode shapes (datasets under
``modes/``) are not compared bit for bit, residuals (~1e-11) are not compared, frequencies
agree to ``FREQUENCY_ATOL + FREQUENCY_RTOL |f|`` (rigid modes are noise of ~1e-3 Hz around 0)
and the other numbers of a modal analysis (MAC, frequency changes) to ``MODAL_TOL``, absolute
and relative (seen run to run: 1e-13).

Summary schema 2 (docs/user-guide.md, "Summaries and results files") renamed keys and made every
bond count directed. ``compare`` reads a table recorded before it (summaries without a
``schema_version``) through :data:`SCHEMA_1_TO_2`, so that the old table still checks every
number; keys that schema 2 added and the old table cannot hold are listed in :data:`SCHEMA_2_NEW`.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import io
import json
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CASES = sorted((ROOT / "cases").glob("*.yaml"))
SHORTEN = {
    "explicit": ["--set", "solver.time=0.3e-6"],
    "static": ["--set", "solver.tolerance=1e-3"],
    "modal": ["--set", "solver.modes=8"],
}
FATIGUE_SHORT = ["--set", "fatigue.mapping=[{steps: 3, tau: 1.0e-6}]", "--set", "fatigue.paris=null"]
#: keys that depend on the machine or the folder, not on the numbers
VOLATILE = {
    "seconds",
    "peak_memory_bytes",
    "plots",
    "output",
    "output_dir",
    "results",
    "case_file",
    "build_seconds",
    "solve_seconds",
    "wall_seconds",
    "directory",
    "files",
    "figures",
}
FREQUENCY_ATOL, FREQUENCY_RTOL = 1e-2, 1e-9  # Hz, 1
MODAL_TOL = 1e-9
#: Schema 1 -> 2, per job kind (the first word of a table entry): old key -> (new key, factor).
#: The fatigue summary counted each bond once; schema 2 counts directed bonds, as runs always did.
SCHEMA_1_TO_2 = {
    "fatigue": {"bonds": ("bonds", 2), "bonds_broken": ("fatigue_broken_bonds", 2)},
}
#: Keys new in schema 2, per job kind: ``kind`` and ``schema_version`` everywhere, a mode's
#: ``label`` ("1st bending", from its type and order), and the fatigue summary's ``broken_bonds``
#: (every directed bond broken at the end, pre-cracks included, as in a run's summary).
SCHEMA_2_NEW = {
    "run": {"kind", "schema_version", "label"},
    "fatigue": {"kind", "schema_version", "label", "broken_bonds"},
}


def _strip(value):
    if isinstance(value, dict):
        return {
            k: _strip(v)
            for k, v in sorted(value.items())
            if k not in VOLATILE and "seconds" not in k and "memory" not in k
        }
    if isinstance(value, list):
        return [_strip(v) for v in value]
    return value


def _digests(results: Path) -> dict:
    out = {}
    with h5py.File(results, "r") as f:

        def visit(name, obj):
            if name.startswith("modes/"):
                return
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fiub" and obj.size:
                data = np.ascontiguousarray(obj[()])
                out[name] = hashlib.sha256(data.tobytes()).hexdigest()[:16]

        f.visititems(visit)
    return out


def _run(args: list[str], folder: Path) -> dict:
    from peridyn.cli import main

    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(io.StringIO()):
        code = main([*args, "--json", "--no-progress", "-o", str(folder)])
    if code != 0:
        return {"exit_code": code}
    summary = _strip(json.loads(stdout.getvalue()))
    results = folder / "results.h5"
    return {"summary": summary, "datasets": _digests(results) if results.is_file() else {}}


#: ``--lattice``: what each explicit run adds
LATTICE = ["--set", "discretization.storage=auto"]


def record(lattice: bool = False) -> dict:
    import yaml

    table = {}
    for path in CASES:
        spec = yaml.safe_load(path.read_text())
        kind = spec["solver"]["type"]
        if lattice and kind != "explicit":
            continue
        with tempfile.TemporaryDirectory() as tmp:
            extra = LATTICE if lattice else []
            table[f"run {path.stem}"] = _run(
                ["run", str(path), "--set", "output.plots=false", *SHORTEN[kind], *extra], Path(tmp)
            )
        if "fatigue" in spec and not lattice:
            with tempfile.TemporaryDirectory() as tmp:
                table[f"fatigue {path.stem}"] = _run(["fatigue", str(path), *FATIGUE_SHORT], Path(tmp))
        print(f"{path.stem}: done", file=sys.stderr)
    return table


def _numbers(value, prefix=""):
    """Flatten nested summaries into {path: leaf}."""
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _numbers(v, f"{prefix}.{k}" if prefix else k)
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from _numbers(v, f"{prefix}[{i}]")
    else:
        yield prefix, value


def _leaf(key: str) -> str:
    """The last key of a flattened path: ``modes[6].label`` -> ``label``."""
    return key.rsplit(".", 1)[-1].split("[")[0]


def _agree(key: str, a, b) -> bool:
    """Equal, or within the eigensolver's run-to-run scatter for its outputs (module docstring)."""
    if key.endswith("residual"):
        return True
    numbers = all(isinstance(v, int | float) and not isinstance(v, bool) for v in (a, b))
    if numbers and key.endswith("frequency_hz"):
        return abs(a - b) <= FREQUENCY_ATOL + FREQUENCY_RTOL * abs(a)
    if numbers and ("modal" in key or "modes" in key):
        return abs(a - b) <= MODAL_TOL * (1.0 + abs(a))
    return a == b


def _schema_2(kind: str, summary: dict) -> tuple[dict, set]:
    """A schema-1 summary in schema 2's keys and counts, and the leaf keys it cannot hold
    (unchanged, and nothing to skip, for a summary that has a ``schema_version``)."""
    if "schema_version" in summary:
        return summary, set()
    renamed = dict(summary)
    for old, (new, factor) in SCHEMA_1_TO_2.get(kind, {}).items():
        if old in renamed:
            renamed[new] = renamed.pop(old) * factor
    return renamed, SCHEMA_2_NEW[kind]


def compare(before: dict, after: dict) -> bool:
    same = True
    for name in sorted(set(before) | set(after)):
        if name not in before or name not in after:
            print(f"{name}: only {'before' if name in before else 'after'}")
            same = False
            continue
        a, b = before[name], after[name]
        old, new_keys = _schema_2(name.split()[0], a.get("summary", a))
        flat_a, flat_b = dict(_numbers(old)), dict(_numbers(b.get("summary", b)))
        flat_b = {k: v for k, v in flat_b.items() if k in flat_a or _leaf(k) not in new_keys}
        keys = sorted(set(flat_a) | set(flat_b))
        missing = [k for k in keys if k not in flat_a or k not in flat_b]
        values = [
            f"{k}: {flat_a[k]!r} -> {flat_b[k]!r}"
            for k in keys
            if k not in missing and not _agree(k, flat_a[k], flat_b[k])
        ]
        data_a, data_b = a.get("datasets", {}), b.get("datasets", {})
        changed = sorted(k for k in set(data_a) | set(data_b) if data_a.get(k) != data_b.get(k))
        if missing or values or changed:
            same = False
            print(f"{name}: DIFFERS: keys on one side only {missing}; values {values}; datasets {changed}")
        else:
            print(f"{name}: same ({len(flat_a)} summary values, {len(data_a)} datasets bit for bit)")
    return same


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("action", choices=["record", "compare"])
    p.add_argument("table", type=Path, help="JSON table of summaries")
    p.add_argument("--lattice", action="store_true", help="explicit cases on discretization.storage auto")
    ns = p.parse_args(argv)
    table = record(ns.lattice)
    if ns.action == "record":
        ns.table.write_text(json.dumps(table, indent=1, sort_keys=True) + "\n")
        return 0
    return 0 if compare(json.loads(ns.table.read_text()), table) else 1


if __name__ == "__main__":
    sys.exit(main())
