"""Time functions for loads."""

import numpy as np
import pytest

from peridyn.errors import InputError
from peridyn.physics.timefunctions import (
    Constant,
    GaussianBurst,
    Ramp,
    Sine,
    Tabulated,
    ToneBurst,
    from_spec,
)


def test_tone_burst_is_windowed_and_bounded():
    burst = ToneBurst(150e3, cycles=3.5, amplitude=2.0, delay=1e-6)
    t = np.linspace(0, 40e-6, 40001)
    y = burst(t)
    assert np.all(y[t < 1e-6] == 0) and np.all(y[t > 1e-6 + burst.duration + 1e-12] == 0)
    assert np.max(np.abs(y)) <= 2.0
    # its spectrum peaks at the centre frequency (within the 25 Hz bin)
    spec = np.abs(np.fft.rfft(y, 8 * len(y)))
    freq = np.fft.rfftfreq(8 * len(y), t[1] - t[0])
    assert freq[np.argmax(spec)] == pytest.approx(150e3, rel=0.02)


def test_gaussian_burst_of_seed_000_starts_at_rest():
    """Seed 000 eqs. 8-9: u = U exp(-p t^2/2) sin(w t); the default delay puts t = 0 at 4 sigma."""
    g = GaussianBurst(150e3, cycles=3.5, amplitude=1e-6)
    assert abs(g(0.0)) < 4e-4 * 1e-6
    omega = 2 * np.pi * 150e3
    p = (2 * g.shape * omega / 3.5) ** 2
    assert g.sigma == pytest.approx(1 / np.sqrt(p), rel=1e-12)


def test_ramp_sine_constant_table():
    assert Ramp(1.0, 3.0, 0.0, 4.0)(np.array([0.0, 2.0, 5.0])).tolist() == [0.0, 2.0, 4.0]
    assert Sine(1.0, 2.0)(0.25) == pytest.approx(2.0)
    assert Constant(3.0)(7.0) == 3.0
    table = Tabulated((0.0, 1.0), (0.0, 10.0))
    assert table(0.25) == pytest.approx(2.5)


def test_sum_and_product():
    f = Constant(2.0) + Ramp(0.0, 1.0) * Constant(3.0)
    assert f(0.5) == pytest.approx(3.5)


def test_table_from_csv(tmp_path):
    path = tmp_path / "load.csv"
    path.write_text("# time, value\n0, 0\n1e-3, 5\n")
    assert from_spec({"type": "table", "file": str(path)})(0.5e-3) == pytest.approx(2.5)


def test_spec_builds_nested_functions():
    f = from_spec({"type": "product", "terms": [{"type": "ramp", "start": 0, "end": 1}, 4.0]})
    assert f(0.5) == pytest.approx(2.0)


@pytest.mark.parametrize(
    "spec, message",
    [
        ({"type": "tonburst"}, "did you mean 'tone_burst'"),
        ({"type": "sine", "frequency": 1.0, "amplitud": 2}, "did you mean 'amplitude'"),
        ({"type": "sine", "frequency": -1.0}, "positive"),
        ({"type": "ramp", "start": 1.0, "end": 0.5}, "after"),
        ("1 + 1", "expected a number or a mapping"),
        ({"type": "table", "file": "/nonexistent/table.csv"}, "does not exist"),
        # found by tests/fuzz: each was a TypeError or ValueError (an internal error of the CLI)
        ({"type": float("nan")}, r"value.type: expected the name of a time function.* got nan"),
        ({"type": []}, r"value.type: expected the name of a time function.* got \[\]"),
        ({"type": "sine", "frequency": [1.0]}, r"value.frequency: expected a finite number, got \[1.0\]"),
        ({"type": "sine", "frequency": 1.0, "amplitude": "x"}, "value.amplitude: expected a finite number"),
        ({"type": "tone_burst", "frequency": 1.0, "amplitude": float("inf")}, "got inf"),
        ({"type": "sine", "frequency": True}, "value.frequency: expected a finite number, got True"),
        ({"type": "sine", "frequency": 1.0, 5: 1.0}, "unknown parameter 5 for Sine"),
        ({"type": "sum", "terms": 5}, "a sum takes only a non-empty list 'terms'"),
        ({"type": "table", "times": 5, "values": [1, 2]}, "value.times: expected a list of finite numbers"),
        ({"type": "table", "times": ["a", 1], "values": [1, 2]}, "value.times: expected a list of finite"),
        ({"type": "table", "file": 3}, "a table takes a CSV 'file'"),
        ({"type": "sine", "frequency": 10**400}, "value.frequency: expected a finite number"),
        (
            {"type": "tone_burst", "frequency": 10**30, "cycles": -(2**63)},
            "tone burst cycles must be positive",
        ),
    ],
)
def test_bad_specs(spec, message):
    with pytest.raises(InputError, match=message):
        from_spec(spec)


@pytest.mark.parametrize(
    "spec, message",
    [
        ({"type": "ramp", "start": 0, "end": -1}, r"^bc\.value: ramp end \(-1\) must be after its start"),
        (
            {"type": "ramp", "end_value": [1, 2]},
            r"^bc\.value\.end_value: expected a finite number, got \[1, 2\]",
        ),
        ({"type": "sine", "frequency": float("nan")}, r"^bc\.value\.frequency: expected a finite number"),
        ({"type": "tone_burst", "frequency": "1e5"}, r"^bc\.value\.frequency: expected a finite number"),
        ({"type": "sine"}, r"^bc\.value: missing 'frequency', which a Sine needs"),
        (
            {"type": "table", "times": 3, "values": [1]},
            r"^bc\.value\.times: expected a list of finite numbers",
        ),
        (
            {"type": "table", "times": [0, 1], "values": [1, "a"]},
            r"^bc\.value\.values: expected a list of finite",
        ),
        (True, r"^bc\.value: expected a number or a mapping"),
        (float("inf"), r"^bc\.value: expected a finite number, got inf"),
    ],
)
def test_every_bad_spec_names_its_key(spec, message):
    """Issue 17: an error in a signal names the case-file key it came from, and a value of the
    wrong type is refused rather than computed with (a list ``end_value`` used to be accepted)."""
    with pytest.raises(InputError, match=message):
        from_spec(spec, "bc.value")


def test_a_gaussian_burst_takes_a_null_delay():
    """``delay: null`` is the default (4 sigma), not a bad number."""
    assert from_spec({"type": "gaussian_burst", "frequency": 1e5, "delay": None}) == GaussianBurst(1e5)


def test_a_null_delay_keeps_the_default_and_numpy_numbers_are_numbers():
    burst = from_spec({"type": "gaussian_burst", "frequency": 1e5, "delay": None})
    assert burst(0.0) == pytest.approx(from_spec({"type": "gaussian_burst", "frequency": 1e5})(0.0), abs=0)
    assert from_spec({"type": "tone_burst", "frequency": np.float64(1e5), "cycles": np.int64(3)}).cycles == 3
