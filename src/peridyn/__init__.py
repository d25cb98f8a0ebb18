"""peridyn: peridynamics for waves, vibration and damage in solids.

A whole run in Python: a body (``geometry``), its bonds (``find_bonds``), a
material model (``make_model``), loads on node sets (``Loading`` with
``BoundaryCondition``), a solver (``ExplicitSolver`` or ``relax``), and
``solver.run``. Case files do the same through ``load_case`` and ``run_case``; a sweep file
(many runs) through ``run_sweep``, its dataset read back with ``load_sweep``.
"""

from peridyn.discretization import geometry
from peridyn.discretization.body import Body
from peridyn.discretization.bonds import Bonds, find_bonds
from peridyn.errors import CaseFileError, InputError, InstabilityError, PeridynError
from peridyn.io.case import load_case
from peridyn.io.dataset import load_sweep
from peridyn.io.provenance import package_version
from peridyn.jobs.run import run_case
from peridyn.jobs.sweep import run_sweep
from peridyn.physics.damage import BondDamage, damage_field
from peridyn.physics.loads import BoundaryCondition, InitialCondition, Loading
from peridyn.physics.materials import LPSModel, PMBModel, make_model
from peridyn.solvers import ExplicitSolver, State, relax

__version__ = package_version()

__all__ = [
    "Body",
    "BondDamage",
    "Bonds",
    "BoundaryCondition",
    "CaseFileError",
    "ExplicitSolver",
    "InitialCondition",
    "InputError",
    "InstabilityError",
    "LPSModel",
    "Loading",
    "PMBModel",
    "PeridynError",
    "State",
    "__version__",
    "damage_field",
    "find_bonds",
    "geometry",
    "load_case",
    "load_sweep",
    "make_model",
    "relax",
    "run_case",
    "run_sweep",
]
