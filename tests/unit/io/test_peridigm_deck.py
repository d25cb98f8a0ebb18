"""Peridigm decks in: reading XML and YAML decks (``peridyn.io.peridigm_deck``) and their
translation to peridyn cases (``peridyn.io.peridigm_case``), with the refusals that name the
deck parameter. Decks from tests/data/peridigm (Peridigm's test suite)."""

import copy
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from peridyn.cli import main
from peridyn.errors import CaseFileError
from peridyn.io.case import load_case, validate_case
from peridyn.io.exodus import read_exodus
from peridyn.io.peridigm_case import convert_deck, deck_case, exact_moduli_pair, load_deck
from peridyn.io.peridigm_deck import is_peridigm_deck, read_deck
from peridyn.physics.materials.elastic import bulk_modulus, shear_modulus
from peridyn.physics.timefunctions import from_spec
from peridyn.setup.build import build

DATA = Path(__file__).parents[2] / "data" / "peridigm"
WAVE = DATA / "WaveInBar.xml"
COMPRESSION = DATA / "Compression_2x1x1.yaml"


def test_xml_parameters_are_typed():
    """WaveInBar.xml's parameters as their declared types (values as written in the deck)."""
    deck = read_deck(WAVE)
    assert deck["Verbose"] is False
    assert deck["Materials"]["My Elastic Material"]["Density"] == 2200.0
    assert deck["Output"]["Output Frequency"] == 20 and isinstance(deck["Output"]["Output Frequency"], int)
    assert deck["Solver"]["Verlet"]["Fixed dt"] == 9.0659e-08
    assert deck["Boundary Conditions"]["Left Side Initial Velocity"]["Value"] == "-100.0"


def test_yaml_deck_is_the_peridigm_mapping():
    deck = read_deck(COMPRESSION)
    assert deck["Blocks"]["My Group of Blocks"]["Horizon"] == 2.0
    assert is_peridigm_deck(COMPRESSION) and is_peridigm_deck(WAVE)
    assert not is_peridigm_deck(Path(__file__).parents[3] / "cases" / "bar_pulse.yaml")


@pytest.mark.parametrize(
    "text, key",
    [
        ('<ParameterList><Parameter name="A" type="double" value="x"/></ParameterList>', "A"),
        ('<ParameterList><Parameter name="A" type="float" value="1"/></ParameterList>', "A (type)"),
        (
            '<ParameterList><Parameter name="A" type="int" value="1"/>'
            '<Parameter name="A" type="int" value="2"/></ParameterList>',
            "A",
        ),
        ("<ParameterList><Parameter", "<file>"),
        ("<Other/>", "<root>"),
    ],
)
def test_bad_xml_names_the_parameter(tmp_path, text, key):
    deck = tmp_path / "deck.xml"
    deck.write_text(text)
    with pytest.raises(CaseFileError) as err:
        read_deck(deck)
    assert err.value.key == key


def test_translation_of_a_pdquickgrid_deck():
    """Compression_2x1x1: two cells of 2 x 1 x 1 m from x = -2 m, LPS with K = 130 GPa and
    mu = 78 GPa (E = 9 K mu / (3 K + mu) = 195 GPa, nu = 0.25), floor(5e-5 / 1e-5) = 5 steps,
    the node sets' 1-based ids as 0-based points, and the deck's Exodus file and variables."""
    case = load_deck(COMPRESSION)
    assert case.geometry.size == [4.0, 1.0, 1.0] and case.geometry.origin == [-2.0, -0.5, -0.5]
    assert case.discretization.spacing == [2.0, 1.0, 1.0] and case.discretization.partial_volumes is False
    assert case.material.E == pytest.approx(195e9, rel=1e-15) and case.material.nu == pytest.approx(0.25)
    assert (case.solver.steps, case.solver.dt) == (5, 1e-5)
    assert case.node_sets["Min X Node Set"].indices == [0]
    assert case.node_sets["Max X Node Set"].indices == [1]
    assert case.output.exodus.file == "Compression_2x1x1.e" and case.output.exodus.every == 1
    assert "Stored_Elastic_Energy" in case.output.exodus.variables


