"""The distributed equilibrium of the fatigue loop (``fatigue.distributed.RankStatics``) in one
process, where the Domain is the serial stand-in: the same code runs on each MPI rank (the
multi-rank runs are in tests/mpi/test_mpi_fatigue.py), and what an MPI fatigue run refuses and
accepts.

Reference: the serial ``LinearStatics`` with the sparse factorisation (``method="direct"``), itself
checked against an assembled solve (tests/unit/test_fatigue_statics.py). Tolerances are the
fatigue model's (``fatigue.statics`` module docstring): equilibrium residual 1e-8 relative, bond
strains to 1e-6 of the largest strain.
"""

from pathlib import Path

import numpy as np
import pytest
from test_fatigue_statics import _cut, _notched_bar

from peridyn.errors import CaseFileError, InputError
from peridyn.fatigue.distributed import RankStatics
from peridyn.fatigue.model import bond_strain
from peridyn.fatigue.statics import LinearStatics
from peridyn.io.case import load_case
from peridyn.jobs.fatigue import check_parallel_fatigue
from peridyn.parallel.domain import Domain
from peridyn.physics.loads import BoundaryCondition, Loading
from peridyn.physics.timefunctions import Constant

SEN = Path(__file__).resolve().parents[2] / "cases" / "sen_fatigue_2d.yaml"


def _strain_error(model, u, reference) -> float:
    """Largest bond-strain difference relative to the largest reference strain."""
    want = bond_strain(model, reference)
    return float(np.abs(bond_strain(model, u) - want).max() / np.abs(want).max())


@pytest.mark.parametrize("load", ["displacement", "force"])
def test_rank_statics_gives_the_serial_equilibrium_as_bonds_break(load):
    """Intact, then after an edge crack of 2 and of 4 points (the preconditioner of the intact
    bonds kept or rebuilt): residual below 1e-8 and strains equal to the factorised solve's to
    1e-6 at each solve; the prescribed displacements kept. The prescribed displacements are set by the
    same loading code on both sides and kept, not solved for: compared exactly."""
    model, loading = _notched_bar(load)
    serial = LinearStatics(model, loading, method="direct")
    ranked = RankStatics(model, loading, Domain.serial(model.body.n_points))
    for depth in (0, 2, 4):
        _cut(model, depth)
        want, got = serial.solve(), ranked.solve()
        assert ranked.records[-1].residual <= 1e-8
        assert _strain_error(model, got, want) <= 1e-6
        held = loading.constrained
        np.testing.assert_array_equal(got[held], serial.u_prescribed[held])
    assert ranked.records[0].factorised  # built once at the first solve


def test_rank_statics_refuses_a_load_free_case():
    model, _ = _notched_bar("force")
    loading = Loading(model.body, [BoundaryCondition("left", "displacement", "xyz", Constant(0.0))])
    with pytest.raises(InputError, match="loads at t = 1 s are all zero"):
        RankStatics(model, loading, Domain.serial(model.body.n_points))


@pytest.mark.parametrize(
    "override, key",
    [
        ("fatigue.solver=direct", "fatigue.solver"),
        ("fatigue.paris.k=compliance", "fatigue.paris.k"),
    ],
)
def test_what_an_mpi_fatigue_run_cannot_do_is_refused_by_its_key(override, key):
    case = load_case(SEN, [override])
    with pytest.raises(CaseFileError, match=key.replace(".", r"\.")):
        check_parallel_fatigue(case)


@pytest.mark.parametrize("overrides", [[], ["fatigue.modal_after={modes: 8}"]])
def test_modal_analyses_and_the_shipped_case_are_accepted_under_mpi(overrides):
    """The shipped case (eq. 7.12, solver auto) runs over ranks, and so do the modal analyses
    before and after (distributed LOBPCG, tests/mpi/test_mpi_fatigue.py), which were refused."""
    check_parallel_fatigue(load_case(SEN, overrides))
