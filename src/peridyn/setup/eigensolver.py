"""Which eigensolver a modal job takes, and the checks of a modal case before anything is
allocated: the shift-invert factor's estimated size against the machine's memory
(``choose_eigensolver``, ``check_assembly_fits``) and the modes asked against the rigid-body
modes of a free body (``check_mode_count``)."""

from __future__ import annotations

from peridyn.errors import CaseFileError, InputError
from peridyn.linalg.ordering import estimated_factor_entries

#: Share of the machine's memory the factorisation may take.
MEMORY_SHARE = 0.7
#: ``auto`` factorises (shift-invert) only below this estimated factor size, bytes; above
#: it LOBPCG is faster as well as smaller (benchmarks/HISTORY.md, "Modal: LOBPCG without a factor").
FACTOR_BUDGET = 2**30


#: Rigid-body modes of a free body by its dimension: translations and rotations.
RIGID_MODES = {2: 3, 3: 6}


def check_mode_count(case, dim: int, held: bool) -> None:
    """Refuse a modal run of a free body (not ``held`` by a boundary condition) that asks for
    no more modes than its rigid-body modes: it would find no vibration mode.

    Raises
    ------
    CaseFileError
        Naming ``solver.modes`` and the rigid modes.
    """
    rigid = RIGID_MODES[dim]
    if not held and case.solver.modes <= rigid:
        raise CaseFileError(
            case.name,
            "solver.modes",
            case.solver.modes,
            f"more than the {rigid} rigid-body modes of a free {dim}D body (--modes), e.g. {rigid + 10}",
        )


def choose_eigensolver(model, requested: str = "auto") -> str:
    """``shift-invert`` or ``lobpcg`` for ``model``.

    ``auto``: shift-invert when the estimated factor (``factor_bytes``) is at most
    ``FACTOR_BUDGET`` and fits in the machine's memory, LOBPCG otherwise. An explicit
    ``shift-invert`` is refused when it cannot fit (``check_assembly_fits``).
    """
    if requested == "auto":
        fits = factor_bytes(model) <= min(FACTOR_BUDGET, MEMORY_SHARE * _machine_memory())
        return "shift-invert" if fits else "lobpcg"
    if requested == "shift-invert":
        check_assembly_fits(model)
    elif requested != "lobpcg":
        raise InputError(f"eigensolver must be auto, shift-invert or lobpcg, got {requested!r}")
    return requested


def factor_bytes(model) -> float:
    """Estimated memory of the shift-invert factor, bytes (8-byte values, 4-byte indices)."""
    unknowns = 4 if model.has_dilatation else 3  # with a dilatation (LPS): three dofs and theta
    return 12.0 * estimated_factor_entries(model.body.points, model.bonds.horizon, unknowns)


def _machine_memory() -> float:
    """Physical memory, bytes (infinite where the system does not say)."""
    import os

    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return float("inf")


def check_assembly_fits(model) -> None:
    """Refuse, with the numbers, a shift-invert factorisation too large for this machine.

    The factor's size is estimated from the nested-dissection separators of the
    points (``linalg.ordering.estimated_factor_entries``): it grows with the
    horizon (wider separators) much faster than the number of bonds does.
    """
    needed = factor_bytes(model)
    entries = needed / 12.0
    available = _machine_memory()
    if needed > MEMORY_SHARE * available:
        raise InputError(
            f"the sparse factorisation of this model would hold about {entries / 1e9:.2f} billion "
            f"entries (~{needed / 2**30:.0f} GiB; this machine has {available / 2**30:.0f} GiB): "
            "use solver.eigensolver lobpcg (or auto), a smaller horizon or a coarser spacing"
        )