def test_pdquickgrid_ids_are_x_fastest():
    """PdQuickGrid numbers its points x fastest; peridyn's box z fastest: id 2 of a 2 x 2 x 2
    grid is (i, j, k) = (1, 0, 0), peridyn's point 4."""
    deck = read_deck(COMPRESSION)
    grid = deck["Discretization"]["TensorProduct3DMeshGenerator"]
    grid.update({"Number Points X": 2, "Number Points Y": 2, "Number Points Z": 2, "Y Length": 2.0})
    grid["Z Length"] = 2.0
    deck["Discretization"]["NeighborhoodType"] = "Spherical"
    deck["Boundary Conditions"]["Max X Node Set"] = "2 3"
    case = deck_case(deck, "grid")
    assert case["node_sets"]["Max X Node Set"]["indices"] == [2, 4]


def test_older_deck_form():
    """Peridigm's older form (BondBreakingInitialVelocity.xml, tests/data/peridigm_other): the
    horizon under Discretization for every block, "Linear Elastic" the LPS model of "Elastic",
    node ids 0-based (id 1 of its 2 x 2 x 1 grid is (i, j) = (1, 0), peridyn's point 2), and
    its box families of horizon 0.51 m on spacings (1.05, 1, 1) m: one cell along y only; with
    0.4 m, none: its points are kept without bonds, with a warning, as Peridigm keeps them."""
    older = read_deck(DATA.parent / "peridigm_other" / "BondBreakingInitialVelocity.xml")
    case = deck_case(older, "older")
    assert case["discretization"]["horizon_m"] == 0.51
    assert case["material"]["model"] == "lps"
    assert case["node_sets"]["Node Set 1"]["indices"] == [2]
    bonds = build(validate_case(case)).bonds
    assert np.diff(bonds.offsets).tolist() == [1, 1, 1, 1]
    assert bonds.neighbours.tolist() == [1, 0, 3, 2]  # (0, 0)-(0, 1) and (1, 0)-(1, 1)
    deck = copy.deepcopy(older)
    deck["Blocks"]["My Group of Blocks"]["Horizon"] = 0.51
    _refusal(deck, "Blocks.My Group of Blocks.Horizon")
    deck = copy.deepcopy(older)
    deck["Boundary Conditions"]["Node Set 0"] = "4"
    assert _refusal(deck, "Boundary Conditions.Node Set 0").value == 4
    deck["Discretization"]["Horizon"] = 0.4  # round(0.4 / 1.0) = 0 cells along every axis
    # Peridigm keeps points without neighbours (they move freely): a warning names them
    case = validate_case(deck_case(older | {"Discretization": deck["Discretization"]}, "older"))
    with pytest.warns(UserWarning, match="4 points have no neighbour within the horizon"):
        assert build(case).bonds.n_bonds == 0


def test_2d_deck_translation_and_refusals():
    """A 2D bond-based deck (ElasticBondBased2DPlaneStress.yaml): a 2D Exodus geometry of the
    deck's Height and plane, E = 4 K / 3 in plane stress (1.25 K in plane strain), so that
    peridyn's 12 kappa / (pi t delta^3) with the plane bulk modulus kappa is Peridigm's
    12 K / (pi h delta^3); a plane flag on another model, Height alone and a 2D material on a
    (3D) PdQuickGrid are refused by name."""
    other = DATA.parent / "peridigm_other"
    deck = read_deck(other / "ElasticBondBased2DPlaneStress.yaml")
    material = deck["Materials"]["My Elastic Bond Based Material"]
    with pytest.raises(CaseFileError) as err:
        deck_case(deck, "2d", "deck.yaml", other)
    assert err.value.key == "Discretization.Input Mesh File"
    deck["Discretization"]["Input Mesh File"] = "ElasticBondBased3D.g"  # a mesh that exists here
    case = deck_case(deck, "2d", "deck.yaml", DATA)
    assert case["geometry"] | {"file": None} == {"type": "exodus", "file": None, "dimension": 2} | {
        "plane": "stress",
        "thickness": 0.25,
    }
    assert case["material"]["E"] == 4.0 / 3.0 * material["Bulk Modulus"]
    strain = copy.deepcopy(deck)
    strain["Materials"]["My Elastic Bond Based Material"] |= {"Plane Stress": False, "Plane Strain": True}
    assert deck_case(strain, "2d", "deck.yaml", DATA)["material"]["E"] == 1.25 * material["Bulk Modulus"]
    lps = copy.deepcopy(deck)
    lps["Materials"]["My Elastic Bond Based Material"] |= {"Material Model": "Elastic", "Shear Modulus": 1e11}
    _refusal(lps, "Materials.My Elastic Bond Based Material.Plane Stress")
    height_only = copy.deepcopy(deck)
    height_only["Materials"]["My Elastic Bond Based Material"]["Plane Stress"] = False
    _refusal(height_only, "Materials.My Elastic Bond Based Material.Height")
    grid = read_deck(COMPRESSION)
    grid["Materials"]["My Elastic Material"] = dict(material)
    _refusal(grid, "Discretization.Type")


