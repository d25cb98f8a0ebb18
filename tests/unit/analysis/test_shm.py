"""Signal processing of the monitoring job (peridyn.analysis.shm) on signals and networks whose
answers are known in closed form."""

import numpy as np
import pytest

from peridyn.analysis.shm.imaging import image_peak, rapid_image
from peridyn.analysis.shm.indices import correlation_index, direct_peaks, residual_energy_index, with_noise
from peridyn.analysis.shm.paths import (
    crossed_paths,
    network_paths,
    path_lengths,
    polyline_centre,
    polyline_length,
    truncated,
)
from peridyn.analysis.shm.windows import arrival_windows, fundamental_group_velocities, window_masks
from peridyn.errors import InputError

T = np.linspace(0.0, 1e-4, 2001)
BURST = np.sin(2 * np.pi * 150e3 * T) * np.exp(-(((T - 3e-5) / 1e-5) ** 2))


def test_residual_energy_of_a_scaled_signal_is_the_squared_scale_change():
    # sum((1.1 b - b)^2) / sum(b^2) = 0.1^2 exactly
    assert residual_energy_index(BURST, 1.1 * BURST) == pytest.approx(0.01, rel=1e-12)
    assert residual_energy_index(BURST, BURST) == 0.0


def test_correlation_index_is_blind_to_gain_and_offset_and_two_for_an_inverted_signal():
    # Pearson's rho is invariant to a positive affine map (rho = 1) and -1 for a negated signal
    assert correlation_index(BURST, 2.0 * BURST + 3.0) == pytest.approx(0.0, abs=1e-12)
    assert correlation_index(BURST, -BURST) == pytest.approx(2.0, abs=1e-12)
    # sin and cos over whole periods are orthogonal with zero mean: rho = 0
    t = np.linspace(0, 1, 1000, endpoint=False)
    assert correlation_index(np.sin(2 * np.pi * 5 * t), np.cos(2 * np.pi * 5 * t)) == pytest.approx(
        1.0, abs=1e-12
    )


def test_indices_use_only_the_windowed_samples_of_each_path():
    # a change outside the window leaves the index at 0; inside it counts
    changed = BURST.copy()
    changed[T > 8e-5] += 1.0
    early = np.vstack([T <= 6e-5, T > 7e-5])
    di = residual_energy_index(np.vstack([BURST, BURST]), np.vstack([changed, changed]), early)
    assert di[0] == 0.0 and di[1] > 0.0
    with pytest.raises(InputError, match="holds no sample"):
        residual_energy_index(BURST, BURST, np.zeros(T.shape, dtype=bool))


def test_noise_has_the_asked_standard_deviation_and_repeats_with_its_seed():
    signals = np.zeros((2, 200_000))
    peaks = np.array([1.0, 3.0])
    noisy = with_noise(signals, 0.01, peaks, seed=7)
    # sample std of 2e5 normal draws: relative standard error 1/sqrt(2 n) = 0.16%
    np.testing.assert_allclose(noisy.std(axis=1), 0.01 * peaks, rtol=0.01)
    np.testing.assert_array_equal(noisy, with_noise(signals, 0.01, peaks, seed=7))
    assert direct_peaks(np.vstack([BURST, -2 * BURST]), T < 1e-4).tolist() == pytest.approx(
        [np.abs(BURST).max(), 2 * np.abs(BURST).max()]
    )


def test_first_arrival_windows_span_the_fastest_to_the_slowest_packet():
    w = arrival_windows([0.1, 0.05], [5000.0, 2500.0], 2e-5, padding=0.0)
    np.testing.assert_allclose(w, [[2e-5, 6e-5], [1e-5, 4e-5]], rtol=1e-12)
    mask = window_masks(T, w)
    assert mask[0][T < 2e-5].sum() == 0 and mask[0][(T >= 2e-5) & (T <= 6e-5)].all()
    with pytest.raises(InputError, match="positive"):
        arrival_windows([0.1], [0.0], 2e-5)


def test_fundamental_group_velocities_approach_the_plate_limits_at_low_frequency_thickness():
    # 2 mm aluminium at 150 kHz (f d = 0.3 MHz mm): S0 is within 1% of the plate velocity
    # sqrt(E / (rho (1 - nu^2))) (Rose, Ultrasonic Guided Waves in Solid Media, 2014, ch. 6),
    # A0 slower than the Rayleigh speed (about 2.9 km/s).
    E, nu, rho = 68.9e9, 0.33, 2700.0
    v = fundamental_group_velocities(E, nu, rho, 0.002, 150e3)
    assert v["S0"] == pytest.approx(np.sqrt(E / (rho * (1 - nu**2))), rel=0.01)
    assert 1500.0 < v["A0"] < 2900.0


def test_rapid_peak_lies_where_the_two_damaged_diagonals_cross():
    # square network; only its diagonals (paths 0-3 and 1-2) see the damage: the image's largest
    # value is where both ellipses overlap, on their common point, the square's centre
    xy = np.array([[0.0, 0.0], [0.1, 0.0], [0.0, 0.1], [0.1, 0.1]])
    paths = network_paths(4)
    di = np.where([(i, j) in ((0, 3), (1, 2)) for i, j in paths], 1.0, 0.0)
    x = y = np.linspace(0.0, 0.1, 101)
    image = rapid_image(xy, paths, di, x, y)
    np.testing.assert_allclose(image_peak(x, y, image), [0.05, 0.05], atol=1e-3 + 1e-12)
    # on each diagonal the weight is 1; outside both ellipses (mid-edge, R = 1.14 > beta) 0
    assert image[50, 50] == pytest.approx(2.0) and image[0, 50] == 0.0


def test_paths_crossed_by_a_crack_and_the_crack_cut_to_a_length():
    xy = np.array([[0.0, 0.0], [0.0, 0.1], [0.1, 0.0], [0.1, 0.1]])
    paths = network_paths(4)
    assert paths.tolist() == [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]
    np.testing.assert_allclose(
        path_lengths(xy, paths), [0.1, 0.1, 0.1 * np.sqrt(2), 0.1 * np.sqrt(2), 0.1, 0.1]
    )
    crack = np.array([[-0.01, 0.05], [0.03, 0.05]])  # crosses the left edge path 0-1 and no other
    assert crossed_paths(xy, paths, crack).tolist() == [True, False, False, False, False, False]
    bent = np.array([[0.0, 0.0], [0.01, 0.0], [0.01, 0.02]])
    assert polyline_length(bent) == pytest.approx(0.03)
    np.testing.assert_allclose(truncated(bent, 0.02), [[0.0, 0.0], [0.01, 0.0], [0.01, 0.01]], atol=1e-15)
    np.testing.assert_allclose(polyline_centre(bent), [0.01, 0.005], atol=1e-15)


def test_the_image_peak_is_sought_away_from_the_transducers():
    # all three paths of transducer 0 changed: the image is largest on transducer 0 itself
    # (weight 1 from each path); away from it the peak is on its paths' common ellipses
    xy = np.array([[0.0, 0.0], [0.1, 0.0], [0.0, 0.1], [0.1, 0.1]])
    paths = network_paths(4)
    di = np.where(paths[:, 0] == 0, 1.0, 0.0)
    x = y = np.linspace(0.0, 0.1, 101)
    image = rapid_image(xy, paths, di, x, y)
    np.testing.assert_allclose(image_peak(x, y, image), [0.0, 0.0], atol=1e-12)
    far = image_peak(x, y, image, xy, 0.01)
    assert np.min(np.hypot(*(xy - far).T)) > 0.01
