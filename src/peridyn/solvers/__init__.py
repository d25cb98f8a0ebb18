"""Solvers: explicit dynamics (velocity Verlet) and quasi-statics (adaptive dynamic relaxation)."""

from peridyn.solvers.explicit import ExplicitSolver, State
from peridyn.solvers.static import RelaxationResult, relax

__all__ = ["ExplicitSolver", "RelaxationResult", "State", "relax"]