def _refusal(deck: dict, key_start: str, folder=DATA):
    with pytest.raises(CaseFileError) as err:
        deck_case(deck, "x", "deck.yaml", folder)
    assert err.value.key.startswith(key_start), err.value
    return err.value


def test_refusals_name_the_deck_parameter():
    base = read_deck(COMPRESSION)
    deck = copy.deepcopy(base)
    deck["Blocks"]["Other"] = dict(deck["Blocks"]["My Group of Blocks"])
    _refusal(deck, "Blocks")
    deck = copy.deepcopy(base)
    deck["Materials"]["My Elastic Material"]["Material Model"] = "Viscoplastic"
    _refusal(deck, "Materials.My Elastic Material.Material Model")
    deck["Materials"]["My Elastic Material"].update(
        {"Material Model": "Linear LPS", "Apply Shear Correction Factor": True}
    )
    _refusal(deck, "Materials.My Elastic Material.Apply Shear Correction Factor")
    deck = copy.deepcopy(base)
    deck["Solver"]["Implicit"] = deck["Solver"].pop("Verlet")
    _refusal(deck, "Solver")
    deck = copy.deepcopy(base)
    deck["Solver"]["Verlet"]["Safety Factor"] = 1.5
    _refusal(deck, "Solver.Verlet.Safety Factor")
    deck = copy.deepcopy(base)
    deck["Solver"]["Verlet"]["Number of Steps"] = 10
    _refusal(deck, "Solver.Verlet.Number of Steps")
    deck = copy.deepcopy(base)
    deck["Output"]["Output Variables"]["Partial_Stress"] = True
    _refusal(deck, "Output.Output Variables.Partial_Stress")
    deck = copy.deepcopy(base)
    deck["Contact"] = {"Search Radius": 0.1}
    _refusal(deck, "Contact")
    deck = copy.deepcopy(base)
    deck["Boundary Conditions"]["Initial Velocity Min X Face"]["Node Set"] = "Nowhere"
    _refusal(deck, "Boundary Conditions.Initial Velocity Min X Face.Node Set")
    deck = copy.deepcopy(base)
    deck["Solver"]["Initial Time"] = 1e-6
    _refusal(deck, "Solver.Initial Time")


def test_pdquickgrid_families_are_boxes():
    """A 3 x 3 x 1 grid of unit cells with horizon 1.2: PdQuickGrid's box of round(1.2) = 1 cell
    holds the diagonal neighbours at sqrt(2) = 1.41 m (8 around the centre point), the sphere
    |xi| <= 1.2 m of ``NeighborhoodType: Spherical`` only the 4 along the axes."""
    deck = read_deck(COMPRESSION)
    grid = deck["Discretization"]["TensorProduct3DMeshGenerator"]
    grid.update({"Number Points X": 3, "Number Points Y": 3, "X Length": 3.0, "Y Length": 3.0})
    deck["Blocks"]["My Group of Blocks"]["Horizon"] = 1.2
    deck["Boundary Conditions"]["Max X Node Set"] = "9"
    counts = {}
    for kind in ("box", "Spherical"):
        if kind == "Spherical":
            deck["Discretization"]["NeighborhoodType"] = kind
        case = validate_case(deck_case(deck, "grid"))
        assert case.discretization.neighbourhood == ("box" if kind == "box" else "sphere")
        counts[kind] = np.diff(build(case).bonds.offsets)
    assert counts["box"][4] == 8 and counts["Spherical"][4] == 4
    assert counts["box"].tolist() == [3, 5, 3, 5, 8, 5, 3, 5, 3]
    deck["Discretization"]["NeighborhoodType"] = "Cubic"
    _refusal(deck, "Discretization.NeighborhoodType")


