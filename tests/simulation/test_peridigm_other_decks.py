"""Other decks of Peridigm's test suite (tests/data/peridigm_other, texts only: their Exodus
meshes were not available): each is refused with a CaseFileError naming the deck parameter
that peridyn cannot run, before any mesh is looked for (docs/peridigm.md lists them)."""

from pathlib import Path

import pytest

from peridyn.errors import CaseFileError
from peridyn.io.peridigm_case import convert_deck

OTHER = Path(__file__).parents[1] / "data" / "peridigm_other"


@pytest.mark.parametrize(
    "deck, key, value",
    [
        (
            "LinearLPSBar.yaml",
            "Materials.Linearized LPS Material.Material Model",
            "Linear LPS Partial Volume",
        ),
        ("ElasticBondBased2DPlaneStress.yaml", "Materials.My Elastic Bond Based Material.Plane Stress", None),
        ("BondBreakingInitialVelocity.xml", "Blocks.My Group of Blocks.Horizon", None),
    ],
)
def test_other_peridigm_decks_are_refused_by_parameter(deck, key, value):
    with pytest.raises(CaseFileError) as err:
        convert_deck(OTHER / deck)
    assert (err.value.key, err.value.value) == (key, value)
