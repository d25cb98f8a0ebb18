"""Peridigm's test corpus run unchanged (``peridyn run DECK -o OUT``) and compared with its gold
files within each deck's own exodiff tolerances (tests/peridigm_corpus.py; decks, meshes, gold
files and ``.comp`` files from Peridigm's test suite, tests/data/peridigm_corpus): each deck's
outcome is the one docs/peridigm.md shows, and no deck that runs differs from its gold file
unless its row says why."""

import pytest
from peridigm_corpus import decks, documented, run

#: Decks whose run takes more than a few seconds (the slow marker).
SLOW = {
    "Body_Force/Body_Force_Explicit.xml",
    "WaveInBar_MultiBlock/WaveInBar_MultiBlock.xml",
    "Contact_Cubes/Contact_Cubes.xml",
    "DefaultBlocks/DefaultBlocks.xml",
    "InitialDamage/InitialDamage.xml",
    "CentrifugalLoad/CentrifugalLoad.xml",
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
