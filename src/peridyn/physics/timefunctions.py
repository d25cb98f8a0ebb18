"""Functions of time for loads: constant, ramp, sine, tone bursts, tables, and their sums/products.

Every function is a small immutable object, callable on a float or an array
of times (s) and returning the same shape. ``f + g`` and ``f * g`` build
sums and products; case files describe the same with ``{type: sum, terms: [...]}``.
Nothing is ever evaluated from a string.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import MISSING, dataclass
from pathlib import Path

import numpy as np

from peridyn.errors import InputError, did_you_mean


class TimeFunction:
    """Base class: ``f(t)`` for t in seconds (float or array)."""

    def __call__(self, t):
        raise NotImplementedError

    def __add__(self, other: TimeFunction) -> TimeFunction:
        return Sum((self, other))

    def __mul__(self, other: TimeFunction) -> TimeFunction:
        return Product((self, other))

    def derivative(self, t, dt: float):
        """Central difference (f(t + dt/2) - f(t - dt/2)) / dt."""
        return (self(t + 0.5 * dt) - self(t - 0.5 * dt)) / dt


@dataclass(frozen=True)
class Constant(TimeFunction):
    """f(t) = value."""

    value: float = 1.0

    def __call__(self, t):
        return np.full_like(np.asarray(t, dtype=float), self.value)


@dataclass(frozen=True)
class Ramp(TimeFunction):
    """Linear from ``start_value`` at ``start`` to ``end_value`` at ``end`` (s), constant outside."""

    start: float = 0.0
    end: float = 1.0
    start_value: float = 0.0
    end_value: float = 1.0

    def __post_init__(self):
        if not self.end > self.start:
            raise InputError(f"ramp end ({self.end}) must be after its start ({self.start})")

    def __call__(self, t):
        frac = np.clip((np.asarray(t, dtype=float) - self.start) / (self.end - self.start), 0, 1)
        return self.start_value + frac * (self.end_value - self.start_value)


@dataclass(frozen=True)
class Sine(TimeFunction):
    """amplitude sin(2 pi frequency t + phase); frequency in Hz, phase in rad."""

    frequency: float
    amplitude: float = 1.0
    phase: float = 0.0

    def __post_init__(self):
        _positive("sine frequency", self.frequency)

    def __call__(self, t):
        return self.amplitude * np.sin(2 * np.pi * self.frequency * np.asarray(t, float) + self.phase)


@dataclass(frozen=True)
class ToneBurst(TimeFunction):
    """Hann-windowed tone burst of ``cycles`` cycles at ``frequency`` (Hz), starting at ``delay`` (s).

    f(t) = amplitude * 0.5 (1 - cos(2 pi f tau / N)) sin(2 pi f tau), tau = t - delay,
    for 0 <= tau <= N / f, zero elsewhere.

    Examples
    --------
    Patra et al.'s (2018) 3.5-cycle burst at 150 kHz lasts 23.3 us; the window peaks mid-burst.

    >>> burst = ToneBurst(150e3, cycles=3.5)
    >>> round(burst.duration * 1e6, 2)
    23.33
    >>> float(burst(0.0)), float(burst(burst.duration + 1e-9))
    (0.0, 0.0)
    >>> round(float(burst(burst.duration / 2)), 12)  # window 1, sin(3.5 pi) = -1 at the centre
    -1.0
    """

    frequency: float
    cycles: float = 3.5
    amplitude: float = 1.0
    delay: float = 0.0

    def __post_init__(self):
        _positive("tone burst frequency", self.frequency)
        _positive("tone burst cycles", self.cycles)

    @property
    def duration(self) -> float:
        """Length of the burst, s."""
        return self.cycles / self.frequency

    def __call__(self, t):
        tau = np.asarray(t, dtype=float) - self.delay
        on = (tau >= 0) & (tau <= self.duration)
        window = 0.5 * (1 - np.cos(2 * np.pi * self.frequency * tau / self.cycles))
        return np.where(on, self.amplitude * window * np.sin(2 * np.pi * self.frequency * tau), 0.0)


@dataclass(frozen=True)
class GaussianBurst(TimeFunction):
    """Gaussian-windowed burst of Patra et al. 2018, eqs. 8-9.

    f(t) = amplitude exp(-p tau^2 / 2) sin(omega tau), tau = t - delay,
    p = (2 shape omega / N)^2, omega = 2 pi frequency. The paper writes the shape
    product as k h; the default 3 / (2 pi) makes the +-3 sigma envelope span the
    N cycles. The default delay is 4 sigma so that the signal starts at rest
    (envelope below 3.4e-4 at t = 0).
    """

    frequency: float
    cycles: float = 3.5
    amplitude: float = 1.0
    shape: float = 3.0 / (2.0 * np.pi)
    delay: float | None = None

    def __post_init__(self):
        _positive("burst frequency", self.frequency)
        _positive("burst cycles", self.cycles)
        _positive("burst shape", self.shape)

    @property
    def sigma(self) -> float:
        """Standard deviation of the envelope, s: 1 / sqrt(p)."""
        return self.cycles / (2.0 * self.shape * 2.0 * np.pi * self.frequency)

    def __call__(self, t):
        delay = 4.0 * self.sigma if self.delay is None else self.delay
        tau = np.asarray(t, dtype=float) - delay
        omega = 2 * np.pi * self.frequency
        return self.amplitude * np.exp(-0.5 * (tau / self.sigma) ** 2) * np.sin(omega * tau)


@dataclass(frozen=True)
class Step(TimeFunction):
    """``before`` up to ``time`` (s) included, ``after`` later."""

    time: float = 0.0
    before: float = 0.0
    after: float = 1.0

    def __call__(self, t):
        return np.where(np.asarray(t, dtype=float) <= self.time, self.before, self.after)


@dataclass(frozen=True)
class Tabulated(TimeFunction):
    """Piecewise-linear interpolation of (times, values); held constant outside the table."""

    times: tuple
    values: tuple

    def __post_init__(self):
        t = np.asarray(self.times, dtype=float)
        v = np.asarray(self.values, dtype=float)
        if t.ndim != 1 or t.shape != v.shape or len(t) < 2:
            raise InputError("a table needs two equal-length columns with at least 2 rows")
        if not np.all(np.isfinite(t)) or not np.all(np.isfinite(v)):
            raise InputError("table times and values must be finite")
        if np.any(np.diff(t) <= 0):
            raise InputError("table times must increase strictly")

    @classmethod
    def from_csv(cls, path) -> Tabulated:
        """Read a two-column CSV (time in s, value); lines starting with '#' are comments."""
        path = Path(path)
        if not path.is_file():
            raise InputError(f"table file {str(path)!r} does not exist")
        try:
            data = np.loadtxt(path, delimiter=",", comments="#", ndmin=2)
        except ValueError as exc:
            raise InputError(f"table file {str(path)!r}: {exc}") from exc
        if data.shape[1] != 2:
            raise InputError(f"table file {str(path)!r} has {data.shape[1]} columns, expected 2")
        return cls(tuple(data[:, 0]), tuple(data[:, 1]))

    def __call__(self, t):
        return np.interp(np.asarray(t, dtype=float), self.times, self.values)


@dataclass(frozen=True)
class Sum(TimeFunction):
    """Sum of time functions."""

    terms: tuple

    def __call__(self, t):
        return sum(term(t) for term in self.terms)


@dataclass(frozen=True)
class Product(TimeFunction):
    """Product of time functions."""

    terms: tuple

    def __call__(self, t):
        out = np.ones_like(np.asarray(t, dtype=float))
        for term in self.terms:
            out = out * term(t)
        return out


def _positive(name: str, value: float) -> None:
    if not (_is_finite_number(value) and value > 0):
        raise InputError(f"{name} must be positive, got {value!r}")


_SIMPLE = {
    "constant": Constant,
    "ramp": Ramp,
    "step": Step,
    "sine": Sine,
    "tone_burst": ToneBurst,
    "gaussian_burst": GaussianBurst,
}


def from_spec(spec, where: str = "value") -> TimeFunction:
    """Build a time function from a case-file entry.

    A number means a constant; a mapping has ``type`` (constant, ramp, sine,
    tone_burst, gaussian_burst, table, sum, product) and that type's
    parameters; ``table`` takes ``file`` (CSV) or ``times`` and ``values``;
    ``sum`` and ``product`` take ``terms``.
    """
    if isinstance(spec, numbers.Real) and not isinstance(spec, bool):
        if not _is_finite_number(spec):
            raise InputError(f"{where}: expected a finite number, got {spec!r}")
        return Constant(float(spec))
    if isinstance(spec, TimeFunction):
        return spec
    if not isinstance(spec, dict) or "type" not in spec:
        raise InputError(f"{where}: expected a number or a mapping with a 'type', got {spec!r}")
    params = {k: v for k, v in spec.items() if k != "type"}
    kind = spec["type"]
    choices = [*_SIMPLE, "table", "sum", "product"]
    if not isinstance(kind, str):
        raise InputError(
            f"{where}.type: expected the name of a time function, one of {choices}, got {kind!r}"
        )
    if kind in ("sum", "product"):
        terms = params.pop("terms", None)
        if not isinstance(terms, list) or not terms or params:
            raise InputError(f"{where}: a {kind} takes only a non-empty list 'terms'")
        built = tuple(from_spec(t, f"{where}.terms[{i}]") for i, t in enumerate(terms))
        return Sum(built) if kind == "sum" else Product(built)
    if kind == "table":
        if "file" in params:
            if not isinstance(params["file"], str) or len(params) > 1:
                raise InputError(f"{where}: a table takes a CSV 'file' (a path) or 'times' and 'values'")
            return Tabulated.from_csv(params["file"])
        for key, column in params.items():
            if not isinstance(column, list) or not all(_is_finite_number(v) for v in column):
                raise InputError(f"{where}.{key}: expected a list of finite numbers, got {column!r}")
        return _construct(Tabulated, where, {k: tuple(v) for k, v in params.items()})
    if kind not in _SIMPLE:
        raise InputError(
            f"{where}.type: unknown time function {kind!r}{did_you_mean(kind, choices)}"
            f"; choose one of {choices}"
        )
    return _construct(_SIMPLE[kind], where, params)


def _construct(cls, where: str, params: dict) -> TimeFunction:
    """``cls(**params)``; every error names ``where`` (the case-file key)."""
    fields = cls.__dataclass_fields__
    unknown = [k for k in params if k not in fields]
    if unknown:
        raise InputError(
            f"{where}: unknown parameter {unknown[0]!r}"
            f"{did_you_mean(unknown[0], fields)} for {cls.__name__}; "
            f"allowed: {sorted(fields)}"
        )
    missing = [k for k, f in fields.items() if f.default is MISSING and k not in params]
    if missing:
        raise InputError(f"{where}: missing {missing[0]!r}, which a {cls.__name__} needs")
    if cls is not Tabulated:  # every parameter of the others is a number (a delay may be null)
        for key, value in params.items():
            if not (_is_finite_number(value) or (value is None and fields[key].default is None)):
                raise InputError(f"{where}.{key}: expected a finite number, got {value!r}")
    try:
        return cls(**params)
    except (TypeError, InputError) as exc:  # e.g. a ramp that ends before it starts
        raise InputError(f"{where}: {exc}") from None


def _is_finite_number(value) -> bool:
    """Whether ``value`` is a finite real number (not a bool, a string, NaN or an infinity)."""
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:  # an integer beyond the floats (10**400)
        return False
