"""peridyn: peridynamics for waves, vibration and damage in solids.

A whole run in Python: a body (``geometry``), its bonds (``find_bonds``), a
material model (``make_model``), loads on node sets (``Loading`` with
``BoundaryCondition``), a solver (``ExplicitSolver`` or ``relax``), and
``solver.run``. Case files do the same through ``load_case`` and ``run_case``; a sweep file
(many runs) through ``run_sweep``, its dataset read back with ``load_sweep``.
"""

from importlib import import_module

#: public name -> the module that defines it. Imported on first use (PEP 562), so that
#: ``import peridyn.kernels`` or any other lower layer loads nothing above it.
_PUBLIC = {
    "geometry": "peridyn.discretization.geometry",
    "Body": "peridyn.discretization.body",
    "Bonds": "peridyn.discretization.bonds",
    "find_bonds": "peridyn.discretization.bonds",
    "CaseFileError": "peridyn.errors",
    "InputError": "peridyn.errors",
    "InstabilityError": "peridyn.errors",
    "PeridynError": "peridyn.errors",
    "load_case": "peridyn.io.case",
    "load_sweep": "peridyn.io.dataset",
    "run_case": "peridyn.jobs.run",
    "run_sweep": "peridyn.jobs.sweep",
    "run_monitor": "peridyn.jobs.monitor",
    "BondDamage": "peridyn.physics.damage",
    "damage_field": "peridyn.physics.damage",
    "BoundaryCondition": "peridyn.physics.loads",
    "InitialCondition": "peridyn.physics.loads",
    "Loading": "peridyn.physics.loads",
    "LPSModel": "peridyn.physics.materials",
    "PMBModel": "peridyn.physics.materials",
    "make_model": "peridyn.physics.materials",
    "ExplicitSolver": "peridyn.solvers",
    "State": "peridyn.solvers",
    "relax": "peridyn.solvers",
}


def __getattr__(name: str):
    if name == "__version__":
        from peridyn.io.provenance import package_version

        value = package_version()
    elif name in _PUBLIC:
        module = import_module(_PUBLIC[name])
        value = module if module.__name__.endswith(f".{name}") else getattr(module, name)
    else:
        raise AttributeError(f"module 'peridyn' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)


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
    "run_monitor",
    "run_sweep",
]
