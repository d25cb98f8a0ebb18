"""peridyn: peridynamics for waves, vibration and damage in solids.

A whole run in Python: a body (``geometry``), its bonds (``find_bonds``), a
material model (``make_model``), loads on node sets (``Loading`` with
``BoundaryCondition``), a solver (``ExplicitSolver`` or ``relax``), and
``solver.run``. Case files do the same through ``load_case`` and ``run_case``.
"""

__version__ = "0.1.0"

from peridyn.discretization import geometry  # noqa: E402
from peridyn.discretization.body import Body  # noqa: E402
from peridyn.discretization.bonds import Bonds, find_bonds  # noqa: E402
from peridyn.errors import CaseFileError, InputError, InstabilityError, PeridynError  # noqa: E402
from peridyn.io.case import load_case  # noqa: E402
from peridyn.jobs.run import run_case  # noqa: E402
from peridyn.physics.damage import BondDamage, damage_field  # noqa: E402
from peridyn.physics.loads import BoundaryCondition, InitialCondition, Loading  # noqa: E402
from peridyn.physics.materials import LPSModel, PMBModel, make_model  # noqa: E402
from peridyn.solvers import ExplicitSolver, State, relax  # noqa: E402

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
    "make_model",
    "relax",
    "run_case",
]
