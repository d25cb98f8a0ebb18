"""The monitoring case file (``peridyn monitor CASE.yaml``, docs/monitoring.md): a fatigue case,
a wave (interrogation) case, the transducer network, the interrogation schedule, sensor noise and
the signal processing's settings. Paths of the two cases are relative to the monitoring file."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

from pydantic import Field, ValidationError, field_validator, model_validator

from peridyn.io.case import (
    Finite,
    NonNegative,
    NotBool,
    Positive,
    Strict,
    apply_override,
    described,
    first_problem,
    read_yaml_mapping,
)

__all__ = ["TRANSFERS", "MonitorCase", "load_monitor_case"]

#: The damage transfers (docs/monitoring.md, "Damage transfer"), each against the other.
TRANSFERS = {"bonds": "cut", "cut": "bonds"}

XY = Annotated[list[Finite], Field(min_length=2, max_length=2)]


class Transducers(Strict):
    """Surface PZT patches, each fired in turn (a ``pzt_radial`` actuator of the wave case) while
    all of them record (``pzt_sensors``): the network's paths are every pair."""

    centers: Annotated[list[XY], Field(min_length=3, max_length=12)] = described(
        ..., "centres of the patches in the plate's plane (x, y)", "m"
    )
    size: Positive = described(..., "side of a square patch or diameter of a circular one", "m")
    shape: str = described("square", "shape of the patches: square or circular")
    amplitude: Positive = described(1e-6, "radial displacement amplitude on an actuator's perimeter", "m")
    frequency: Positive = described(..., "centre frequency of the tone burst", "Hz")
    cycles: Positive = described(3.5, "cycles of the Hann-windowed tone burst")

    @model_validator(mode="after")
    def _shape(self):
        if self.shape not in ("square", "circular"):
            raise ValueError(f"shape: square or circular, got {self.shape!r}")
        return self

    def signal(self) -> dict:
        """The actuators' time function (a case file's ``signal``)."""
        return {"type": "tone_burst", "frequency": self.frequency, "cycles": self.cycles}


class Schedule(Strict):
    """When the structure is interrogated: at 0 cycles (the baseline, always), then every
    ``every_cycles`` cycles and/or every ``every_crack_growth`` of crack growth, and at the end of
    the fatigue life, or at the first step whose crack reaches ``until_crack_length``."""

    every_cycles: Positive | None = described(None, "cycles between interrogations")
    every_crack_growth: Positive | None = described(None, "crack growth between interrogations", "m")
    until_crack_length: Positive | None = described(
        None, "the last interrogation: the first step whose crack is at least this long", "m"
    )
    max_interrogations: Annotated[int, NotBool, Field(ge=2, le=100)] = described(
        20, "most interrogations, the baseline included"
    )

    @model_validator(mode="after")
    def _some(self):
        if self.every_cycles is None and self.every_crack_growth is None:
            raise ValueError("schedule: give every_cycles, every_crack_growth or both")
        return self


class Noise(Strict):
    """Seeded Gaussian white noise added to every recorded signal (baseline included)."""

    level: NonNegative = described(0.0, "standard deviation as a fraction of each path's direct-arrival peak")
    seed: Annotated[int, NotBool, Field(ge=0)] = described(0, "seed of the noise")


class Processing(Strict):
    """Windows, images and the crack threshold of the signal processing."""

    modes: Annotated[list[str], Field(min_length=1)] = described(
        ["S0"], "Lamb modes whose direct packets the windows hold (S0: the first arrival; S0 and A0)"
    )
    window_padding: NonNegative = described(
        0.0, "window length after the slowest direct packet, in burst durations"
    )
    rapid_beta: Annotated[float, NotBool, Field(gt=1, allow_inf_nan=False)] = described(
        1.05, "RAPID ellipse size (path-length ratio of its rim)"
    )
    image_spacing: Positive = described(0.5e-3, "pixel size of the damage images", "m")
    peak_exclusion: NonNegative | None = described(
        None, "no image peak within this distance of a transducer (default: twice the patch size)", "m"
    )
    index: str = described(
        "correlation", "index the image and the checks use: correlation or residual_energy"
    )

    @model_validator(mode="after")
    def _index(self):
        unknown = sorted(set(self.modes) - {"S0", "A0"})
        if unknown:
            raise ValueError(f"modes: S0 and/or A0, got {unknown[0]!r}")
        if self.index not in ("correlation", "residual_energy"):
            raise ValueError(f"index: correlation or residual_energy, got {self.index!r}")
        return self


class MonitorOutput(Strict):
    """Where the job writes and whether it draws figures."""

    directory: str | None = described(None, "output folder (default peridyn-out/<name>)")
    plots: bool = described(True, "draw the figures")


class MonitorCase(Strict):
    """A monitoring case: fatigue life, interrogations, processing (docs/monitoring.md)."""

    name: str = described(..., "name of the case (the default output folder peridyn-out/<name>)")
    description: str = described("", "one line saying what the case is")
    fatigue_case: str = described(..., "fatigue case file (2D plane stress), relative to this file")
    wave_case: str = described(..., "wave case file (3D plate, explicit), relative to this file")
    transducers: Transducers = described(..., "the PZT network")
    schedule: Schedule = described(..., "interrogation schedule")
    noise: Noise = described(Noise(), "sensor noise")
    processing: Processing = described(Processing(), "signal processing settings")
    transfer: str = described(
        "bonds",
        "how the fatigue damage reaches the wave case: bonds (the fatigue model's broken bonds "
        "through the thickness) or cut (its crack paths as through-thickness cuts)",
    )
    check_transfer: bool = described(
        True,
        "repeat each interrogation after the crack first grew through the other damage transfer",
    )
    output: MonitorOutput = described(MonitorOutput(), "output folder and figures")

    @field_validator("transfer")
    @classmethod
    def _transfer(cls, value: str) -> str:
        if value not in TRANSFERS:
            raise ValueError(f"bonds or cut, got {value!r}")
        return value

    @model_validator(mode="after")
    def _name(self):
        if not self.name or self.name in (".", "..") or "/" in self.name or "\0" in self.name:
            raise ValueError(f"name: a folder name, got {self.name!r}")
        return self


def load_monitor_case(path, overrides=()) -> tuple[MonitorCase, Path]:
    """Read and validate a monitoring case file; returns it and its folder (the base of its paths).

    Raises
    ------
    CaseFileError
        Missing or unreadable file, bad YAML or a wrong entry (one line naming its key).
    """
    path = Path(path)
    raw = read_yaml_mapping(path, "YAML monitoring case file")
    for item in overrides:
        apply_override(raw, item, str(path))
    try:
        return MonitorCase.model_validate(raw), path.parent
    except ValidationError as exc:
        raise first_problem(exc, str(path)) from None
