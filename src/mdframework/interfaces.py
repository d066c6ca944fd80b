"""The interfaces every plugin implements.

Each plugin is a class with a ``name`` (the ``kind`` a config file uses to choose it) and a nested
pydantic ``Config`` model that validates its section of a run config. ``__init__`` takes that
validated config and does no work.

Data passed between stages (shapes, dtypes, units):

- :class:`Motion`: a :class:`~mdframework.skeleton.Skeleton` plus metadata.
- :class:`Scatterers`: ``positions`` ``(n_pulses, n_scatterers, 3)`` float64 [m] in the scene
  frame and ``rcs`` ``(n_pulses, n_scatterers)`` float64 [m^2].
- :class:`Received`: ``signal`` ``(n_pulses,)`` complex128, the pulse-compressed slow-time return
  at the range gate, normalised so that a lone scatterer at the gate gives its range-equation
  amplitude [sqrt(W)]; optional range-time data.
"""

from __future__ import annotations

import dataclasses
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict

from .pointcloud import PointCloud
from .skeleton import Skeleton, to_canonical

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


class PluginConfig(BaseModel):
    """Base of every plugin's config model: unknown fields are errors."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    kind: str


class Plugin(ABC):
    """Common base: a registered name and a config model."""

    #: The ``kind`` that selects this plugin in a config file.
    name: ClassVar[str]
    #: The pydantic model of this plugin's config section (with ``kind: Literal[name]``).
    Config: ClassVar[type[PluginConfig]]

    def __init__(self, config: PluginConfig) -> None:
        self.config = config


# --------------------------------------------------------------------------- motion sources


@dataclass(frozen=True)
class Motion:
    """What a motion source yields.

    ``skeleton`` is in the source's own joints (z up, metres, seconds). ``canonical_map`` maps each
    canonical joint name to a source joint name, or is ``None`` for sources that are not human
    bodies (point targets). ``point_rcs`` (n_joints,) [m^2] is set by sources whose joints are
    isotropic point scatterers. ``metadata`` holds subject, activity label, source file, frame rate
    and anything else worth recording with a run (JSON-serialisable values only).
    """

    skeleton: Skeleton
    metadata: Mapping[str, Any] = field(default_factory=dict)
    canonical_map: Mapping[str, str] | None = None
    point_rcs: FloatArray | None = None

    def canonical(self) -> Skeleton:
        """The skeleton mapped to the canonical 17 joints; ``ValueError`` if there is no map."""
        if self.canonical_map is None:
            raise ValueError(
                "this motion has no mapping to the canonical 17-joint body "
                f"(source: {self.metadata.get('source', 'unknown')})"
            )
        return to_canonical(self.skeleton, self.canonical_map)


class MotionSource(Plugin):
    """Reads or generates motion."""

    @abstractmethod
    def load(self) -> Motion:
        """Return the motion described by the config. Errors name the file and line."""


# --------------------------------------------------------------------------- scatterer models


@dataclass(frozen=True)
class Scatterers:
    """Point scatterers over slow time. See the module docstring for shapes and units."""

    positions: FloatArray
    rcs: FloatArray
    names: tuple[str, ...]
    #: Optional body-part shapes, for effects such as shadowing: ``semi_axes`` (n_scatterers, 3)
    #: [m] as (a, b, c) and ``axes`` (n_pulses, n_scatterers, 3), the direction of each part's
    #: c-axis (not necessarily unit length). ``None`` for point scatterers.
    semi_axes: FloatArray | None = None
    axes: FloatArray | None = None

    def __post_init__(self) -> None:
        if self.positions.ndim != 3 or self.positions.shape[2] != 3:
            raise ValueError(
                f"positions must be (n_pulses, n_scatterers, 3), got {self.positions.shape}"
            )
        if self.rcs.shape != self.positions.shape[:2]:
            raise ValueError(f"rcs must be {self.positions.shape[:2]}, got {self.rcs.shape}")
        if len(self.names) != self.positions.shape[1]:
            raise ValueError("one name per scatterer is required")

    def replace(self, **changes: Any) -> Scatterers:
        """A copy with some fields replaced (e.g. ``rcs``)."""
        return dataclasses.replace(self, **changes)

    def ranges(self, radar_position: FloatArray) -> FloatArray:
        """Distance of every scatterer to the radar, (n_pulses, n_scatterers) float64 [m]."""
        d = self.positions - np.asarray(radar_position, dtype=np.float64)
        return np.asarray(np.sqrt(d[..., 0] ** 2 + d[..., 1] ** 2 + d[..., 2] ** 2), np.float64)


class ScattererModel(Plugin):
    """Turns a body (or a set of points) into scatterers with an RCS for each pulse."""

    #: Whether this model needs the canonical 17-joint body (a model may decide per config).
    needs_canonical: bool = True

    @abstractmethod
    def scatterers(
        self, motion: Motion, skeleton: Skeleton, radar_position: FloatArray, wavelength: float
    ) -> Scatterers:
        """Scatterers for every pulse.

        ``skeleton`` is already resampled to the pulse times and placed in the scene frame
        (canonical joints if ``needs_canonical``). ``radar_position`` is (3,) [m];
        ``wavelength`` [m] is the radar's, for frequency-dependent RCS.
        """


# --------------------------------------------------------------------------- waveforms


@dataclass(frozen=True)
class Received:
    """Radar data after pulse compression.

    ``signal`` (n_pulses,) complex128: slow-time return at the range gate [sqrt(W)].
    ``range_time`` (n_pulses, n_bins) complex128 and ``range_axis`` (n_bins,) float64 [m]: the
    compressed output over a window of ranges, when the waveform computes it (else ``None``).
    """

    signal: ComplexArray
    range_time: ComplexArray | None = None
    range_axis: FloatArray | None = None


class RadarWaveform(Plugin):
    """A radar: its carrier, pulse rate, range equation and receive chain."""

    @property
    @abstractmethod
    def carrier_frequency(self) -> float:
        """Carrier (band-centre) frequency [Hz]."""

    @property
    @abstractmethod
    def prf(self) -> float:
        """Pulse repetition frequency, i.e. the slow-time sample rate [Hz]."""

    @abstractmethod
    def receive(self, ranges: FloatArray, rcs: FloatArray, gate_range: FloatArray) -> Received:
        """Received, pulse-compressed data.

        ``ranges`` and ``rcs``: (n_pulses, n_scatterers) float64 [m], [m^2].
        ``gate_range``: (n_pulses,) float64 [m], the range gate to report in ``signal``.
        """


# --------------------------------------------------------------------------- recorded radar output


@dataclass(frozen=True)
class Recording:
    """One recording of a real radar's output.

    ``name`` identifies the recording (e.g. its original file name; records cut from it share
    it, so experiments can hold whole recordings out); ``cloud`` holds its detected points in the
    conventions of :mod:`mdframework.pointcloud` (radial velocity positive approaching);
    ``metadata``: source, file, sensor, licence and anything worth recording (JSON values).
    """

    name: str
    cloud: PointCloud
    metadata: Mapping[str, Any] = field(default_factory=dict)


class RadarRecordingSource(Plugin):
    """Reads recordings of a real radar (point clouds), for datasets and experiments."""

    @abstractmethod
    def load(self) -> list[Recording]:
        """The recordings the config names, in a fixed order. Errors name the file and line."""


# --------------------------------------------------------------------------- classifiers


class Classifier(Plugin):
    """Learns activity labels from feature vectors (scikit-learn style)."""

    @abstractmethod
    def fit(self, features: FloatArray, labels: NDArray[Any]) -> Classifier:
        """Fit on ``features`` (n_samples, n_features) and ``labels`` (n_samples,)."""

    @abstractmethod
    def predict(self, features: FloatArray) -> NDArray[Any]:
        """Predicted labels, (n_samples,)."""


# --------------------------------------------------------------------------- effects


@dataclass(frozen=True)
class SceneContext:
    """What an effect may need to know about the scene.

    ``radar_position`` (3,) [m]; ``prf`` and ``carrier_frequency`` [Hz]; ``pulse_times``
    (n_pulses,) [s]; ``gate_range`` (n_pulses,) [m]; ``skeleton``: the body at the pulse times in
    the scene frame (canonical joints when the scatterer model uses them); ``waveform``: the radar
    plugin (for its bandwidth, pulse width, range equation); ``rng``: the run's seeded generator
    (each effect gets its own stream, derived from the run's seed and the effect's position).
    """

    radar_position: FloatArray
    prf: float
    carrier_frequency: float
    pulse_times: FloatArray
    gate_range: FloatArray
    skeleton: Skeleton
    waveform: RadarWaveform
    rng: np.random.Generator


class Effect(Plugin):
    """A scene effect (noise, clutter, multipath, antenna pattern, shadowing, ...).

    ``stage`` says where it acts: on the scatterers before the radar (``"scatterers"``: it gets
    and returns :class:`Scatterers`, e.g. attenuating RCS or adding image scatterers) or on the
    received data (``"received"``: it gets and returns :class:`Received`, e.g. adding noise).
    The pipeline instantiates and runs only the effects a scene's ``effects`` list names, in
    that order within each stage; an effect not named is never constructed.
    """

    stage: ClassVar[Literal["scatterers", "received"]]

    @abstractmethod
    def apply(self, data: Any, context: SceneContext) -> Any:
        """Return the modified ``Scatterers`` or ``Received``."""

    def describe(self) -> dict[str, Any]:
        """What this effect did, for the run's metadata (default: its config)."""
        return dict(self.config.model_dump())
