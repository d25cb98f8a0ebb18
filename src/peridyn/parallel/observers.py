"""Observers of a run that live on rank 0 (recorder, crack history) fed with the whole body.

``RootObservers`` is the one observer every rank attaches. At a step where one of its observers
is due, the ranks gather the state (and the damage index) in global point order on rank 0,
which calls the observers with it; their errors reach every rank (``Domain.on_root``). At a step
where only a recorder's series are due (``attach``'s ``series``; the Lamb plate case records them at
every step) the ranks check the state together (``Domain.check_state``) and gather only the
values at the probe points (``peridyn.parallel.points.PointGather``). Per-point
tensors (``output.stress``, ``output.strain``) are computed by each rank on its owned points
(their families and the neighbours' displacements are on the rank) and gathered likewise for
the final state (the VTU snapshots are written per rank: ``peridyn.io.vtu_pieces``). In one
process the observers get the run's own state, and the damage and tensors are computed when
asked.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence

import numpy as np

from peridyn.discretization.state import ProbeState, State
from peridyn.parallel.domain import Domain
from peridyn.parallel.points import PointGather
from peridyn.physics.damage import damage_field


class RootObservers:
    """Observers called on rank 0 with the gathered state.

    Parameters
    ----------
    domain : Domain
    model : Model
        The rank's part of the model (its ``bonds.intact`` gives the damage index).

    tensors : callable (u) -> dict of str to array, or None
        The rank's per-point tensor fields at its local displacement ``u`` (n_local, 3), m
        (``peridyn.setup.recording.point_tensors``); None: none asked.

    The observers are given by ``attach`` (they may take ``damage`` as their damage index and
    ``tensor_fields`` as their tensors).
    """

    def __init__(self, domain: Domain, model, tensors=None):
        self.domain = domain
        self.model = model
        self.tensors = tensors
        self.observers: list = []
        self.due: list = []
        self.prepare: list = []
        self.damage_due: list | None = None
        self._damage: np.ndarray | None = None
        self._tensors: dict = {}
        self._series = None  # (due, PointGather, record, runaway limit) under MPI
        self._device_probes = False  # the series come from ``attach``'s ``device_probes``

    def attach(
        self,
        observers: Sequence,
        due: Sequence[Callable[[int], bool]],
        prepare=(),
        damage_due=None,
        series=None,
        device_probes=None,
    ) -> None:
        """Watch with ``observers`` (objects with ``observe(state, solver)``, used on rank 0 only:
        None elsewhere) at the steps where one of ``due`` (callables step -> bool, known on every
        rank) is True; ``prepare``: (due, collective callable(state)) pairs run on every rank
        first at their steps, with the rank's state (e.g. gathering the bonds' intact mask for a
        checkpoint, writing the pieces of a VTU snapshot). ``damage_due``: callables step ->
        bool, the steps at which an observer reads ``damage`` (the damage index, a pass over
        every bond, is then computed and gathered); None: at every step observed.

        ``series``: None, or ``(due, u_points, v_points, record)``: at a step where ``due``
        (step -> bool) is True and none of ``due`` is, the ranks check the whole state
        (``Domain.check_state``: an unsound one raises InstabilityError on every rank), gather
        u at the global points ``u_points`` (k,) and v at ``v_points`` (s,) only, and rank 0
        calls ``record`` (a callable, None elsewhere) with that ``ProbeState``: a recorder's
        ``record_series`` with its ``Probes``. Collective; several ranks only (in one process
        the observers see the state itself), or in one process with ``device_probes``: a
        callable ``(state, u_points, v_points, limit) -> (u, v)`` that checks the state where it
        lives and returns the probe points' values (the GPU backend's ``probe_values``), so that
        a series-only step reads those points only."""
        self.observers = list(observers) if self.domain.is_root else []
        self.due = list(due)
        self.prepare = list(prepare)
        self.damage_due = None if damage_due is None else list(damage_due)
        self._series = None
        self._device_probes = device_probes is not None and self.domain.size == 1
        if series is not None and (self.domain.size > 1 or self._device_probes):
            series_due, u_points, v_points, record = series
            limit = self.domain.runaway_limit(self.model.body.points)
            if self._device_probes:
                gather = functools.partial(device_probes, u_points=u_points, v_points=v_points, limit=limit)
            else:
                gather = PointGather(self.domain, u_points, v_points)
            self._series = series_due, gather, record, limit

    def detach(self) -> None:
        """Forget ``attach``'s observers. Observers hold this object's ``damage``: until they are
        detached, the two keep each other, and the run's model, alive (a reference cycle that only
        a garbage collection frees; a sweep worker would grow by a model per run)."""
        self.observers, self.due, self.prepare, self.damage_due, self._series = [], [], [], None, None

    def damage(self) -> np.ndarray:
        """The damage index (n_points,) of the whole body at the last gathered state (rank 0)."""
        if self.domain.size == 1:
            return damage_field(self.model)
        return self._damage

    def tensor_fields(self, u: np.ndarray) -> dict:
        """The whole body's tensor fields gathered by the last ``call`` with ``tensors`` (rank 0,
        several ranks; ``u`` is that call's gathered displacement): the ``tensors`` of a
        ``Recorder`` on rank 0."""
        return self._tensors

    def observe(self, state: State, solver) -> None:
        """Gather and call the observers when one is due (every rank calls it); in one process,
        call them at every step (nothing to gather). At a step with only the series due, gather
        the probe points' values and record them (``attach``'s ``series``)."""
        serial = self.domain.size == 1 and self._series is None
        if serial or any(due(state.step) for due in self.due):
            for due, prepare in self.prepare:
                if due(state.step):
                    prepare(state)
            damage = self.damage_due is None or any(due(state.step) for due in self.damage_due)
            self.call(
                state, lambda whole: [obs.observe(whole, solver) for obs in self.observers], damage=damage
            )
        elif self._series is not None and self._series[0](state.step):
            self.record_probes(state)

    def record_probes(self, state: State) -> None:
        """The series record of ``attach``'s ``series`` at ``state`` (collective)."""
        _, gather, record, limit = self._series
        if self._device_probes:  # checked where the state lives
            values = gather(state)
        else:
            self.domain.check_state(state, limit)
            values = gather(state.u, state.v)
        probe = None if values is None else ProbeState(*values, state.time, state.step)
        self.domain.on_root(record, probe)

    def finish(self, state: State, recorder) -> None:
        """``recorder.finish`` (rank 0's ``Recorder``, None elsewhere) at the final ``state``,
        without the whole state on rank 0: under MPI each field (``Recorder.final_keys``) is
        gathered, written and dropped before the next, so that rank 0 holds one field of the
        whole body at a time, not u, v, a and the damage index together (collective). With
        tensor fields asked for, or in one process, ``recorder.finish`` with the whole state."""
        if self.domain.size == 1 or self.tensors is not None:
            self.call(state, lambda whole: recorder.finish(whole), True)
            return
        keys = self.domain.from_root(lambda: recorder.final_keys())
        local = {"u": lambda: state.u, "v": lambda: state.v, "damage": lambda: damage_field(self.model)}
        for key in keys:
            self.domain.on_root(
                lambda key, whole: recorder.write_final(key, whole), key, self.domain.gather(local[key]())
            )
        self.domain.on_root(lambda: recorder.finished())

    def record(self, state: State, recorder, probes) -> None:
        """The series record and the snapshot of ``state`` by ``recorder`` (rank 0's
        ``Recorder``, None elsewhere; a run's first record, without an Exodus record), its
        series at ``probes``' points (``Probes``): under MPI the ranks check the state together
        (``Domain.check_state``), gather the probe points' values for the series and u alone
        for the snapshot (collective); in one process from ``state`` itself."""
        d = self.domain
        if d.size == 1:
            recorder.record_series(state)
            recorder.snapshot(state)
            return
        d.check_state(state, d.runaway_limit(self.model.body.points))
        values = PointGather(d, probes.u_points, probes.v_points)(state.u, state.v)
        probe = None if values is None else ProbeState(*values, state.time, state.step)
        d.on_root(lambda: recorder.record_series(probe))
        self.snapshot(state, recorder, checked=True)

    def snapshot(self, state: State, recorder, checked: bool = False) -> None:
        """``recorder.snapshot`` of ``state`` without an Exodus record: under MPI the ranks check
        the state together (unless ``checked``) and gather u alone, so that rank 0 holds one
        field of the whole body (a VTU snapshot is written by the ranks:
        ``peridyn.io.vtu_pieces``); in one process from ``state`` itself (collective)."""
        d = self.domain
        if d.size == 1:
            recorder.snapshot(state)
            return
        if not checked:
            d.check_state(state, d.runaway_limit(self.model.body.points))
        u = d.gather(state.u)
        d.on_root(lambda: recorder.snapshot(State(u, None, None, state.time, state.step), checked=True))

    def call(self, state: State, fn, tensors: bool = False, damage: bool = True):
        """``fn(state of the whole body)`` on rank 0 after gathering (collective); its result on
        rank 0, None elsewhere. ``tensors``: gather the tensor fields too (for ``fn`` to read
        through ``tensor_fields``); ``damage``: gather the damage index (else ``damage()`` gives
        None until the next call that gathers it)."""
        whole = self.domain.gather_state(state)
        if self.domain.size > 1:
            self._damage = self.domain.gather(damage_field(self.model)) if damage else None
            if tensors and self.tensors is not None:
                self._tensors = {k: self.domain.gather(v) for k, v in self.tensors(state.u).items()}
        return self.domain.on_root(fn, whole)
