"""PZT actuators (radial displacement, pin force) and the PZT sensor signal (peridyn.physics.transducers)."""

from __future__ import annotations

import numpy as np
import pytest

from peridyn.discretization import geometry
from peridyn.errors import InputError
from peridyn.physics.loads import Loading
from peridyn.physics.timefunctions import ToneBurst
from peridyn.physics.transducers import (
    pin_force_actuator,
    pzt_radial_actuator,
    pzt_sensor_signal,
    pzt_sensor_weights,
)

# VALIDATION.md V2 (seed 000, sec. 2.2): 1.2 mm in-plane spacing, 3 layers 1 mm apart in a 2 mm
# plate, 2.4 mm square PZT, 1 um radial displacement at its perimeter, 3.5 cycles at 150 kHz.
SPACING, PATCH, AMPLITUDE = 1.2e-3, 2.4e-3, 1e-6
BURST = ToneBurst(150e3, 3.5)
# A grid point (cell centre (i + 1/2) h) at the patch centre, so that the perimeter passes
# through points as in the seed.
CENTER = (10.5 * SPACING, 10.5 * SPACING)


def _plate():
    return geometry.plate(21 * SPACING, 21 * SPACING, 2e-3, SPACING, layers=3, layer_placement="surface")


def _offsets(body, name):
    return body.points[body.node_set(name), :2] - np.asarray(CENTER)


def test_radial_square_patch_is_the_seed_model():
    body, (bc,) = pzt_radial_actuator(_plate(), CENTER, PATCH, BURST, amplitude=AMPLITUDE)
    idx = body.node_set("pzt")
    assert len(idx) == 9  # 3 x 3 points: centre, 4 edge midpoints, 4 corners
    assert np.allclose(body.points[idx, 2], 2e-3)  # top layer
    d = _offsets(body, "pzt")
    size = np.linalg.norm(bc.profile, axis=1)
    centre = np.all(np.abs(d) < 1e-12, axis=1)
    assert np.all(bc.profile[centre] == 0.0)
    assert np.allclose(size[~centre], AMPLITUDE, rtol=1e-12)  # perimeter points: 1 um
    radial = bc.profile[~centre] / size[~centre, None]
    assert np.allclose(radial, d[~centre] / np.linalg.norm(d[~centre], axis=1)[:, None])
    assert bc.kind == "displacement" and bc.components == (0, 1)


@pytest.mark.parametrize("shape", ["square", "circular"])
def test_radial_profile_grows_linearly_along_rays(shape):
    """A patch two spacings in half size: points one spacing out get half the amplitude."""
    body, (bc,) = pzt_radial_actuator(_plate(), CENTER, 4 * SPACING, BURST, shape=shape, amplitude=AMPLITUDE)
    d = _offsets(body, "pzt")
    on_axis = (np.abs(d[:, 1]) < 1e-12) & (d[:, 0] > 0)
    x = d[on_axis, 0]
    assert np.allclose(bc.profile[on_axis, 0], AMPLITUDE * x / (2 * SPACING), rtol=1e-12)
    if shape == "circular":  # uniform expansion u = A d / R
        assert np.allclose(bc.profile, AMPLITUDE * d / (2 * SPACING), rtol=1e-12)


def test_radial_actuator_drives_in_plane_motion_only():
    body, bcs = pzt_radial_actuator(_plate(), CENTER, PATCH, BURST, amplitude=AMPLITUDE)
    loading = Loading(body, bcs)
    u, v = np.zeros((body.n_points, 3)), np.zeros((body.n_points, 3))
    t = 0.3 * BURST.duration
    loading.apply_kinematics(t, 1e-8, u, v)
    idx = body.node_set("pzt")
    assert np.allclose(u[idx, :2], bcs[0].profile * BURST(t), rtol=1e-12)
    assert not loading.constrained[:, 2].any()
    assert np.count_nonzero(u) == np.count_nonzero(bcs[0].profile)


def test_actuator_on_the_bottom_layer():
    body, _ = pzt_radial_actuator(_plate(), CENTER, PATCH, BURST, layer=0, name="bottom")
    assert np.all(body.points[body.node_set("bottom"), 2] == 0.0)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"shape": "hexagonal"},
        {"size": -1.0},
        {"center": (-1.0, -1.0)},  # no point under the patch
        {"layer": 3},  # the plate has 3 layers
    ],
)
def test_actuator_rejects_bad_input(kwargs):
    args = {"center": CENTER, "size": PATCH, "function": BURST} | kwargs
    with pytest.raises(InputError):
        pzt_radial_actuator(_plate(), **args)


def test_actuator_needs_layers_or_layer_none():
    box = geometry.box((12 * SPACING, 12 * SPACING, 2 * SPACING), SPACING)
    with pytest.raises(InputError, match="no layers"):
        pzt_radial_actuator(box, (6 * SPACING, 6 * SPACING), PATCH, BURST)
    body, _ = pzt_radial_actuator(box, (6 * SPACING, 6 * SPACING), PATCH, BURST, layer=None)
    assert len(body.node_set("pzt")) == 2 * 2 * 2  # both point layers under the patch