def test_convert_writes_a_case_that_loads_as_the_deck(tmp_path):
    """``peridyn convert DECK -o case.yaml`` writes the case that ``peridyn run DECK`` runs."""
    out = tmp_path / "case.yaml"
    assert main(["convert", str(WAVE), "-o", str(out)]) == 0
    written, deck = load_case(out), load_deck(WAVE)
    assert (tmp_path / written.geometry.file).resolve() == Path(deck.geometry.file)
    written.geometry.file = deck.geometry.file
    assert written == deck
    assert main(["validate", str(WAVE), "--json"]) == 0  # validate reads decks as run does
    assert convert_deck(WAVE)["geometry"]["file"] == str((DATA / "WaveInBar.g").resolve())


def test_converted_case_moves_with_its_mesh(tmp_path):
    """The case that ``convert -o`` writes names its mesh relative to its own folder: a folder
    holding the deck, its mesh and the case, moved elsewhere, still runs (the mesh of 1000
    points is found)."""
    first = tmp_path / "first"
    (first / "cases").mkdir(parents=True)
    for name in ("WaveInBar.xml", "WaveInBar.g"):
        shutil.copy(DATA / name, first / name)
    assert main(["convert", str(first / "WaveInBar.xml"), "-o", str(first / "cases/case.yaml")]) == 0
    assert yaml.safe_load((first / "cases/case.yaml").read_text())["geometry"]["file"] == "../WaveInBar.g"
    moved = shutil.move(first, tmp_path / "moved")
    setup = build(load_case(Path(moved) / "cases/case.yaml"), Path(moved) / "cases")
    assert setup.body.n_points == read_exodus(DATA / "WaveInBar.g").n_elements


def test_translation_of_expressions_and_compute_classes():
    """ElasticBondBased3D: prescribed displacements, one an expression in y and t; the bulk
    modulus alone (E = 1.5 K: peridyn's PMB has nu = 1/4, K = E / (3 (1 - 2 nu))); the
    "Block_Data" sums as global outputs; Peridigm's velocity of prescribed points."""
    case = load_deck(DATA / "ElasticBondBased3D.yaml")
    assert case.material.model == "pmb" and case.material.E == 1.5 * 200e9
    values = [bc.value for bc in case.boundary_conditions]
    assert values == [0.0, {"type": "expression", "text": "0.001*y*t/1.0e-8"}, 0.0]
    assert [bc.kind for bc in case.boundary_conditions] == ["displacement"] * 3
    assert case.solver.prescribed_velocity == "difference"
    sums = case.output.exodus.sums
    assert (sums["Top_Reaction_Force"].variable, sums["Top_Reaction_Force"].set) == ("Force", "block_3")
    assert "Top_Reaction_Force" not in case.output.exodus.variables


def test_bad_expressions_and_compute_classes_are_refused():
    base = read_deck(DATA / "ElasticBondBased3D.yaml")
    deck = copy.deepcopy(base)
    deck["Boundary Conditions"]["Prescribed Displacement Y"]["Value"] = "open('x').read()"
    _refusal(deck, "Boundary Conditions.Prescribed Displacement Y.Value")
    deck = copy.deepcopy(base)
    deck["Compute Class Parameters"]["Top Reaction Force"]["Calculation Type"] = "Average"
    _refusal(deck, "Compute Class Parameters.Top Reaction Force.Calculation Type")
    deck = copy.deepcopy(base)
    deck["Output1"]["Output Variables"]["Dilatation"] = True
    _refusal(deck, "Output1.Output Variables.Dilatation")


