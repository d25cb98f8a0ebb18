"""Peridigm's test corpus run unchanged (``peridyn run DECK -o OUT``) and compared with its gold
files within each deck's own exodiff tolerances (tests/peridigm_corpus.py; decks, meshes, gold
files and ``.comp`` files from Peridigm's test suite, tests/data/peridigm_corpus): each deck's
outcome is the one docs/peridigm.md shows (match; differs, the items over their tolerance and
why; refused, with the one line naming what peridyn lacks), so that a deck whose outcome
changes fails here until the table is written again (``python tests/peridigm_corpus.py``)."""

from dataclasses import replace

import numpy as np
import pytest
from peridigm_corpus import CORPUS, conjoined, decks, documented, run

from peridyn.cli import main
from peridyn.io.exodus import read_exodus

#: Decks whose run takes more than 5 s here (the slow marker; the whole corpus takes 8 min,
#: Contact_Cubes 3 of them).
SLOW = {
    "BondBreakingInitialVelocity_TimeDependentCS/BondBreakingInitialVelocity.xml",
    "InitialDamage/InitialDamage.xml",
    "Body_Force/Body_Force_Explicit.xml",
    "Body_Force/Body_Force_Implicit.xml",
    "WaveInBar_MultiBlock/WaveInBar_MultiBlock.xml",
    "Contact_Cubes/Contact_Cubes.xml",
}


def _marked(deck: str):
    return pytest.param(deck, marks=pytest.mark.slow) if deck in SLOW else deck


def test_table_lists_every_deck():
    """docs/peridigm.md has one row for each deck of the corpus, and no other."""
    assert sorted(documented()) == decks()


@pytest.mark.parametrize("deck", [_marked(d) for d in decks()])
def test_deck_outcome_is_documented(tmp_path, deck):
    """The deck's outcome (match, differs with what, refused with what) is its row of the table."""
    outcome = run(deck, tmp_path / "out")
    assert outcome.row() == documented()[deck]


def test_files_are_joined_in_time_as_conjoin_joins_them():
    """Two files of one mesh whose times overlap (0, 1, 2 s and 1.5, 3 s): joined, the steps of
    the first before 1.5 s and then the second's, the later file's data where they overlap, as
    SEACAS conjoin's manual states (first 0 to 5 s, second 4 to 10 s: 0 to 4 s of the first)."""
    mesh = read_exodus(CORPUS / "Compression_QS_3x2x2" / "Compression_QS_3x2x2_gold.e")

    def at(times, value):
        nodal = {"DisplacementX": np.full((len(times), len(mesh.coordinates)), value)}
        return replace(mesh, times=np.array(times), nodal_variables=nodal, element_variables={})

    joined = conjoined([at([1.5, 3.0], 2.0), at([0.0, 1.0, 2.0], 1.0)])
    assert np.array_equal(joined.times, [0.0, 1.0, 1.5, 3.0])
    assert np.array_equal(joined.nodal_variables["DisplacementX"][:, 0], [1.0, 1.0, 2.0, 2.0])


#: Decks of several kinds (quasi-static on a grid, two blocks without bonds between them, bond
#: filters, an implicit solver, a critical stretch in time, two output files, Peridigm's order of
#: operations, points without bonds in contact beyond the horizon, a quasi-static solver then a
#: Verlet one) converted.
CONVERTED = [
    "Compression_QS_3x2x2/Compression_QS_3x2x2.xml",
    "Bar_TwoDisconnectedPieces_QS/Bar.xml",
    "PrecrackedPlate/PrecrackedPlate.xml",
    "PrecrackedPlateTwoCracks/PrecrackedPlate.xml",
    "CompressionImplicit_2x1x1/CompressionImplicit_2x1x1.xml",
    "BondBreakingInitialVelocity_TimeDependentCS/BondBreakingInitialVelocity.xml",
    "MultipleOutputFiles/MultipleOutputFiles.xml",
    "Compression_2x1x1/Compression_2x1x1.yaml",
    "Contact_2x1x1/Contact_2x1x1.xml",
    "Compression_QS_Explicit_MultiFreqOutput_3x2x2/Compression_QS_Explicit_MultiFreqOutput_3x2x2.xml",
]


@pytest.mark.parametrize("deck", [_marked(d) for d in CONVERTED])
def test_converted_deck_runs_the_same(tmp_path, deck):
    """``peridyn convert DECK -o case.yaml`` then ``peridyn run case.yaml`` writes the Exodus
    files that running the deck writes, value for value (the same case, so the same bits)."""
    case = tmp_path / "case" / "case.yaml"
    case.parent.mkdir()
    assert main(["convert", str(CORPUS / deck), "-o", str(case)]) == 0
    quiet = ["--no-progress", "--json"]
    assert main(["run", str(CORPUS / deck), "-o", str(tmp_path / "deck"), *quiet]) == 0
    assert main(["run", str(case), "-o", str(tmp_path / "converted"), *quiet]) == 0
    written = sorted(p.name for p in (tmp_path / "deck").iterdir() if p.suffix in (".e", ".h"))
    assert written and written == sorted(
        p.name for p in (tmp_path / "converted").iterdir() if p.suffix in (".e", ".h")
    )
    for name in written:
        a, b = read_exodus(tmp_path / "deck" / name), read_exodus(tmp_path / "converted" / name)
        assert np.array_equal(a.times, b.times) and np.array_equal(a.coordinates, b.coordinates)
        for kind in ("nodal_variables", "element_variables", "global_variables"):
            mine, theirs = getattr(a, kind), getattr(b, kind)
            assert mine.keys() == theirs.keys()
            for key in mine:
                assert np.array_equal(mine[key], theirs[key]), (name, key)
