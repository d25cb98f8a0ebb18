"""Peridigm's test corpus (tests/data/peridigm_corpus: decks, meshes, exodiff ``.comp`` files and
gold results of Peridigm's regression and verification tests) run as a user runs a deck, and the
table of outcomes that docs/peridigm.md shows.

Each deck is run with ``peridyn run DECK -o OUT``. Its outcome is one of

- ``match``: every Exodus file it writes that has a gold file (``<name>_gold.e``, or
  ``<name>_gold.h`` of a history file) equals it within the deck's ``.comp`` tolerances
  (``<name>.comp``, or the folder's one ``.comp``), by ``exodiff_comp.compare``; when none of
  them has one and the folder has ``<folder>_gold.e``, the files written joined in time, as
  Peridigm's test of a sequence of solvers joins its output files (SEACAS ``conjoin``), equal
  that gold file;
- ``differs``: it runs, and the items over their tolerance are named (with the largest excess,
  in units of the tolerance);
- ``refused``: peridyn stops before running, with the one line naming what the deck asks that
  peridyn lacks.

``python tests/peridigm_corpus.py`` runs every deck and rewrites the table in docs/peridigm.md
(between its ``corpus table`` markers); ``tests/simulation/test_peridigm_corpus.py`` checks each
deck's row against a fresh run.
"""

from __future__ import annotations

import contextlib
import io
import json
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from exodiff_comp import compare, compare_meshes

from peridyn.io.exodus import ExodusMesh, read_exodus

CORPUS = Path(__file__).parent / "data" / "peridigm_corpus"
DOCS = Path(__file__).parents[1] / "docs" / "peridigm.md"
BEGIN, END = "<!-- corpus table: begin -->", "<!-- corpus table: end -->"


#: Why a deck that differs does (docs/peridigm.md): the row adds it to the items. None differs now.
WHY: dict[str, str] = {}


def decks() -> list[str]:
    """Every deck of the corpus, as ``folder/deck`` relative to ``CORPUS``."""
    found = [*CORPUS.glob("*/*.xml"), *CORPUS.glob("*/*.yaml")]
    return sorted(p.relative_to(CORPUS).as_posix() for p in found)


@dataclass(frozen=True)
class Outcome:
    """A deck's outcome: ``status`` "match", "differs" or "refused", and a one-line ``detail``."""

    deck: str
    status: str
    detail: str

    def row(self) -> str:
        return f"| `{self.deck}` | {self.status} | {self.detail} |"


def _gold(folder: Path, written: Path) -> tuple[Path, Path]:
    """The gold file and the ``.comp`` file that a written Exodus file is compared with."""
    gold = folder / f"{written.stem}_gold{written.suffix}"
    comp = folder / f"{written.stem}.comp"
    if not comp.is_file():
        (comp,) = folder.glob("*.comp")
    return gold, comp


def conjoined(meshes: list[ExodusMesh]) -> ExodusMesh:
    """Exodus files of one mesh joined in time as SEACAS ``conjoin`` joins them (Sjaardema, "A
    Collection of Exodus Utilities: Exodiff, EPU, EJoin, and Conjoin", Sandia): in the order
    of their first times, each file's steps before the next file's first time, then the next
    file's (where their times overlap, the later file's steps are kept). The variables are
    those of the first file; the ``node_status`` and ``elem_status`` that conjoin adds are
    not made (no ``.comp`` file lists them)."""
    ordered = sorted(meshes, key=lambda m: m.times[0])
    keep = [m.times < nxt.times[0] for m, nxt in zip(ordered, ordered[1:], strict=False)]
    keep.append(np.ones(len(ordered[-1].times), dtype=bool))

    def joined(kind: str) -> dict:
        first = getattr(ordered[0], kind)
        return {
            k: np.concatenate([getattr(m, kind)[k][w] for m, w in zip(ordered, keep, strict=True)])
            for k in first
        }

    return replace(
        ordered[0],
        times=np.concatenate([m.times[w] for m, w in zip(ordered, keep, strict=True)]),
        nodal_variables=joined("nodal_variables"),
        element_variables=joined("element_variables"),
        global_variables=joined("global_variables"),
    )