def test_translation_of_a_quasi_static_text_file_deck():
    """Compression_QS_3x2x2_TextFile: the text mesh, node sets from files and inline lists
    (1-based ids), QuasiStatic as 20 Newton load steps to the final time converged on the
    absolute residual, at most 10 iterations each."""
    folder = DATA / "Compression_QS_3x2x2_TextFile"
    case = load_deck(folder / "Compression_QS_3x2x2_TextFile.xml")
    assert case.geometry.type == "mesh"
    assert case.node_sets["Node Set One"].indices == [0, 1, 2, 3]
    assert case.node_sets["Node Set Two"].indices == [8, 9, 10, 11]
    assert case.node_sets["Node Set Three"].indices == [1, 3]
    s = case.solver
    assert (s.type, s.time, s.load_steps, s.absolute_tolerance, s.newton_iterations) == (
        "newton",
        5e-5,
        20,
        1e-2,
        10,
    )
    deck = read_deck(folder / "Compression_QS_3x2x2_TextFile.xml")
    deck["Solver"]["QuasiStatic"]["Stabilization Type"] = "Kinetic"
    _refusal(deck, "Solver.QuasiStatic.Stabilization Type", folder)
    deck = read_deck(folder / "Compression_QS_3x2x2_TextFile.xml")
    deck["Boundary Conditions"]["Node Set One"] = "missing.txt"
    with pytest.raises(CaseFileError, match="Node Set One"):
        deck_case(deck, "x", "deck.xml", folder)


def test_critical_stretch_damage():
    """A block's "Critical Stretch" damage model becomes the material's critical stretch, a
    "Time Dependent Critical Stretch" of two values a step in time; other damage models are
    refused naming the parameter."""
    deck = read_deck(WAVE)
    deck["Damage Models"] = {"My Damage": {"Damage Model": "Critical Stretch", "Critical Stretch": 5e-4}}
    deck["Blocks"]["My Group of Blocks"]["Damage Model"] = "My Damage"
    case = validate_case(deck_case(deck, "wave", str(WAVE), DATA))
    assert case.material.damage.critical_stretch == 5e-4
    deck["Damage Models"]["My Damage"] = {
        "Damage Model": "Time Dependent Critical Stretch",
        "Time Dependent Critical Stretch": " if(t < 2.0e-5){ value = 50.0; } else{ value = 5e-4; } ",
    }
    stretch = validate_case(deck_case(deck, "wave", str(WAVE), DATA)).material.damage.critical_stretch
    below = math.nextafter(2e-5, -math.inf)  # t < T: the step holds up to the float below T
    assert stretch == {"type": "step", "time": below, "before": 50.0, "after": 5e-4}
    schedule = from_spec(stretch)
    assert (schedule(below), schedule(2e-5)) == (50.0, 5e-4)
    deck["Damage Models"]["My Damage"]["Time Dependent Critical Stretch"] = "0.01*t"
    _refusal(deck, "Damage Models.My Damage.Time Dependent Critical Stretch")
    deck["Damage Models"]["My Damage"] = {"Damage Model": "Interface Aware", "Critical Stretch": 5e-4}
    _refusal(deck, "Damage Models.My Damage.Damage Model")
    deck["Blocks"]["My Group of Blocks"]["Damage Model"] = "Other"
    _refusal(deck, "Damage Models.Other")


def test_moduli_reach_lps_to_the_bit():
    """A deck's bulk and shear moduli reach peridyn's LPS unchanged: the plain conversion of
    K = 130 GPa, mu = 78 GPa (Peridigm's Compression decks) to E and nu comes back 1 ulp off
    in both, the translated material's E and nu give them back exactly (a modulus one bit off
    is a force one bit off, above those decks' 1e-9 N tolerance on 1e8 N)."""
    K, mu = 130.0e9, 78.0e9
    E, nu = 9.0 * K * mu / (3.0 * K + mu), (3.0 * K - 2.0 * mu) / (2.0 * (3.0 * K + mu))
    assert (bulk_modulus(E, nu), shear_modulus(E, nu)) != (K, mu)
    material = deck_case(read_deck(COMPRESSION), "c")["material"]
    assert bulk_modulus(material["E"], material["nu"]) == K
    assert shear_modulus(material["E"], material["nu"]) == mu
    assert material["E"] == pytest.approx(E, rel=1e-15) and material["nu"] == pytest.approx(nu, rel=1e-15)


