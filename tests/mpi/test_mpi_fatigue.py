"""``mpiexec -n 2`` and ``-n 3 peridyn fatigue`` (issue 20 item 5) give the serial run's fatigue
history: the same crack lengths and bonds broken at the same cycles, the same broken bonds at the
end, in the same files; and with the modal analyses before and after (the dog-bone, below:
``test_mpi_fatigue_modal_analyses_give_the_serial_modes``) the serial modes to the LOBPCG's
tolerance.

Case: the 2D SEN specimen (cases/sen_fatigue_2d.yaml) at 1 mm (200 points), stopped at a 3.5 mm
crack (260-460 steps, about 100 directed bonds broken by the cycles; pre-crack, no-damage sets,
adaptive mapping, phases I and II): as shipped, symmetric about its crack plane, and with the
pre-crack one row above the mid-plane (``ASYMMETRIC``: no two bonds alike).

Why not bit for bit: the equilibrium is solved by the distributed CG (``fatigue.distributed``) to
the serial tolerance, 1e-8 on the residual, not by the serial factorisation; strains then agree
to about 1e-6 relative (``fatigue.statics``, module docstring), so the cycles a bond lasts,
1 / (A eps^m) with m <= 4 here, agree to ``CYCLES_RTOL`` = 4e-6. The displacement agrees to the
same up to a rigid motion: the specimen is held by balanced forces alone and its rigid motion
only by the 1e-9 diagonal shift, which the residual barely sees (strains ignore it).

Mirror images (the shipped specimen): two bonds mirrored across the crack plane have equal
strains to round-off in serial. Where both lives end at the same cycle, serial breaks both in one
adaptive step (slack 1e-12 relative); under MPI their strains differ by the solver's 1e-9 or so
and the second breaks one step later, at a cycle equal to 1e-8 (measured on 2 ranks: 262 serial
steps against 282, final cycles equal to 8e-9). Where one breaks and the other never does, which
one is decided by round-off in serial too: under MPI it may be the mirror image. So for the
shipped case the steps that end at the same cycle are merged before the histories are compared,
and the damage is compared as pairs of mirror points (to round-off: a mirror point sums its
family in another order). With the pre-crack off the mid-plane every
step and every point's damage is the serial one (measured: 463 steps each, final cycles to 3e-8).
crack_length.csv prints 6 significant digits (rounding <= 5e-6 relative), added to the tolerance
for its cycles.

Run with ``PYTHONPATH=src python -m pytest -m mpi -q -p no:cacheprovider tests/mpi``.
"""

import csv
import json
import shutil
from pathlib import Path

import meshio
import numpy as np
import pytest
from conftest import peridyn_process

pytestmark = pytest.mark.mpi

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "cases" / "sen_fatigue_2d.yaml"
SETS = ["discretization.spacing=1e-3", "fatigue.paris.stop_length=0.0035", "output.plots=false"]

#: the pre-crack one row (1 mm) above the mid-plane y = 10 mm
ASYMMETRIC = "precracks=[{type: segment, start: [-0.001, 0.0106], end: [0.0024, 0.0106]}]"
CASES = {"symmetric": [], "asymmetric": [ASYMMETRIC]}
#: relative agreement of cycles: strains to 1e-6 (solver tolerance 1e-8), times m <= 4
CYCLES_RTOL = 4e-6
#: and crack_length.csv's rounding to 6 significant digits
CSV_RTOL = CYCLES_RTOL + 5e-6
#: the files a serial fatigue run writes (output.plots off, no modal analyses)
FILES = {
    "broken_bonds.csv",
    "crack_length.csv",
    "damage.vtu",
    "fatigue.json",
    "run.log",
    "status.json",
    "provenance.json",
    "summary.json",
}


def _fatigue(out: Path, ranks: int, *extra: str, case: Path = CASE, sets=SETS, flags=()):
    """``peridyn fatigue`` of ``case`` with the ``--set`` overrides ``sets`` and ``extra`` and the
    command-line ``flags``, into ``out`` with ``--json``, on ``ranks`` processes."""
    argv = ["fatigue", str(case), "-o", str(out), "--json", "--no-progress", *flags]
    for s in [*sets, *extra]:
        argv += ["--set", s]
    return peridyn_process(argv, ranks)


