"""Absorbing boundary layers (peridyn.physics.absorbing) and the damped explicit step.

Sources: the cubic damping profile and its round-trip amplitude factor
exp(-c_max w / (4 c_g)) (module docstring of ``peridyn.physics.absorbing``; graded absorbing layers
after Rajagopal et al., NDT&E Int. 2012); the stability limit (w dt)^2 + 2 c dt < 4 of
velocity Verlet with the damping force taken at the half-step velocity (spectral radius of
its amplification matrix, ``solvers.explicit.damped_stable_step``).
"""

import numpy as np
import pytest
from conftest import STEEL_E, STEEL_NU, STEEL_RHO

from peridyn.discretization import geometry
from peridyn.discretization.bonds import find_bonds
from peridyn.errors import InputError, InstabilityError
from peridyn.io.case import load_case
from peridyn.physics.absorbing import layer_damping
from peridyn.physics.loads import InitialCondition, Loading
from peridyn.physics.materials import make_model
from peridyn.setup.build import build
from peridyn.setup.solver_choice import explicit_damping
from peridyn.solvers import ExplicitSolver
from peridyn.solvers.explicit import damped_stable_step

H = 1e-3  # grid spacing of the strips, m
BAR_SPEED = np.sqrt(STEEL_E / STEEL_RHO)  # long-wave speed of a free strip, m/s


def test_profile_is_cubic_from_the_inner_edge_to_the_face():
    """c = c_max ((w - d) / w)^3: c_max on the outermost points, c_max / 8 half-way, 0 inside."""
    x = np.arange(0.0, 0.1001, 0.001)
    points = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    c = layer_damping(points, 0.02, 1e6, ["x-", "x+"])
    assert c[0] == c[-1] == pytest.approx(1e6)
    assert c[10] == pytest.approx(1e6 / 8)  # 10 mm into a 20 mm layer
    assert c[90] == pytest.approx(1e6 / 8)
    assert np.all(c[20:81] == 0.0)
    assert layer_damping(points, 0.02, 1e6, ["x+"])[0] == 0.0


@pytest.mark.parametrize(
    "width, damping, faces, message",
    [
        (0.0, 1e6, ["x-"], "width must be positive"),
        (0.01, -1.0, ["x-"], "damping must be positive"),
        (0.01, 1e6, ["x-", "x-"], "faces must be distinct"),
        (0.01, 1e6, ["z+"], "faces must be distinct names among"),
        (0.06, 1e6, ["x-", "x+"], "no undamped interior"),
    ],
)
def test_bad_layers_are_refused(width, damping, faces, message):
    x = np.linspace(0.0, 0.1, 11)
    with pytest.raises(InputError, match=message):
        layer_damping(np.column_stack([x, x]), width, damping, faces)


def _strip_model(length: int, shift: int = 0, width: int = 4):
    """LPS plane-stress strip ``length`` x ``width`` cells of H, starting at x = -shift H."""
    body = geometry.rectangle(length * H, width * H, H, 1e-3, origin=(-shift * H, 0.0))
    body = body.with_node_set("all", np.ones(body.n_points, dtype=bool))
    return make_model("lps", body, find_bonds(body, 3.015 * H), E=STEEL_E, nu=STEEL_NU, density=STEEL_RHO)


def _strip_record(model, centre, wavelength, damping, dt, n_steps, interior):
    """u_x of the points with x in ``interior`` every 4 steps after an initial wave packet
    at ``centre``: 4 wavelengths of a cosine under a Hann envelope (zero outside)."""
    x = model.body.points[:, 0]
    s = (x - centre) / wavelength
    u0 = 1e-6 * np.where(np.abs(s) < 2, np.cos(np.pi * s / 4) ** 2, 0.0) * np.cos(2 * np.pi * s)
    loading = Loading(model.body, initial=[InitialCondition("all", "displacement", "x", u0)])
    solver = ExplicitSolver(model, loading, damping=damping, dt=dt)
    state = solver.initial_state()
    keep = (x > interior[0]) & (x < interior[1])
    record = []
    for step in range(n_steps):
        solver.step(state)
        if step % 4 == 0:
            record.append(state.u[keep, 0].copy())
    return np.array(record)