def test_moduli_search_keeps_nu_below_one_half():
    """A shear modulus far below the bulk modulus (5e-324 Pa, the smallest float: a damaged deck
    the fuzz campaign made) puts nu a few ulps below 1/2; the search for the exact pair must not
    step onto nu = 1/2, where K = E / (3 (1 - 2 nu)) divides by zero: it returns the given pair."""
    K, mu = 130.0e9, 5e-324
    E, nu = 9.0 * K * mu / (3.0 * K + mu), (3.0 * K - 2.0 * mu) / (2.0 * (3.0 * K + mu))
    assert exact_moduli_pair(E, nu, K, mu) == (E, nu)


SEQUENCE = (
    Path(__file__).parents[2]
    / "data"
    / "peridigm_corpus"
    / "Compression_QS_Explicit_MultiFreqOutput_3x2x2"
    / "Compression_QS_Explicit_MultiFreqOutput_3x2x2.xml"
)


def test_translation_of_a_sequence_of_solvers():
    """Compression_QS_Explicit_MultiFreqOutput_3x2x2 (Peridigm's corpus): Solver1 QuasiStatic,
    20 load steps to 5e-5 s, then Solver2 Verlet from 5e-5 s to 1e-4 s in steps of 1e-7 s as
    ``solver.then`` (floor(5e-5 / 1e-7) = 500 steps, Peridigm's count); Output1 and Output2
    with their Initial and Final Output Steps as the files' step windows."""
    case = load_deck(SEQUENCE)
    s = case.solver
    assert (s.type, s.time, s.load_steps) == ("newton", 5e-5, 20)
    assert (s.then.dt, s.then.steps, s.then.prescribed_velocity) == (1e-7, 500, "difference")
    qs, explicit = case.output.exodus, case.output.exodus_more[0]
    assert (qs.file, qs.every, qs.first_step, qs.last_step) == (
        "Compression_QS_Explicit_MultiFreqOutput_3x2x2_QS.e",
        1,
        0,
        20,
    )
    assert (explicit.every, explicit.first_step, explicit.last_step) == (100, 21, None)


def test_refused_sequences_name_the_solver_list():
    """Only a quasi-static solver followed by a Verlet one with a fixed step, from the time
    where the first ends, is run; other sequences are refused at the list that breaks it."""
    folder = SEQUENCE.parent
    base = read_deck(SEQUENCE)
    deck = copy.deepcopy(base)
    deck["Solver3"] = copy.deepcopy(deck["Solver2"])
    _refusal(deck, "Solver3", folder)
    deck = copy.deepcopy(base)
    deck["Solver1"], deck["Solver2"] = deck["Solver2"], deck["Solver1"]
    _refusal(deck, "Solver1.Initial Time", folder)  # a Verlet list first, from 5e-5 s
    deck = copy.deepcopy(base)
    deck["Solver2"]["Initial Time"] = 4e-5
    _refusal(deck, "Solver2.Initial Time", folder)
    deck = copy.deepcopy(base)
    del deck["Solver2"]["Verlet"]["Fixed dt"]
    _refusal(deck, "Solver2.Verlet.Fixed dt", folder)
    deck = copy.deepcopy(base)
    deck["Solver"] = deck.pop("Solver1")
    _refusal(deck, "Solver", folder)
    with pytest.raises(CaseFileError, match="then"):
        validate_case(
            {
                **convert_deck(SEQUENCE),
                "solver": {"type": "explicit", "steps": 1, "then": {"dt": 1e-7, "steps": 1}},
            }
        )
    deck = copy.deepcopy(base)
    deck["Output1"]["Final Output Step"] = -1
    _refusal(deck, "Output1.Final Output Step", folder)
    deck = copy.deepcopy(base)  # two lists of one file: one window
    deck["Output2"].update({"Output Filename": deck["Output1"]["Output Filename"], "Output Frequency": 1})
    _refusal(deck, "Output2.Initial Output Step", folder)
