"""The material registry (``peridyn.physics.materials.registry``) and the one-file test material.

``make_model`` has no per-material branch: it builds whatever is registered, including the
test-only "conical" material of tests/materials/conical_bond.py (registered by conftest),
which also goes through a free-free modal analysis here.
"""

import numpy as np
import pytest
from conftest import MATERIALS, small_body, small_model

from peridyn.discretization.bonds import find_bonds
from peridyn.errors import InputError
from peridyn.linalg.stiffness import assemble_stiffness
from peridyn.physics.materials import MODELS, LPSModel, Model, PMBModel, make_model, register_material
from peridyn.setup.eigensolver import factor_bytes
from peridyn.solvers.modal import modal_analysis


def test_the_shipped_materials_and_the_test_material_are_registered():
    assert MODELS["pmb"] is PMBModel and MODELS["lps"] is LPSModel
    assert "conical" in MODELS
    for name, cls in MODELS.items():
        assert cls.name == name


@pytest.mark.parametrize("name", MATERIALS)
def test_make_model_builds_each_registered_material(name):
    model = small_model(name, 3, n=4, horizon_factor=1.5)
    assert type(model) is MODELS[name]
    assert model.E == 200e9


def test_unknown_material_names_the_choices():
    body = small_body(3, n=4)
    bonds = find_bonds(body, 1.5 * body.spacing)
    with pytest.raises(
        InputError, match=r"unknown material model 'pmv' \(did you mean 'pmb'\?\); choose one of"
    ):
        make_model("pmv", body, bonds, E=200e9, density=7850.0)


def test_float64_lps_reads_the_bonds_lengths_without_a_copy():
    """8 B a bond less (``benchmarks/HISTORY.md``, "What the PMB float64 kernel waits on; ..."): the
    float64 model's ``length`` is the bonds' array; float32 keeps its own rounded copy."""
    body = small_body(3, None, n=4)
    bonds = find_bonds(body, 3.015 * body.spacing)
    lps64, lps32 = (
        make_model("lps", body, bonds, E=200e9, nu=0.25, density=7850.0, dtype=d)
        for d in (np.float64, np.float32)
    )
    assert np.shares_memory(lps64.length, bonds.length)
    assert lps32.length.dtype == np.float32 and not np.shares_memory(lps32.length, bonds.length)


def test_lps_needs_a_poisson_ratio():
    body = small_body(3, n=4)
    bonds = find_bonds(body, 1.5 * body.spacing)
    with pytest.raises(InputError, match="an LPS material needs Poisson's ratio nu"):
        make_model("lps", body, bonds, E=200e9, density=7850.0)


def test_a_taken_name_cannot_be_registered_again():
    with pytest.raises(ValueError, match="'pmb' is taken by peridyn.physics.materials.pmb.PMBModel"):

        @register_material("pmb")
        class Impostor(Model):
            pass

    assert MODELS["pmb"] is PMBModel
    with pytest.raises(TypeError, match="is not a subclass of Model"):
        register_material("not-a-model")(dict)
    assert "not-a-model" not in MODELS


def test_factor_estimate_counts_the_dilatation_unknown():
    """The shift-invert factor of a material with a dilatation (LPS) carries 4 unknowns per
    point (three dofs and theta, ``solvers.modal``), a bond-based one's 3: the nested-dissection
    estimate (``linalg.ordering``) grows with their square."""
    lps, pmb = (small_model(name, 3, n=6, horizon_factor=2.015) for name in ("lps", "pmb"))
    assert lps.has_dilatation and not pmb.has_dilatation
    assert factor_bytes(lps) / factor_bytes(pmb) == pytest.approx((4 / 3) ** 2, rel=1e-12)


@pytest.mark.parametrize("name", MATERIALS)
def test_free_free_modes(name):
    """A free 3D block has six rigid-body modes (K annihilates rigid motions, objectivity) and
    positive elastic modes (the linearised energy is positive semi-definite): the six lowest
    eigenvalues are rigid (|f| below 1e-4 of the highest computed, ``solvers.modal``) and the
    next ones positive, with relative eigen-residuals below 1e-6, the bound the shift-invert modal
    tests use (tests/simulation/test_modal.py; measured here: PMB 1.1e-8, LPS 4e-10, conical 1e-10
    with the solver's fixed start vector)."""
    model = small_model(name, 3, n=6, horizon_factor=2.015)
    K = assemble_stiffness(model)
    assert abs(K - K.T).max() <= 1e-14 * abs(K).max()
    result = modal_analysis(model, n_modes=10)
    assert result.n_rigid == 6
    assert np.all(result.rigid[:6])
    elastic = result.elastic()
    assert np.all(elastic.frequencies > 0)
    assert np.abs(result.frequencies[:6]).max() < 1e-4 * elastic.frequencies.min()
    assert result.residuals.max() < 1e-6


def test_linearisation_is_read_only_and_checks_its_parts():
    """``Model.linearisation()`` is built once and cannot be changed through its arrays; a
    dilatation comes with all its parts, of one length per kind (bonds, points)."""
    from peridyn.physics.materials import BondLinearisation

    model = small_model("lps", 3, n=4, horizon_factor=1.5)
    lin = model.linearisation()
    assert model.linearisation() is lin
    with pytest.raises(ValueError, match="read-only"):
        lin.pair[0] = 1.0
    assert model.theta_coef.flags.writeable  # the model's own arrays stay writable
    ones = np.ones(5)
    with pytest.raises(ValueError, match=r"needs all of .* missing \['p_coef', 'dilatation_energy'\]"):
        BondLinearisation(ones, ones, weight=ones, theta_coef=ones)
    with pytest.raises(ValueError, match="must have one length"):
        BondLinearisation(ones, np.ones(4))
