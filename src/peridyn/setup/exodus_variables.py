"""Values of Peridigm's named output variables (``output.exodus.variables``) at a state of a
run, for the recorder's Exodus file (``peridyn.io.recorder.variables_exodus``)."""

from __future__ import annotations

import numpy as np

from peridyn.discretization.state import State
from peridyn.errors import CaseFileError
from peridyn.io.exodus_write import PERIDIGM_VARIABLES
from peridyn.physics.damage import damage_field
from peridyn.physics.materials.base import Model

#: Global variables of a variable over a set: its sum, largest or smallest value (per component).
REDUCTIONS = {"sum": np.sum, "maximum": np.max, "minimum": np.min}
#: Variables that only a state-based material has (its per-point dilatation and weighted volume).
STATE_BASED = ("Dilatation", "Weighted_Volume")


def check_variables(case_name: str, model: Model, variables) -> None:
    """Refuse variables the case's material does not define (a bond-based one has no dilatation)."""
    for name in variables:
        if name in STATE_BASED and not model.has_dilatation:
            raise CaseFileError(
                case_name, "output.exodus.variables", name, "a variable of the material (no dilatation)"
            )


def variable_values(model: Model, variables, sums=None, loading=None, force=None):
    """A function of a state (u, v, a: (n_points, 3)) giving the ``variables``' values as
    ``ExodusWriter.append`` takes them: ``{"nodal": {...}, "element": {...}, "global_":
    {...}}``, vectors (n_points, dim), scalars (n_points,), and per ``sums`` entry (name ->
    (variable, node set name[, "sum" | "maximum" | "minimum"])) that variable's sum (or
    extreme) over the set, (dim,) or a scalar. Force density
    is the internal force density (N/m^3) at u, force that times the point's volume (N);
    acceleration the solver's; external force density the body-force density (N/m^3) of
    ``loading`` (a ``Loading``, needed for it) at the state's time; ``Lambda`` Peridigm's
    plastic multiplier, zero (peridyn's materials are elastic). ``force``: a function of the
    state giving the internal force density (the solver's ``internal_force``), else
    ``model.force(state.u)``."""
    sums = sums or {}
    needed = set(variables) | {variable for variable, *_ in sums.values()}
    body = model.body
    dim = body.dim

    def values(state: State) -> dict:
        force_density = None
        if {"Force", "Force_Density"} & needed:
            force_density = (model.force(state.u) if force is None else force(state))[:, :dim]
        computed = {
            "Displacement": lambda: state.u[:, :dim],
            "Velocity": lambda: state.v[:, :dim],
            "Acceleration": lambda: state.a[:, :dim],
            "External_Force_Density": lambda: loading.body_force_density(
                state.time, np.zeros((body.n_points, 3))
            )[:, :dim],
            "Lambda": lambda: np.zeros(body.n_points),
            "Global_Kinetic_Energy": lambda: (
                0.5 * np.sum(model.density * body.volumes * np.sum(state.v**2, axis=1))
            ),
            "Force_Density": lambda: force_density,
            "Force": lambda: force_density * body.volumes[:, None],
            "Element_Id": lambda: np.arange(1.0, body.n_points + 1.0),
            "ID": lambda: np.arange(0.0, body.n_points),
            "Proc_Num": lambda: np.zeros(body.n_points),
            "Volume": lambda: body.volumes,
            "Dilatation": lambda: model.dilatation(state.u),
            "Weighted_Volume": lambda: model.weighted_volume,
            "Stored_Elastic_Energy": lambda: model.energy_density(state.u) * body.volumes,
            "Number_Of_Neighbors": lambda: np.diff(model.bonds.offsets).astype(np.float64),
            "Horizon": lambda: np.broadcast_to(model.bonds.horizons(), (body.n_points,)).astype(np.float64),
            "Damage": lambda: damage_field(model),
        }
        out = {"nodal": {}, "element": {}, "global_": {}}
        for name in variables:
            placement = PERIDIGM_VARIABLES[name][0]
            out["global_" if placement == "global" else placement][name] = computed[name]()
        for name, (variable, set_name, *calculation) in sums.items():
            reduce = REDUCTIONS[calculation[0] if calculation else "sum"]
            out["global_"][name] = reduce(computed[variable]()[body.node_set(set_name)], axis=0)
        return out

    return values


class GatheredVariables:
    """The named variables of an MPI run (``output.exodus`` as a mapping), gathered on rank 0.

    ``collect`` (collective: every rank calls it at a state) computes each rank's values on its
    owned points (``variable_values`` of its part: its ghosts' displacements are current, so
    force densities and dilatations are the serial ones) and gathers them in global point order
    on rank 0, where the object, called with the gathered state, gives them as
    ``variable_values`` does: ``Element_Id`` the global 1-based ids (``ID`` 0-based),
    ``Proc_Num`` each point's rank (as Peridigm writes it), and each of ``sums`` summed over its
    set of the whole body.

    Parameters
    ----------
    domain : Domain
    model : Model
        The rank's part of the model.
    variables : sequence of str
    sums : dict or None
        Name -> (nodal variable, node set name), as ``variable_values``.
    whole_body : Body
        The case's body (its node sets name the sums' points).
    loading : Loading or None
        The rank's part of the loading (for ``External_Force_Density``).
    """

    def __init__(self, domain, model: Model, variables, sums, whole_body, loading=None):
        self.domain, self.whole_body = domain, whole_body
        self.variables, self.sums = list(variables), dict(sums or {})
        whole = [v for v in self.variables if PERIDIGM_VARIABLES[v][0] == "global"]
        if whole:
            raise CaseFileError(
                "<case>", "output.exodus.variables", whole[0], "a per-point variable under MPI"
            )
        needed = self.variables + [v for v, *_ in self.sums.values() if v not in self.variables]
        self._local = variable_values(model, needed, loading=loading)
        self._values: dict | None = None
        self._step: int | None = None

    def collect(self, state: State) -> None:
        """Gather the values at the rank's ``state`` on rank 0 (collective)."""
        local = self._local(state)
        rank = float(self.domain.comm.rank)
        whole = {}
        for placement in ("nodal", "element"):
            for name, values in local[placement].items():
                if name == "Proc_Num":
                    values = np.full(len(values), rank)
                whole[name] = self.domain.gather(np.ascontiguousarray(values))
        self._step = state.step
        if not self.domain.is_root:
            return
        whole["Element_Id"] = np.arange(1.0, self.whole_body.n_points + 1.0)
        whole["ID"] = np.arange(0.0, self.whole_body.n_points)
        out = {"nodal": {}, "element": {}, "global_": {}}
        for name in self.variables:
            out[PERIDIGM_VARIABLES[name][0]][name] = whole[name]
        for name, (variable, set_name, *calculation) in self.sums.items():
            reduce = REDUCTIONS[calculation[0] if calculation else "sum"]
            out["global_"][name] = reduce(whole[variable][self.whole_body.node_set(set_name)], axis=0)
        self._values = out

    def __call__(self, state: State) -> dict:
        """The values gathered by the last ``collect``, which must be of ``state``'s step."""
        if self._step != state.step:
            raise RuntimeError(f"Exodus variables collected at step {self._step}, asked at step {state.step}")
        return self._values
