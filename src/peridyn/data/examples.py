"""The example inputs shipped with peridyn: cases, sweeps and the gallery's scripts and inputs.

In a checkout they live in the repository (``cases/``, ``sweeps/``, ``examples/``,
``tests/data/peridigm/``); a wheel carries them as package data in ``peridyn/examples_data/``
(``setup.py`` copies them there at build time, following :data:`EXAMPLE_SOURCES`). Either way
:func:`example_path` finds one and :func:`copy_examples` (``peridyn examples DIR``) copies them
all out, laid out as::

    cases/            the shipped case files (and cases/data/)
    sweeps/           the shipped sweep files (their ``base`` is ../cases/...)
    gallery/          the gallery's scripts (plot_*.py)
    gallery/peridigm/ Peridigm's WaveInBar deck, mesh and gold output (plot_09_peridigm_deck.py)

This module imports nothing but the standard library: ``setup.py`` runs it to build the wheel.
"""

from __future__ import annotations

import shutil
from pathlib import Path

#: (folder of the examples, folder in the repository, file patterns, whether sub-folders come too)
#: ``cases/`` comes whole, with the data files its cases read (``cases/data/*.csv``).
EXAMPLE_SOURCES = (
    ("cases", "cases", ("*",), True),
    ("sweeps", "sweeps", ("*.yaml",), False),
    ("gallery", "examples", ("plot_*.py", "README.rst"), False),
    ("gallery/peridigm", "tests/data/peridigm", ("WaveInBar*", "LICENSE-peridigm.md"), False),
)

#: The folder of the examples inside the installed package.
PACKAGED = Path(__file__).resolve().parent.parent / "examples_data"

#: The repository root when peridyn runs from a checkout (``src/peridyn/data/examples.py``).
CHECKOUT = Path(__file__).resolve().parents[3]


def example_files(repository: Path) -> list[tuple[str, Path]]:
    """Every example file of a checkout: (path among the examples, e.g. ``cases/bar_pulse.yaml``;
    the file in ``repository``), sorted by the first."""
    found = {}
    for target, source, patterns, recursive in EXAMPLE_SOURCES:
        folder = repository / source
        for pattern in patterns:
            for path in folder.rglob(pattern) if recursive else folder.glob(pattern):
                if path.is_file() and "__pycache__" not in path.parts:
                    found[f"{target}/{path.relative_to(folder).as_posix()}"] = path
    return sorted(found.items())


def _from_checkout() -> bool:
    return not PACKAGED.is_dir() and (CHECKOUT / "pyproject.toml").is_file()


def _available() -> dict[str, Path]:
    if PACKAGED.is_dir():
        return {p.relative_to(PACKAGED).as_posix(): p for p in sorted(PACKAGED.rglob("*")) if p.is_file()}
    if _from_checkout():
        return dict(example_files(CHECKOUT))
    raise FileNotFoundError(
        f"no examples in this installation of peridyn (no {PACKAGED}): reinstall it from a wheel"
    )


def example_path(name: str) -> Path:
    """The shipped example ``name``, e.g. ``"cases/bar_pulse.yaml"`` or
    ``"gallery/peridigm/WaveInBar.xml"`` (names as :func:`copy_examples` lays them out).

    Raises
    ------
    FileNotFoundError
        No example of that name (the message lists the folders there are).
    """
    files = _available()
    key = name.strip("/")
    if key not in files:
        folders = sorted({k.rsplit("/", 1)[0] for k in files})
        raise FileNotFoundError(f"no example {name!r}; the examples are in {', '.join(folders)}")
    return files[key]


def copy_examples(destination: str | Path) -> list[Path]:
    """Copy every shipped example into ``destination`` (created; it must not hold files yet);
    returns the files written."""
    destination = Path(destination)
    if destination.exists() and (not destination.is_dir() or any(destination.iterdir())):
        raise FileExistsError(f"{destination} exists and is not an empty folder")
    written = []
    for name, source in _available().items():
        target = destination / name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, target)
        written.append(target)
    return written
