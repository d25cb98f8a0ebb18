"""Solvers: explicit dynamics (velocity Verlet) and quasi-statics (adaptive dynamic relaxation);
implicit quasi-statics (Newton-Raphson) and dynamics (Newmark)."""

from peridyn.solvers.explicit import ExplicitSolver, State
from peridyn.solvers.newmark import NewmarkSolver
from peridyn.solvers.newton import NewtonResult, newton
from peridyn.solvers.relaxation import RelaxationResult, relax

__all__ = ["ExplicitSolver", "RelaxationResult", "State", "relax", "NewmarkSolver", "NewtonResult", "newton"]