def _excess(folder: Path, written: list[Path]) -> dict:
    """Each compared item's excess over its tolerance (``exodiff_comp.compare``), named after
    its file when several are compared; empty when no gold file applies."""
    compared = [r for r in written if _gold(folder, r)[0].is_file()]
    joined_gold = folder / f"{folder.name}_gold.e"
    if not compared and joined_gold.is_file():
        exodus = [read_exodus(p) for p in written if p.suffix == ".e"]
        (comp,) = folder.glob("*.comp")
        return compare_meshes(read_exodus(joined_gold), conjoined(exodus), comp)
    over = {}
    for result in compared:  # a file without a gold file (a history file) is not compared
        gold, comp = _gold(folder, result)
        excess = compare(gold, result, comp)
        over |= {f"{result.name}: {k}" if len(compared) > 1 else k: v for k, v in excess.items()}
    return over


def run(deck: str, out: Path) -> Outcome:
    """Run ``deck`` (``folder/deck`` under ``CORPUS``) into ``out`` with the CLI; its outcome."""
    from peridyn.cli import main

    path = CORPUS / deck
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(io.StringIO()):
        status = main(["run", str(path), "-o", str(out), "--no-progress", "--json"])
    if status != 0:
        error = json.loads(stdout.getvalue().strip().splitlines()[-1])
        line = error["error"].replace(f"{path}: ", "")
        return Outcome(deck, "refused", line.replace("|", "/").splitlines()[0])
    written = sorted(p for p in out.iterdir() if p.suffix in (".e", ".h"))
    if not written:
        return Outcome(deck, "differs", "no Exodus file written")
    excess = _excess(path.parent, written)
    if not excess:
        return Outcome(deck, "differs", f"no gold file of {', '.join(p.name for p in written)}")
    over = {k: v for k, v in excess.items() if v > 0}
    if not over:
        return Outcome(deck, "match", "")
    worst = sorted(over.items(), key=lambda kv: -kv[1])
    text = ", ".join(f"{k} ({v + 1:.3g}x)" for k, v in worst[:6])
    text += f" and {len(worst) - 6} more" if len(worst) > 6 else ""
    return Outcome(deck, "differs", text + (f": {WHY[deck]}" if deck in WHY else ""))


def documented() -> dict[str, str]:
    """The rows of the table in docs/peridigm.md, by deck."""
    text = DOCS.read_text(encoding="utf-8")
    table = text[text.index(BEGIN) + len(BEGIN) : text.index(END)]
    rows = {}
    for line in table.splitlines():
        if line.startswith("| `"):
            rows[line.split("`")[1]] = line
    return rows


def write_docs(outcomes: list[Outcome]) -> None:
    """Rewrite the table of docs/peridigm.md between its markers."""
    text = DOCS.read_text(encoding="utf-8")
    counts = {s: sum(o.status == s for o in outcomes) for s in ("match", "differs", "refused")}
    lines = [
        BEGIN,
        f"{counts['match']} of {len(outcomes)} decks match, {counts['differs']} differ, "
        f"{counts['refused']} are refused.",
        "",
        "| deck | outcome | what differs, or what is refused |",
        "|---|---|---|",
        *(o.row() for o in outcomes),
        END,
    ]
    head, tail = text[: text.index(BEGIN)], text[text.index(END) + len(END) :]
    DOCS.write_text(head + "\n".join(lines) + tail, encoding="utf-8")


if __name__ == "__main__":
    import tempfile

    chosen = sys.argv[1:] or decks()
    results = []
    for name in chosen:
        with tempfile.TemporaryDirectory() as tmp:
            results.append(run(name, Path(tmp) / "out"))
        print(results[-1].row(), flush=True)
    if not sys.argv[1:]:
        write_docs(results)