def test_layers_absorb_a_wave_packet_and_leave_the_interior_alone():
    """A packet (wavelength 30 H) splits and runs into 1.5-wavelength layers at both ends of a
    strip. The reflected field is the difference from the same strip extended beyond the
    layers' positions (whose own end reflections come back after the record): 98 % of the
    amplitude without layers, 2.0 % with c_max = 18 c / w (predicted round-trip factor
    exp(-18 / 4) = 1.1 %, plus the profile's own small reflection), i.e. under 0.1 % of the
    energy; before any wave reaches a layer the interior is unchanged (to 1e-6)."""
    length, wavelength = 300, 30 * H
    width = 1.5 * wavelength
    extra = int(width / H) + 60
    dt = 0.9e-7  # below every strip's stable step
    n_steps = int(0.95 * length * H / BAR_SPEED / dt)
    interior = (width, length * H - width)
    centre = 0.5 * length * H
    free = _strip_record(
        _strip_model(length + 2 * extra, extra), centre, wavelength, 0.0, dt, n_steps, interior
    )
    strip = _strip_model(length)
    amplitude = np.abs(free).max()
    no_layer = _strip_record(strip, centre, wavelength, 0.0, dt, n_steps, interior)
    damping = layer_damping(strip.body.points, width, 18 * BAR_SPEED / width, ["x-", "x+"])
    layered = _strip_record(strip, centre, wavelength, damping, dt, n_steps, interior)
    assert np.abs(no_layer - free).max() / amplitude > 0.9
    reflected = np.abs(layered - free).max() / amplitude
    assert reflected < 0.03, f"reflected amplitude {reflected:.3f} of the incident"
    # the packet's front (2 wavelengths ahead of its centre) reaches a layer after
    # (centre - 2 wavelengths - width) / c
    before = int((centre - 2 * wavelength - width) / BAR_SPEED / dt) // 4
    assert np.abs(layered[:before] - free[:before]).max() / amplitude < 1e-6


def test_damped_step_limit_is_the_stability_limit():
    """With c dt0 = 1.95 (dt0 the undamped stable step) the solver's step keeps a free strip's
    energy bounded over 3000 steps, while the undamped step blows up (the old behaviour):
    the limit (w dt)^2 + 2 c dt < 4 is needed and sufficient for this scheme."""
    model = _strip_model(20, width=3)
    dt0 = ExplicitSolver(model).stable_dt
    c = 1.95 / dt0
    assert damped_stable_step(dt0, 0.0) == dt0
    rng = np.random.default_rng(1)
    u0 = 1e-9 * rng.standard_normal(model.body.n_points)
    loading = Loading(model.body, initial=[InitialCondition("all", "displacement", "x", u0)])
    solver = ExplicitSolver(model, loading, damping=c, safety=1.0)
    assert solver.dt == pytest.approx(4 / (c + np.sqrt(c**2 + 16 / dt0**2)))
    state = solver.initial_state()
    energy0 = model.strain_energy(state.u)
    solver.run(state, 3000)
    assert solver.kinetic_energy(state) + model.strain_energy(state.u) <= energy0
    with pytest.raises(InputError, match="exceeds the stable step"):
        ExplicitSolver(model, loading, damping=c, dt=dt0)
    unsafe = ExplicitSolver(model, loading, damping=c)
    unsafe.dt = dt0
    with pytest.raises(InstabilityError):
        unsafe.run(unsafe.initial_state(), 3000)


def test_per_point_damping_is_checked():
    model = _strip_model(10, width=2)
    with pytest.raises(InputError, match="one value per point"):
        ExplicitSolver(model, damping=np.ones(3))
    with pytest.raises(InputError, match="non-negative"):
        ExplicitSolver(model, damping=-np.ones(model.body.n_points))


def test_case_block_reaches_the_solver(tmp_path):
    """``absorbing`` in a case adds the layer profile to solver.damping; other solvers and
    layers wider than the plate are refused with the block named."""
    case_file = tmp_path / "plate.yaml"
    case_file.write_text(
        "name: p\ngeometry: {type: plate, size: [0.02, 0.01, 0.002], layers: 2}\n"
        "discretization: {spacing: 1.0e-3, horizon: 1.5}\n"
        "material: {model: lps, E: 70.0e9, nu: 0.33, density: 2700}\n"
        "absorbing: {width: 0.004, damping: 1.0e6, faces: [x-, x+]}\n"
        "initial_conditions: [{set: all, kind: velocity, components: [x], value: 1.0}]\n"
        "solver: {type: explicit, steps: 2, damping: 10.0}\n"
    )
    case = load_case(case_file)
    setup = build(case)
    damping = explicit_damping(case, setup.body)
    x = setup.body.points[:, 0]
    assert damping[np.argmin(x)] == pytest.approx(1e6 + 10.0)
    assert damping[np.argmin(np.abs(x - 0.0105))] == 10.0
    with pytest.raises(InputError, match="absorbing: layers damp the explicit solver only"):
        load_case(case_file, ["solver.type=static"])
    wide = load_case(case_file, ["absorbing.width=0.02"])
    with pytest.raises(InputError, match="absorbing.*no undamped interior"):
        explicit_damping(wide, build(wide).body)