def test_pin_force_square_loads_each_edge_with_line_force_times_length():
    line_force = 250.0  # N/m, arbitrary
    body, (bc,) = pin_force_actuator(_plate(), CENTER, 4 * SPACING, BURST, line_force=line_force)
    idx = body.node_set("pin_force")
    forces = bc.profile * body.volumes[idx, None]  # N per point at function = 1
    d = _offsets(body, "pin_force")
    assert len(idx) == 16  # the outer ring of the 5 x 5 patch
    assert np.allclose(forces.sum(axis=0), 0.0, atol=1e-12 * line_force * SPACING)
    for axis in (0, 1):
        for sign in (-1, 1):
            side = sign * d[:, axis] > 1.5 * SPACING
            assert np.isclose(sign * forces[side, axis].sum(), line_force * 4 * SPACING, rtol=1e-12)
    assert np.all(np.einsum("ij,ij->i", forces, d) > 0)  # outward
    assert bc.kind == "body_force"


def test_pin_force_circle_pushes_the_rim_radially():
    line_force, size = 100.0, 8 * SPACING
    body, (bc,) = pin_force_actuator(_plate(), CENTER, size, BURST, shape="circular", line_force=line_force)
    idx = body.node_set("pin_force")
    forces = bc.profile * body.volumes[idx, None]
    d = _offsets(body, "pin_force")
    r = np.linalg.norm(d, axis=1)
    assert np.all((r > 0.5 * size - SPACING) & (r <= 0.5 * size + 1e-12))
    assert np.isclose(np.linalg.norm(forces, axis=1).sum(), line_force * np.pi * size, rtol=1e-12)
    assert np.allclose(
        forces[:, 0] * d[:, 1] - forces[:, 1] * d[:, 0], 0.0, atol=1e-12 * line_force * SPACING**2
    )
    assert np.allclose(forces.sum(axis=0), 0.0, atol=1e-12 * line_force * SPACING)
    density = Loading(body, [bc]).body_force_density(0.3 * BURST.duration, np.zeros((body.n_points, 3)))
    assert np.allclose(density[idx, :2], bc.profile * BURST(0.3 * BURST.duration))


# -- sensor ------------------------------------------------------------------------------


def _top_points(h=SPACING, n=21):
    body = geometry.plate(n * h, n * h, 2e-3, h, layers=3, layer_placement="surface")
    return body.points[geometry.layer(body, -1)]


@pytest.mark.parametrize("shape", ["square", "circular"])
def test_sensor_is_exact_for_linear_fields(shape, rng):
    points = _top_points()
    gradients = rng.normal(size=(4, 3, 3)) * 1e-4  # four records, random displacement gradients
    shifts = rng.normal(size=(4, 3)) * 1e-6
    u = np.einsum("tij,pj->tpi", gradients, points) + shifts[:, None, :]
    signal = pzt_sensor_signal(points, u, CENTER, PATCH, shape)
    expected = gradients[:, 0, 0] + gradients[:, 1, 1]  # eps_xx + eps_yy, exact for linear u
    assert signal.shape == (4,)
    assert np.allclose(signal, expected, rtol=1e-10, atol=1e-16)
    assert np.isclose(pzt_sensor_signal(points, u[1], CENTER, PATCH, shape), expected[1], rtol=1e-10)


def _wave_error(h):
    """Relative error of the sensor on u_x = U sin(k (x - x_c)) with spacing h.

    Under a square of half size a the mean of du_x/dx is U sin(k a) / a. The centre is off the
    grid, so that the perimeter crosses the cells and the interpolation shows.
    """
    a, k = 0.5 * PATCH, 612.41
    n = int(round(3 * PATCH / h)) + 1
    points = _top_points(h, n)
    center = ((n / 2 + 0.37) * h, (n / 2 - 0.21) * h)
    u = np.zeros((len(points), 3))
    u[:, 0] = 1e-6 * np.sin(k * (points[:, 0] - center[0]))
    return pzt_sensor_signal(points, u, center, PATCH) / (1e-6 * np.sin(k * a) / a) - 1


def test_sensor_gives_the_area_mean_of_a_wave_to_second_order():
    """k = 612.41 rad/m (A0 at 150 kHz, VALIDATION V1): k a = 0.73, where a least-squares
    gradient (U k * 3 (sin ka - ka cos ka) / (ka)^3) would be 3.8% off.
    """
    spacings = np.array([0.3e-3, 0.2e-3, 0.1e-3])
    errors = np.array([_wave_error(h) for h in spacings])
    rate = np.polyfit(np.log(spacings), np.log(np.abs(errors)), 1)[0]
    assert abs(rate - 2.0) < 0.2, f"observed rate {rate:.3f}, errors {errors}"
    assert abs(errors[-1]) < 1e-3  # measured -4.4e-4 at 0.1 mm


def test_sensor_weights_vanish_away_from_the_patch():
    points = _top_points()
    weights = pzt_sensor_weights(points, CENTER, PATCH)
    far = np.max(np.abs(points[:, :2] - np.asarray(CENTER)), axis=1) > PATCH
    assert np.all(weights[far] == 0.0)


def test_sensor_rejects_several_layers_and_patches_off_the_points():
    body = _plate()
    u = np.zeros((body.n_points, 3))
    with pytest.raises(InputError, match="several layers"):
        pzt_sensor_signal(body.points, u, CENTER, PATCH)
    top = _top_points()
    with pytest.raises(InputError, match="not inside"):
        pzt_sensor_signal(top, np.zeros((len(top), 3)), (0.0, 0.0), PATCH)
    with pytest.raises(InputError, match="shape"):
        pzt_sensor_signal(top, np.zeros((len(top) + 1, 3)), CENTER, PATCH)