def _history(folder: Path, merge: bool) -> np.ndarray:
    """(k, 3) rows of crack_length.csv (cycles, crack length m, directed bonds broken); with
    ``merge``, the steps that end at the same cycle as the next (to ``CSV_RTOL``) merged into the
    last of them."""
    with open(folder / "crack_length.csv") as fh:
        rows = np.array([[float(v) for v in row] for row in list(csv.reader(fh))[1:]])
    n = rows[:, 0]
    last = np.append(n[1:] > n[:-1] * (1 + CSV_RTOL), True) if merge else np.ones(len(n), dtype=bool)
    return rows[last]


def _mirror_pairs(points: np.ndarray, values: np.ndarray) -> np.ndarray:
    """(2, n) each point's value and its mirror image's across the mid-plane (y -> 20 mm - y), in
    ascending order."""
    key = np.round(points[:, :2] / 1e-4).astype(np.int64)
    image = key.copy()
    image[:, 1] = 200 - key[:, 1]
    index = {tuple(k): i for i, k in enumerate(key)}
    mirror = np.array([index[tuple(k)] for k in image])
    return np.sort(np.stack([values, values[mirror]]), axis=0)


def _without_rigid_motion(points: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The in-plane displacement (n, 2) less its least-squares rigid motion (translation and
    rotation about z)."""
    x = points[:, :2] - points[:, :2].mean(axis=0)
    n = len(x)
    basis = np.zeros((2 * n, 3))
    basis[0::2, 0] = basis[1::2, 1] = 1.0
    basis[0::2, 2], basis[1::2, 2] = -x[:, 1], x[:, 0]
    flat = u[:, :2].reshape(-1)
    return (flat - basis @ np.linalg.lstsq(basis, flat, rcond=None)[0]).reshape(n, 2)


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    if shutil.which("mpiexec") is None:
        pytest.skip("mpiexec not installed (pip install 'peridyn[mpi]')")
    pytest.importorskip("mpi4py")
    runs = {}
    for name, extra in CASES.items():
        out = tmp_path_factory.mktemp("serial") / name
        done = _fatigue(out, 1, *extra)
        assert done.returncode == 0, done.stderr
        runs[name] = json.loads(done.stdout), out
    return runs


@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("case", list(CASES))
def test_mpi_fatigue_gives_the_serial_crack_history(serial, case, ranks, tmp_path):
    """The serial run's files, summary counts, crack history and damage on 2 and 3 ranks, to the
    tolerances of the module docstring (why not bit for bit). Compared exactly: the directed bonds
    broken and the crack lengths of crack_length.csv (printed to 6 digits), which follow from which
    bonds broke, not from the solver's round-off; the points of damage.vtu (the body's coordinates,
    written as given); and which points never broke (booleans)."""
    want, folder = serial[case]
    symmetric = case == "symmetric"
    out = tmp_path / "run"
    done = _fatigue(out, ranks, *CASES[case])
    assert done.returncode == 0, done.stderr
    got = json.loads(done.stdout)
    assert {p.name for p in out.iterdir()} == {p.name for p in folder.iterdir()} == FILES
    for key in ("points", "bonds", "broken_bonds", "fatigue_broken_bonds", "crack_length_m", "paris_rates"):
        assert got[key] == want[key], key
    assert want["fatigue_broken_bonds"] > 0 and want["crack_length_m"] > 0.0024  # the crack grew
    assert got["cycles"] == pytest.approx(want["cycles"], rel=CYCLES_RTOL)
    a, b = _history(out, symmetric), _history(folder, symmetric)
    assert a.shape == b.shape
    np.testing.assert_array_equal(a[:, 1:], b[:, 1:])  # crack lengths and bonds broken
    np.testing.assert_allclose(a[:, 0], b[:, 0], rtol=CSV_RTOL)
    mine, theirs = meshio.read(out / "damage.vtu"), meshio.read(folder / "damage.vtu")
    x = theirs.points
    np.testing.assert_array_equal(mine.points, x)
    phi, phi_serial = mine.point_data["damage"], theirs.point_data["damage"]
    first, first_serial = mine.point_data["first_break_cycle"], theirs.point_data["first_break_cycle"]
    if symmetric:  # which of two mirror images breaks is round-off's choice (module docstring)
        phi, phi_serial = _mirror_pairs(x, phi), _mirror_pairs(x, phi_serial)
        first, first_serial = _mirror_pairs(x, first), _mirror_pairs(x, first_serial)
    # the same bonds broken; a mirror point sums its family in another order (a few ulp), while
    # one bond more or less changes a point's damage by 2.8e-4 at least (the smallest share of a
    # bond in its family's bond volume here, partial volumes included)
    np.testing.assert_allclose(phi, phi_serial, rtol=0, atol=1e-14 if symmetric else 0)
    np.testing.assert_array_equal(first < 0, first_serial < 0)  # -1: never broke
    np.testing.assert_allclose(first, first_serial, rtol=CYCLES_RTOL)
    if not symmetric:  # the same bonds broken, at the same cycles (printed to 6 digits)
        pairs, pairs_serial = (
            np.loadtxt(f / "broken_bonds.csv", delimiter=",", skiprows=1) for f in (out, folder)
        )
        np.testing.assert_array_equal(pairs[:, :2], pairs_serial[:, :2])
        np.testing.assert_allclose(pairs[:, 2], pairs_serial[:, 2], rtol=CSV_RTOL)
        u, u_serial = (_without_rigid_motion(x, m.point_data["u_max"]) for m in (mine, theirs))
        np.testing.assert_allclose(u, u_serial, rtol=0, atol=1e-6 * np.abs(u_serial).max())
    assert json.loads((out / "status.json").read_text())["status"] == "complete"


@pytest.mark.parametrize(
    "extra, key",
    [
        (["fatigue.solver=direct"], "fatigue.solver"),
        (["fatigue.paris.k=compliance"], "fatigue.paris.k"),
    ],
)
def test_what_mpi_fatigue_cannot_do_is_refused_by_its_key(extra, key, tmp_path):
    """The serial solvers and the compliance K are not distributed: one error naming the key."""
    if shutil.which("mpiexec") is None:
        pytest.skip("mpiexec not installed")
    pytest.importorskip("mpi4py")
    done = _fatigue(tmp_path / "run", 2, *extra)
    assert done.returncode == 1
    lines = [line for line in done.stderr.splitlines() if "error" in line]
    assert len(lines) == 1 and key in lines[0], done.stderr


def test_fatigue_calibrate_is_refused_under_mpi_once(tmp_path):
    """Calibration fits a few CSV files in one process: under mpiexec it would run N times."""
    if shutil.which("mpiexec") is None:
        pytest.skip("mpiexec not installed")
    pytest.importorskip("mpi4py")
    data = tmp_path / "strain_life.csv"
    data.write_text("cycles,strain\n1e3,0.01\n1e4,0.006\n1e5,0.004\n1e6,0.003\n")
    done = peridyn_process(["fatigue", "calibrate", "--strain-life", str(data)], 2)
    assert done.returncode == 1
    lines = [line for line in done.stderr.splitlines() if "error" in line]
    assert len(lines) == 1 and "does not run over MPI ranks" in lines[0], done.stderr


#: The dog-bone (cases/dogbone_fatigue.yaml, V5: fatigue, then free-free modal analyses of the
#: healthy and the damaged body, 12 modes) at 1 mm: 1 746 points, the shipped 870 000 cycles break
#: 24 directed bonds at the notch root (no crack through the depth), which lower the elastic
#: frequencies by 0.009 % to 4.3 %. About 8 s serial, 15 s on 2 ranks.
DOGBONE = ROOT / "cases" / "dogbone_fatigue.yaml"
DOGBONE_SETS = ["discretization.spacing=1e-3"]
#: relative agreement of the elastic frequencies: the residual target of LOBPCG and the serial
#: shift-invert (1e-7 relative) bounds the eigenvalue errors by its square (about 1e-14); 1e-6 is
#: the serial-vs-MPI tolerance of ``peridyn modal`` (tests/mpi/test_mpi_solve.py)
FREQUENCY_RTOL = 1e-6
#: MAC of a mode before with a mode after: the shapes are within sin(theta) <= residual / relative
#: eigenvalue gap of the exact ones, 1e-7 / 0.13 (the closest elastic pair here: 9 728 and 10 365
#: Hz) ~ 1e-6 in each run, and a MAC moves by at most twice that per run: 4e-6, bounded by 1e-5
MAC_ATOL = 1e-5


@pytest.fixture(scope="module")
def serial_modal(tmp_path_factory):
    """The serial dog-bone run with its modal analyses: (summary, output folder)."""
    if shutil.which("mpiexec") is None:
        pytest.skip("mpiexec not installed (pip install 'peridyn[mpi]')")
    pytest.importorskip("mpi4py")
    out = tmp_path_factory.mktemp("serial") / "dogbone"
    done = _fatigue(out, 1, case=DOGBONE, sets=DOGBONE_SETS)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout), out


def _elastic(rows: list[dict]) -> list[dict]:
    return [r for r in rows if r["type"] != "rigid"]


@pytest.mark.parametrize("ranks, asked_by", [(2, "case"), (3, "flag")])
def test_mpi_fatigue_modal_analyses_give_the_serial_modes(serial_modal, ranks, asked_by, tmp_path):
    """``mpiexec -n 2`` and ``-n 3 peridyn fatigue`` of the dog-bone with its modal analyses before
    and after the cycles (``fatigue.modal_after``; on 3 ranks asked by ``--modal`` instead, 12 modes
    either way) write the serial run's files, figure and summary keys; the same bonds break; the
    elastic frequencies before and after equal the serial ones to ``FREQUENCY_RTOL`` with the same
    mode types (rigid modes: the same number, their near-zero frequencies not compared); each mode
    before is matched to the same mode after, with a MAC above 0.99 equal to the serial one to
    ``MAC_ATOL``, and its frequency moves the same way as in serial, by the same amount to twice
    ``FREQUENCY_RTOL`` (every serial change here is larger than that: the direction is decided). The
    signs of the frequency changes are compared exactly: each serial change is larger than twice the
    tolerance."""
    want, folder = serial_modal
    out = tmp_path / "run"
    extra, flags = ([], []) if asked_by == "case" else (["fatigue.modal_after=null"], ["--modal"])
    done = _fatigue(out, ranks, *extra, case=DOGBONE, sets=DOGBONE_SETS, flags=flags)
    assert done.returncode == 0, done.stderr
    got = json.loads(done.stdout)
    files = FILES | {"crack_length.png", "modal.json"}  # figures on
    assert {p.name for p in out.iterdir()} == {p.name for p in folder.iterdir()} == files
    assert got.keys() == want.keys() and got["modal"].keys() == want["modal"].keys()
    assert [Path(p).name for p in got["plots"]] == [Path(p).name for p in want["plots"]]
    assert json.loads((out / "modal.json").read_text()) == got["modal"]
    for key in ("points", "bonds", "broken_bonds", "fatigue_broken_bonds", "cycles"):
        assert got[key] == want[key], key
    assert want["fatigue_broken_bonds"] > 0  # the body after differs from the body before
    for stage in ("before", "after"):
        mine, theirs = got["modal"][stage], want["modal"][stage]
        assert len(mine) == len(theirs) == 12
        assert [(r["type"], r["order"]) for r in mine] == [(r["type"], r["order"]) for r in theirs]
        np.testing.assert_allclose(
            [r["frequency_hz"] for r in _elastic(mine)],
            [r["frequency_hz"] for r in _elastic(theirs)],
            rtol=FREQUENCY_RTOL,
        )
    pairs, serial_pairs = got["modal"]["matches"], want["modal"]["matches"]
    assert [(p["before"], p["after"]) for p in pairs] == [(p["before"], p["after"]) for p in serial_pairs]
    mac, serial_mac = (np.array([p["mac"] for p in m]) for m in (pairs, serial_pairs))
    assert mac.min() > 0.99 and serial_mac.min() > 0.99
    np.testing.assert_allclose(mac, serial_mac, rtol=0, atol=MAC_ATOL)
    np.testing.assert_allclose(got["modal"]["mac"], want["modal"]["mac"], rtol=0, atol=MAC_ATOL)
    change, serial_change = (np.array([p["frequency_change"] for p in m]) for m in (pairs, serial_pairs))
    assert np.all(np.abs(serial_change) > 2 * FREQUENCY_RTOL)
    np.testing.assert_array_equal(np.sign(change), np.sign(serial_change))
    np.testing.assert_allclose(change, serial_change, rtol=0, atol=2 * FREQUENCY_RTOL)
    assert json.loads((out / "status.json").read_text())["status"] == "complete"
