"""The interfaces every plugin implements.

Each plugin is a class with a ``name`` (the ``kind`` a config file uses to choose it) and a nested
pydantic ``Config`` model that validates its section of a run config. ``__init__`` takes that
validated config and does no work.

Data passed between stages (shapes, dtypes, units):

- :class:`Motion`: a :class:`~mdframework.skeleton.Skeleton` plus metadata.
- :class:`Scatterers`: ``positions`` ``(n_pulses, n_scatterers, 3)`` float64 [m] in the scene
  frame and ``rcs`` ``(n_pulses, n_scatterers)`` float64 [m^2].
- :class:`PulseBlock`: the streaming unit. The pipeline cuts a record's pulses into blocks of
  consecutive pulses (a few thousand) and runs scatterers, scatterer-stage effects, ranges and the
  radar's receive chain block by block, so memory is set by the block size, not the record.
- :class:`Received`: ``signal`` ``(n_pulses,)`` complex128, the pulse-compressed slow-time return
  at the range gate, normalised so that a lone scatterer at the gate gives its range-equation
  amplitude [sqrt(W)]; optional range-time data and waveform-specific ``products``.

Block invariance: every per-block stage (scatterer models, scatterer-stage effects, waveforms)
must give the same output whether a record is processed as one block or as many
(:func:`mdframework.testing.check_block_invariance`).
"""

from __future__ import annotations

import dataclasses
import functools
import json
import types
import typing
import warnings
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, ValidationError, model_validator

from .physics.radar import distances
from .pointcloud import PointCloud
from .skeleton import Skeleton, to_canonical

if TYPE_CHECKING:
    from .physics.spectrogram import Spectrogram, SpectrogramGeometry
    from .settings import ProcessingConfig

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


def _base(annotation: Any) -> Any:
    """The type under ``Annotated[...]`` layers."""
    while typing.get_origin(annotation) is typing.Annotated:
        annotation = typing.get_args(annotation)[0]
    return annotation


#: what is wrong with a value: (what was wanted, what was found, the value or the item of it
#: that is wrong), or None
_Problem = tuple[str, str, Any] | None


def _flag(value: Any) -> _Problem:
    return None if isinstance(value, bool) else ("true or false", type(value).__name__, value)


def _number(value: Any, want: str = "a number") -> _Problem:
    if isinstance(value, bool):
        return want, "a flag", value
    return (want, "text", value) if isinstance(value, str) else None


def _first(check: Callable[[Any], _Problem], items: Iterable[Any]) -> _Problem:
    return next((found for found in map(check, items) if found is not None), None)


def _scalar_check(annotation: Any) -> Callable[[Any], _Problem] | None:
    """The check of a field that takes numbers or flags (also inside an optional, a union with
    named choices, a tuple, a list or a table of them); None for any other field."""
    annotation = _base(annotation)
    if annotation is bool:
        return _flag
    if annotation in (int, float):
        return _number
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin in (typing.Union, types.UnionType):
        members = [_base(a) for a in args if a is not type(None)]
        if len(members) == 1:  # optional: None is the field's own "not given"
            inner = _scalar_check(members[0])
            return None if inner is None else (lambda v: None if v is None else inner(v))
        if not any(m in (int, float) for m in members) or bool in members or str in members:
            return None
        words = [w for m in members if typing.get_origin(m) is Literal for w in typing.get_args(m)]
        want = "a number or " + " or ".join(map(repr, words)) if words else "a number"
        return lambda v: None if isinstance(v, str) and v in words else _number(v, want)
    if origin in (tuple, list) and args:
        found = [_scalar_check(a) for a in args if a is not Ellipsis]
        checks = [c for c in found if c is not None]
        if not checks or len(checks) < len(found):
            return None
        if origin is list or args[-1] is Ellipsis:
            one = checks[0]
            return lambda v: _first(one, v) if isinstance(v, list | tuple) else None
        return lambda v: (
            next((p for c, x in zip(checks, v, strict=False) if (p := c(x))), None)
            if isinstance(v, list | tuple)
            else None
        )
    if origin is dict and len(args) == 2 and (of := _scalar_check(args[1])) is not None:
        return lambda v: _first(of, v.values()) if isinstance(v, dict) else None
    return None


@functools.cache
def _scalar_fields(model: type[BaseModel]) -> tuple[tuple[str, Callable[[Any], _Problem]], ...]:
    """(key in the config, check) of each field of ``model`` that takes numbers or flags."""
    out = []
    for name, info in model.model_fields.items():
        check = _scalar_check(info.annotation)
        if check is not None:
            out.append((info.alias or name, check))
    return tuple(out)


def _shown(value: Any) -> str:
    """A config value as the file wrote it, at most 40 characters."""
    try:
        text = json.dumps(value)
    except (TypeError, ValueError):  # a date, say
        text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def refuse_lax_scalars(model: type[BaseModel], data: Any) -> Any:
    """A config section's raw ``data`` as it is, after refusing a flag or text where a field
    takes only numbers (or numbers and named choices), and anything but a flag where it takes
    only flags, also inside the tuples, lists and tables of a field: pydantic's lax mode would
    silently read ``prf = true`` as 1 Hz. The error names the field first (``hop: a number, not
    a flag (true)``), which the config's error message makes its location. Used as a
    ``mode="before"`` model validator by every config model."""
    if not isinstance(data, dict):
        return data
    for key, check in _scalar_fields(model):
        if key in data and (problem := check(data[key])) is not None:
            want, found, value = problem
            raise ValueError(f"{key}: {want}, not {found} ({_shown(value)})")
    return data


class ConfigSection(BaseModel):
    """Base of every config model, the core's and the plugins' (and of the tables inside a
    plugin's section, such as a point target): unknown fields are errors, float fields must be
    finite (a field that gives ``inf`` a meaning says so with ``Field(allow_inf_nan=True)``),
    and numbers and flags are not converted from each other or from text
    (:func:`refuse_lax_scalars`)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    @model_validator(mode="before")
    @classmethod
    def _no_lax_scalars(cls, data: Any) -> Any:
        return refuse_lax_scalars(cls, data)


class PluginConfig(ConfigSection):
    """Base of every plugin's config model (a :class:`ConfigSection` with the ``kind`` that
    chooses the plugin)."""

    kind: str


class RadarConfig(PluginConfig):
    """Base of radar configs: a :class:`PluginConfig` that can say how many pulses per second
    its radar sends, so that a record over the pulse budget (:mod:`mdframework.limits`) is
    refused when the config is read, before the radar is built. A radar config that derives
    from :class:`PluginConfig` alone works too; its records are then checked once the run's
    radar is built."""

    def pulse_rate(self) -> float | None:
        """Pulses (slow-time samples, FMCW chirps) per second of a record [Hz] for the pulse
        budget, or ``None`` when the config alone does not fix it. Default ``None``; the
        radar's :attr:`RadarWaveform.pulse_rate` is this rate when it is given."""
        return None


class Plugin(ABC):
    """Common base: a registered name and a config model."""

    #: The ``kind`` that selects this plugin in a config file.
    name: ClassVar[str]
    #: The pydantic model of this plugin's config section (with ``kind: Literal[name]``).
    Config: ClassVar[type[PluginConfig]]

    def __init__(self, config: PluginConfig | None = None) -> None:
        name = type(self).__name__
        if config is None:  # the defaults, as a config section holding only the kind means
            try:
                config = type(self).Config.model_validate({})
            except ValidationError as exc:
                needed = sorted({str(e["loc"][0]) for e in exc.errors() if e["type"] == "missing"})
                fields = ", ".join(needed) or "its fields"
                verb = "has" if len(needed) == 1 else "have"
                raise TypeError(
                    f"{name}() needs a config: {fields} {verb} no default; give "
                    f"{name}({name}.Config(...))"
                ) from None
        if isinstance(config, Mapping):  # a config section as read, not validated
            raise TypeError(
                f"{name} takes an instance of {name}.Config, e.g. {name}({name}.Config(...)) or, "
                f"from a dict, {name}({name}.Config.model_validate(d)); got "
                f"{type(config).__name__}"
            )
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
    ``linear_tracks`` is set by sources whose joints move exactly linearly in time between frames
    (constant-velocity targets): the pipeline then resamples them linearly, which is exact and
    needs no spline, unless conditioning changes the tracks.
    """

    skeleton: Skeleton
    metadata: Mapping[str, Any] = field(default_factory=dict)
    canonical_map: Mapping[str, str] | None = None
    point_rcs: FloatArray | None = None
    linear_tracks: bool = False

    def canonical(self) -> Skeleton:
        """The skeleton mapped to the canonical 17 joints; ``ValueError`` if there is no map."""
        if self.canonical_map is None:
            raise ValueError(
                "this motion has no mapping to the canonical 17-joint body "
                f"(source: {self.metadata.get('source', 'unknown')})"
            )
        return self._canonical

    @functools.cached_property
    def _canonical(self) -> Skeleton:
        """The canonical skeleton, mapped once per motion (records cut from one recording
        share it)."""
        assert self.canonical_map is not None
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
    #: Optional ranges already computed by the model (set it with :meth:`with_ranges`):
    #: ``(positions, radar_position, ranges)``, valid for that very ``positions`` array (by
    #: identity) and radar position (3 floats) [m], ranges (n_pulses, n_scatterers) [m]. A copy
    #: whose positions are another array (``replace(positions=...)``, also through
    #: ``dataclasses.replace``) drops it, so it can never give the ranges of other positions.
    range_cache: tuple[FloatArray, tuple[float, float, float], FloatArray] | None = field(
        default=None, repr=False, compare=False
    )
    #: Optional centres of the body-part shapes (n_pulses, n_scatterers, 3) [m], given when the
    #: scatterers do not sit at them (e.g. the ``ellipsoid`` model's ``scattering_phase =
    #: "specular"`` puts each on its part's surface): effects that need the shapes' geometry
    #: (shadowing, multipath) use these. ``None``: the positions are the centres.
    centres: FloatArray | None = None
    #: Optional (n_scatterers,) bool: which scatterers sit at their shape's geometric-optics
    #: specular point for the radar (from ``centres``, ``semi_axes`` and ``axes``), a point that
    #: moves over the surface with the direction of view. Effects that look from elsewhere (the
    #: multipath image radar) take their own specular point from the centre. ``None``: none.
    specular: NDArray[np.bool_] | None = None

    def __post_init__(self) -> None:
        if self.positions.ndim != 3 or self.positions.shape[2] != 3:
            raise ValueError(
                f"positions must be (n_pulses, n_scatterers, 3), got {self.positions.shape}"
            )
        if self.rcs.shape != self.positions.shape[:2]:
            raise ValueError(f"rcs must be {self.positions.shape[:2]}, got {self.rcs.shape}")
        if len(self.names) != self.positions.shape[1]:
            raise ValueError("one name per scatterer is required")
        if self.centres is not None and self.centres.shape != self.positions.shape:
            raise ValueError(f"centres must be {self.positions.shape}, got {self.centres.shape}")
        if self.specular is not None:
            if self.specular.shape != (self.positions.shape[1],):
                raise ValueError(f"specular must be ({self.positions.shape[1]},) bool")
            if np.any(self.specular) and (
                self.centres is None or self.semi_axes is None or self.axes is None
            ):
                raise ValueError("specular scatterers need centres, semi_axes and axes")
        if self.range_cache is not None and self.range_cache[0] is not self.positions:
            object.__setattr__(self, "range_cache", None)

    def replace(self, **changes: Any) -> Scatterers:
        """A copy with some fields replaced (e.g. ``rcs``)."""
        return dataclasses.replace(self, **changes)

    def only(self, i: int) -> Scatterers:
        """Scatterer ``i`` alone (its arrays with one scatterer), its shape fields with it."""
        one = slice(i, i + 1)
        return Scatterers(
            self.positions[:, one],
            self.rcs[:, one],
            self.names[one],
            None if self.semi_axes is None else self.semi_axes[one],
            None if self.axes is None else self.axes[:, one],
            centres=None if self.centres is None else self.centres[:, one],
            specular=None if self.specular is None else self.specular[one],
        )

    def with_ranges(self, radar_position: FloatArray, ranges: FloatArray) -> Scatterers:
        """A copy that remembers ``ranges`` (n_pulses, n_scatterers) [m] of these positions from
        ``radar_position`` (3,) [m], so that :meth:`ranges` need not compute them again (a
        model that computed them anyway, for its RCS, passes them on)."""
        if ranges.shape != self.rcs.shape:
            raise ValueError(f"ranges must be {self.rcs.shape}, got {ranges.shape}")
        cache = (self.positions, _position_key(radar_position), ranges)
        return dataclasses.replace(self, range_cache=cache)

    def ranges(self, radar_position: FloatArray) -> FloatArray:
        """Distance of every scatterer to the radar, (n_pulses, n_scatterers) float64 [m]."""
        cache = self.range_cache
        if (
            cache is not None
            and cache[0] is self.positions
            and cache[1] == _position_key(radar_position)
        ):
            return cache[2]
        return distances(self.positions, radar_position)


def _position_key(radar_position: FloatArray) -> tuple[float, float, float]:
    x, y, z = (float(v) for v in np.asarray(radar_position, dtype=np.float64))
    return x, y, z


class ScattererModel(Plugin):
    """Turns a body (or a set of points) into scatterers with an RCS for each pulse."""

    #: Whether this model needs the canonical 17-joint body (a model may decide per config).
    needs_canonical: bool = True

    def start_record(self, body: Skeleton) -> None:
        """Called once per record before its blocks, with the whole placed body at the source's
        own frame times (``n_frames``, not pulses). A model that needs record-wide quantities
        (the body's height, an orientation to hold over untracked frames) takes them from here,
        so that :meth:`scatterers` gives the same result for any cut of the record into blocks.
        Default: nothing."""

    @abstractmethod
    def scatterers(
        self, motion: Motion, skeleton: Skeleton, radar_position: FloatArray, wavelength: float
    ) -> Scatterers:
        """Scatterers for every pulse of one block.

        ``skeleton`` is already resampled to the block's pulse times and placed in the scene
        frame (canonical joints if ``needs_canonical``). ``radar_position`` is (3,) [m];
        ``wavelength`` [m] is the radar's, for frequency-dependent RCS. Blocks arrive in time
        order, after :meth:`start_record`.
        """


# --------------------------------------------------------------------------- waveforms


@dataclass(frozen=True)
class PulseBlock:
    """Consecutive pulses of a record, the unit a waveform receives.

    ``start``: index of the block's first pulse in the record. ``times`` (n,) float64 [s] on the
    scene clock. ``scatterers``: positions (n, K, 3) float64 [m] in the scene frame and RCS
    (n, K) float64 [m^2]. ``ranges`` (n, K) float64 [m]: scatterer to radar, computed once by the
    pipeline. ``gate_range`` (n,) float64 [m]. ``radar_position`` (3,) float64 [m].
    ``receiver_noise``: whether a waveform that adds receiver noise itself
    (:attr:`RadarWaveform.adds_receiver_noise`) adds it to this block; False asks for the
    scatterers' response alone (:func:`receive_points` by default, and
    :meth:`RadarWaveform.receive_each` for e.g. clutter patches, whose responses are summed and
    rescaled: noise in each would be summed with them).
    """

    start: int
    times: FloatArray
    scatterers: Scatterers
    ranges: FloatArray
    gate_range: FloatArray
    radar_position: FloatArray
    receiver_noise: bool = True

    @property
    def n_pulses(self) -> int:
        """Number of pulses in the block."""
        return int(self.times.shape[0])


@dataclass(frozen=True)
class Received:
    """Radar data after pulse compression.

    ``signal`` (n_pulses,) complex128: slow-time return at the range gate [sqrt(W)].
    ``range_time`` (n_rows, n_bins) complex128 and ``range_axis`` (n_bins,) float64 [m]: the
    compressed output over a window of ranges, when the waveform computes it (else ``None``); a
    waveform returns one row per pulse of a block, and the pipeline keeps every pulse's row of a
    record up to :data:`mdframework.pipeline.MAX_KEPT_RANGE_TIME_ROWS` (16384) and evenly spaced
    rows beyond (``range_time_pulses`` (n_rows,) int64 then gives the pulse index of each row).
    ``products``: further arrays a waveform produces (e.g. range-Doppler maps or point clouds),
    each stacked along axis 0 over a record's blocks and saved under its name.
    """

    signal: ComplexArray
    range_time: ComplexArray | None = None
    range_axis: FloatArray | None = None
    products: Mapping[str, NDArray[Any]] = field(default_factory=dict)
    range_time_pulses: NDArray[np.int64] | None = None


@dataclass(frozen=True)
class ReceiverInput:
    """What a received-stage effect puts into the raw samples of a radar that simulates it
    there (:attr:`RadarWaveform.takes_receiver_inputs`, e.g. the FMCW radar making range-Doppler
    maps and points), so that it reaches every product of the radar alike
    (:meth:`Effect.receiver_input`).

    ``noise_power`` [W]: circular complex white Gaussian noise of this power per complex raw
    (ADC) sample, drawn per frame from ``noise_key`` and the frame's index (the same whatever
    the blocks). ``static_ranges`` (P,) [m] and ``static_rcs`` (P,) [m^2]: point scatterers that
    do not move, at these ranges along the radar's boresight (zero Doppler).
    """

    effect: str
    noise_power: float = 0.0
    noise_key: int = 0
    static_ranges: FloatArray = field(default_factory=lambda: np.zeros(0))
    static_rcs: FloatArray = field(default_factory=lambda: np.zeros(0))


class RadarWaveform(Plugin):
    """A radar: its carrier, pulse timing, range equation and receive chain."""

    #: Blocks hold a multiple of this many pulses (e.g. the pulses of one FMCW frame, so that no
    #: frame straddles two blocks).
    block_multiple: ClassVar[int] = 1
    #: The run's ``seed``, set by the framework on the radar it builds for a run (``None``
    #: outside one): a radar that draws random numbers itself (its receiver noise) seeds them
    #: from it, unless its config gives a seed of its own, so that the run's seed, and each
    #: dataset record's, reaches every random draw.
    seed: int | None = None

    @property
    @abstractmethod
    def carrier_frequency(self) -> float:
        """Carrier (band-centre) frequency [Hz]."""

    @property
    @abstractmethod
    def prf(self) -> float:
        """Pulse repetition frequency, i.e. the (mean) slow-time sample rate [Hz]."""

    @property
    def pulse_rate(self) -> float:
        """Pulses per second of a record [Hz], for the pulse budget (:mod:`mdframework.limits`).
        Default: the config's :meth:`RadarConfig.pulse_rate` when it gives one (e.g. FMCW chirps
        of several transmitters, more than one per slow-time sample), else :attr:`prf`."""
        rate = self.config.pulse_rate() if isinstance(self.config, RadarConfig) else None
        return self.prf if rate is None else rate

    @property
    def adds_receiver_noise(self) -> bool:
        """Whether the radar adds receiver noise to its returns itself (the FMCW radar's
        ``receiver_noise``); the ``noise`` effect is then refused, since it would count that
        noise twice. Default: False."""
        return False

    @property
    def takes_receiver_inputs(self) -> bool:
        """Whether this radar simulates the received-stage effects that describe themselves as
        a :class:`ReceiverInput` (:meth:`Effect.receiver_input`: noise, static clutter) in its
        raw samples, so that they reach all its products (the FMCW radar's maps and points)
        rather than the slow-time signal alone. Default: False."""
        return False

    @property
    def max_static_range(self) -> float | None:
        """Range [m] at or beyond which the static scatterers of :class:`ReceiverInput` s
        (``static_ranges``) are left out of the raw samples (the FMCW radar's maximum range,
        unless it aliases them), so that an effect can report what was simulated; ``None``:
        none left out. Default: ``None``."""
        return None

    def set_receiver_inputs(self, inputs: Sequence[ReceiverInput]) -> None:
        """The record's :class:`ReceiverInput` s (maybe none), before its blocks, when
        :attr:`takes_receiver_inputs`; a block with ``receiver_noise`` False leaves them out
        (the scatterers' response alone). Default: nothing."""

    @property
    def range_resolution(self) -> float | None:
        """Range resolution ``c / (2 B)`` [m] of the compressed return (``B`` the swept
        bandwidth), or ``None`` for a radar without one (CW). Default: from the config's
        ``bandwidth`` [Hz] when it has one; a radar may set its own (``self.range_resolution =
        ...``, e.g. in ``__init__``)."""
        if "range_resolution" in self.__dict__:
            return typing.cast("float | None", self.__dict__["range_resolution"])
        from .constants import SPEED_OF_LIGHT

        bandwidth = getattr(self.config, "bandwidth", None)
        return None if bandwidth is None else SPEED_OF_LIGHT / (2.0 * float(bandwidth))

    @range_resolution.setter
    def range_resolution(self, value: float | None) -> None:
        self.__dict__["range_resolution"] = value

    def unambiguous_range(self) -> float | None:
        """Largest range [m] the radar measures without ambiguity, or ``None`` for a radar
        without range (CW) or one that does not say: ``mdf check`` reports it, and a fixed
        ``scene.gate`` beyond it is warned about. Default ``None``: a ``prf`` does not tell
        (a CW radar's I/Q rate is called that too, and a pulse radar sending several pulses
        per slow-time sample has a shorter pulse interval). The LFM radar's is
        ``c / (2 prf)``, the FMCW radar's its maximum range."""
        return None

    @property
    def max_unambiguous_velocity(self) -> float:
        """Largest |radial velocity| [m/s] the slow-time sampling represents without aliasing.
        Default: ``lambda * prf / 4`` (complex samples at ``prf``)."""
        from .physics.radar import max_unambiguous_velocity

        return max_unambiguous_velocity(self.carrier_frequency, self.prf)

    def faster_sampling(self, rate: float) -> str:
        """What to change in this radar's config so that it samples slow time at ``rate`` [Hz]
        or faster (e.g. to keep a fast scatterer's Doppler unambiguous): a clause naming the
        config fields. Default: ``radar.prf``; a radar whose slow-time rate follows from other
        fields (FMCW timing, CW's sample rate) overrides it."""
        return f"raise radar.prf to at least {np.ceil(rate):.0f} Hz"

    def smaller_spectrogram(self, processing: ProcessingConfig) -> tuple[str, str]:
        """What sets the size of this radar's spectrogram (:meth:`spectrogram_geometry`), for
        the message refusing one of more than ``limits.MAX_SPECTROGRAM_CELLS`` values: the
        config field to name first and a clause saying what to change. Default: the
        pipeline's STFT's (``processing.hop``, ``processing.nfft``, the record's length); a
        radar whose spectrogram is sized by other fields (FMCW frames with gaps: one column per
        frame) overrides it."""
        return (
            "processing.hop",
            "raise processing.hop, lower processing.nfft or shorten the record",
        )

    @property
    def shortest_record(self) -> float:
        """Shortest record [s] that :meth:`pulse_times` gives any pulse in (e.g. the chirps of
        one FMCW frame). Default 0: uniform pulses from the record's start."""
        return 0.0

    def start_record(self, times: FloatArray, range_span: tuple[float, float]) -> None:
        """Called once per record before its blocks: ``times`` (n_pulses,) [s] of the whole
        record and the smallest and largest distance [m] of the body's joints to the radar over
        it (e.g. to fix a range-time window for every block). Default: nothing."""

    def working_memory(self) -> Mapping[str, int]:
        """Bytes this radar holds at once beyond the pipeline's own arrays (the slow-time signal
        and a block's scatterers), by what holds them: a raw path's fast-time samples, an FMCW
        radar's kept range-Doppler maps. ``mdf check`` adds them to its memory estimate; called
        after :meth:`start_record`. Default: none."""
        return {}

    def pulse_times(self, start: float, end: float) -> FloatArray:
        """Slow-time instants (n_pulses,) float64 [s] of a record from ``start`` to ``end``
        (scene clock, inclusive). Default: uniform at :attr:`prf` from ``start``."""
        from .physics.interpolation import pulse_times

        return pulse_times(start, end, self.prf)

    def product_axes(self) -> Mapping[str, NDArray[Any]]:
        """Axes of this radar's ``products`` (e.g. the range and velocity of range-Doppler
        maps), saved with them as they are (not stacked over blocks). Default: none."""
        return {}

    @abstractmethod
    def receive(self, block: PulseBlock) -> Received:
        """Received, pulse-compressed data of one block: ``signal`` (block.n_pulses,)."""

    def receive_signal(self, block: PulseBlock) -> ComplexArray:
        """Only the slow-time signal of one block, (block.n_pulses,) complex128: what one-off
        receives such as clutter patches use. It must equal ``receive(block).signal``.
        Default: exactly that; a radar whose ``products`` cost much (FMCW range-Doppler maps
        and point clouds) overrides it to skip them."""
        return self.receive(block).signal

    def receive_each(self, block: PulseBlock) -> ComplexArray:
        """Each scatterer's slow-time signal alone, (K, block.n_pulses) complex128 [sqrt(W)]:
        row ``i`` is :meth:`receive_signal` of the block with scatterer ``i`` only and without
        receiver noise (``block.receiver_noise`` is not read). For one-off responses of many
        scatterers, such as the clutter patches. Default: exactly that, one scatterer after
        another; a radar whose every call has a cost of its own (the FMCW radar's pass over the
        frames) overrides it to take the scatterers together."""
        sc = block.scatterers
        out = np.empty((sc.positions.shape[1], block.n_pulses), dtype=np.complex128)
        for i in range(out.shape[0]):
            out[i] = self.receive_signal(
                dataclasses.replace(
                    block,
                    scatterers=sc.only(i),
                    ranges=block.ranges[:, i : i + 1],
                    receiver_noise=False,
                )
            )
        return out

    def spectrogram(
        self, signal: ComplexArray, times: FloatArray, processing: ProcessingConfig
    ) -> Spectrogram | None:
        """The record's micro-Doppler spectrogram when this radar's slow time is not uniform
        (e.g. FMCW frames with gaps): ``signal`` (n_pulses,) complex128; ``times`` (n_pulses,)
        float64 [s], the record's pulse instants as :meth:`pulse_times` gave them (scene clock),
        for a radar whose spectrogram follows them (staggered or jittered pulses, say); a radar
        whose timing its config fixes (FMCW) may ignore them. Default ``None``: the pipeline
        takes the STFT of ``signal`` at :attr:`prf`. A radar that overrides it overrides
        :meth:`spectrogram_geometry` to match."""
        return None

    def spectrogram_geometry(
        self, n_pulses: int, processing: ProcessingConfig
    ) -> SpectrogramGeometry:
        """The geometry of the spectrogram of a record of ``n_pulses`` pulses (window, hop, FFT
        size, number of spectra, slow-time rate), worked out without its pulses: ``mdf check``
        reports it and the run refuses a record too short for it before the first pulse.
        :class:`~mdframework.physics.spectrogram.RecordTooShortError` when the record is too
        short for one spectrum. Default: the pipeline's STFT of ``n_pulses`` samples at
        :attr:`prf` (``processing`` window length, hop and FFT size); it must describe what
        :meth:`spectrogram` gives (:func:`mdframework.testing.check_radar_waveform` compares)."""
        from .physics.spectrogram import stft_geometry

        p = processing
        return stft_geometry(n_pulses, self.prf, p.window_length, p.hop, p.nfft)

    def gate_gain(self, ranges: FloatArray, gate_range: FloatArray) -> FloatArray | None:
        """Power gain (n_pulses, n_scatterers) of each scatterer in the range gate of
        ``Received.signal`` (1 at the gate, 0 outside it), for the empty-result check
        (:mod:`mdframework.emptiness`). Default None: the radar has no single range gate, and
        no scatterer counts as lost to gating."""
        return None


def _points_block(
    waveform: RadarWaveform,
    ranges: FloatArray,
    rcs: FloatArray,
    gate_range: FloatArray,
    radar_position: FloatArray | None,
    times: FloatArray | None,
    receiver_noise: bool,
) -> PulseBlock:
    """The block of :func:`receive_points` and :func:`point_responses`."""
    r = np.asarray(ranges, dtype=np.float64)
    origin = np.zeros(3) if radar_position is None else np.asarray(radar_position, np.float64)
    positions = np.zeros((*r.shape, 3))
    positions[..., 0] = r
    positions += origin
    t = np.arange(r.shape[0]) / waveform.prf if times is None else np.asarray(times, np.float64)
    scat = Scatterers(
        positions, np.asarray(rcs, dtype=np.float64), tuple(map(str, range(r.shape[1])))
    )
    gate = np.asarray(gate_range, dtype=np.float64)
    return PulseBlock(0, t, scat, r, gate, origin, receiver_noise=receiver_noise)


def receive_points(
    waveform: RadarWaveform,
    ranges: FloatArray,
    rcs: FloatArray,
    gate_range: FloatArray,
    radar_position: FloatArray | None = None,
    times: FloatArray | None = None,
    signal_only: bool = False,
    receiver_noise: bool = False,
) -> Received:
    """One-off receive of point scatterers given by their ranges, e.g. contract checks:
    ``ranges``, ``rcs`` (n_pulses, K) [m], [m^2]; ``gate_range`` (n_pulses,) [m]. The
    scatterers are put on the +x axis of the radar; ``times`` default to ``n / prf``. With
    ``signal_only`` the result holds only the signal (:meth:`RadarWaveform.receive_signal`: no
    products). The response is the scatterers' alone unless ``receiver_noise`` asks a radar that
    adds receiver noise itself to add it (:attr:`PulseBlock.receiver_noise`)."""
    block = _points_block(waveform, ranges, rcs, gate_range, radar_position, times, receiver_noise)
    if signal_only:
        return Received(waveform.receive_signal(block))
    return waveform.receive(block)


def point_responses(
    waveform: RadarWaveform,
    ranges: FloatArray,
    rcs: FloatArray,
    gate_range: FloatArray,
    radar_position: FloatArray | None = None,
    times: FloatArray | None = None,
) -> ComplexArray:
    """Each point scatterer's slow-time signal alone, without receiver noise, (K, n_pulses)
    complex128 [sqrt(W)] (:meth:`RadarWaveform.receive_each`), e.g. the clutter patches; the
    arguments as for :func:`receive_points`."""
    block = _points_block(waveform, ranges, rcs, gate_range, radar_position, times, False)
    return waveform.receive_each(block)


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


class RecordingSource(Plugin):
    """Reads recordings of a real radar (point clouds), for datasets and experiments (the
    ``recording`` entry of a dataset source)."""

    @abstractmethod
    def load(self) -> list[Recording]:
        """The recordings the config names, in a fixed order. Errors name the file and line."""


# --------------------------------------------------------------------------- classifiers


class Classifier(Plugin):
    """Learns activity labels from feature vectors (scikit-learn style).

    ``seed``: the experiment's ``seed``, set by the framework on every instance it makes,
    before ``fit`` (``None`` when a classifier is made without one). A classifier that draws
    random numbers (a random forest, a shuffled solver) seeds them from it, so that an
    experiment's seed reproduces its results; one that draws none ignores it. A plugin written
    before the attribute existed keeps working unchanged.
    """

    #: The experiment's seed, or None (see the class docstring).
    seed: int | None = None

    @abstractmethod
    def fit(self, features: FloatArray, labels: NDArray[Any]) -> Classifier:
        """Fit on ``features`` (n_samples, n_features) float64 and ``labels`` (n_samples,)
        str; return the fitted classifier (``self``)."""

    @abstractmethod
    def predict(self, features: FloatArray) -> NDArray[Any]:
        """Predicted labels (n_samples,), one per row of ``features``, each one of the labels
        ``fit`` was given (an experiment stops naming the plugin otherwise)."""


# --------------------------------------------------------------------------- effects


@dataclass(frozen=True)
class SceneContext:
    """What an effect may need to know about the scene.

    ``radar_position`` (3,) [m]; ``prf`` and ``carrier_frequency`` [Hz]; ``pulse_times``
    (n_pulses,) [s] and ``gate_range`` (n_pulses,) [m]: of the block for scatterer-stage effects,
    of the whole record for received-stage effects; ``skeleton``: the body at the block's pulse
    times in the scene frame (canonical joints when the scatterer model uses them), ``None`` for
    received-stage effects; ``waveform``: the radar plugin (for its bandwidth, pulse width, range
    equation); ``rng``: the effect's own seeded generator (from the run's seed and the number of
    effects of its stage listed after it: :func:`mdframework.pipeline.effect_generators`;
    received-stage effects only: a scatterer-stage effect must not draw random numbers, so that
    it is block-invariant); ``block_start``: index of the block's first
    pulse in the record (0 for received-stage effects); ``echo`` (n_pulses,) complex [sqrt(W)]:
    received-stage effects only, the record's slow-time signal as the radar gave it, before any
    received-stage effect (the target's echo, with the paths the scatterer-stage effects added,
    and the noise and clutter of a radar that puts them in its raw samples): the reference of a
    level set relative to the signal (the noise's ``snr_db``, the clutter's ``csr_db``), so that
    it does not depend on the order of the received-stage effects (``None``: take the data as it
    comes).
    """

    radar_position: FloatArray
    prf: float
    carrier_frequency: float
    pulse_times: FloatArray
    gate_range: FloatArray
    skeleton: Skeleton | None
    waveform: RadarWaveform
    rng: np.random.Generator
    block_start: int = 0
    echo: ComplexArray | None = None


class Effect(Plugin):
    """A scene effect (noise, clutter, multipath, antenna pattern, shadowing, ...).

    ``stage`` says where it acts: on the scatterers before the radar (``"scatterers"``: it gets
    and returns :class:`Scatterers` of one block, e.g. attenuating RCS or adding image
    scatterers; it must be deterministic and block-invariant) or on the received data
    (``"received"``: it gets and returns the whole record's :class:`Received`, e.g. adding
    noise).
    The pipeline instantiates and runs only the effects a scene's ``effects`` list names, in
    that order within each stage; an effect not named is never constructed.
    """

    stage: ClassVar[Literal["scatterers", "received"]]

    def start_record(self, body: Skeleton, radar_position: FloatArray) -> None:
        """Called once per record before its blocks, with the whole placed body at the source's
        own frame times and the radar position (3,) [m]: a scatterer-stage effect takes
        record-wide quantities (e.g. a fixed beam's aim) from here and resets what it
        accumulates over blocks. Default: nothing."""

    def check_radar(self, waveform: RadarWaveform) -> None:
        """Called when a run's plugins are built, with its radar: raise
        :class:`~mdframework.errors.SceneError` (naming the config field) when this effect
        cannot work with that radar, so that the run is refused before any pulse is simulated.
        Default: nothing."""

    def receiver_input(self, context: SceneContext) -> ReceiverInput | None:
        """A received-stage effect that a radar can simulate in its raw samples returns what it
        puts there, when the radar takes it (:attr:`RadarWaveform.takes_receiver_inputs`);
        :meth:`apply` is then not called. Called once per record before its blocks, with the
        record's ``pulse_times`` and ``gate_range`` and the effect's own generator. Default
        None: the effect acts on the slow-time signal (:meth:`apply`)."""
        return None

    def check_effects(self, effects: Sequence[Effect]) -> None:
        """Called when a run's plugins are built, after :meth:`check_radar`, with every effect
        the scene lists, in the listed order (this one among them): raise
        :class:`~mdframework.errors.SceneError` (naming the ``effects`` list) when this effect
        cannot work with the others in that order. Default: nothing."""

    def refuse_listed_after(self, effects: Sequence[Effect], why: Mapping[str, str]) -> None:
        """For :meth:`check_effects`: a :class:`~mdframework.errors.SceneError` naming both
        places in the ``effects`` list when an effect whose name is a key of ``why`` is listed
        after this one (``why[name]``: what would go wrong, e.g. the scatterers that ``multipath``
        adds would miss this effect)."""
        from .errors import SceneError

        mine = next((i for i, e in enumerate(effects) if e is self), None)
        if mine is None:  # a caller's bug: check_effects passes the list that holds this effect
            raise ValueError(f"refuse_listed_after: effect {self.name!r} is not in the list")
        for i, e in enumerate(effects[mine + 1 :], mine + 1):
            if e.name in why:
                raise SceneError(
                    f"effects: {self.name} (effects[{mine}]) is listed before {e.name} "
                    f"(effects[{i}]), so {why[e.name]}: list {self.name} after {e.name}"
                )

    @abstractmethod
    def apply(self, data: Any, context: SceneContext) -> Any:
        """Return the modified ``Scatterers`` (of one block) or ``Received`` (of the record)."""

    def describe(self) -> dict[str, Any]:
        """What this effect did, for the run's metadata (default: its config)."""
        return dict(self.config.model_dump())


# --------------------------------------------------------------------------- old names

#: old public name -> current one (each still importable, with a DeprecationWarning)
OLD_NAMES = {"RadarRecordingSource": "RecordingSource"}


def __getattr__(name: str) -> Any:
    if name in OLD_NAMES:
        new = OLD_NAMES[name]
        warnings.warn(
            f"{__name__}.{name} is deprecated: use {__name__}.{new}",
            DeprecationWarning,
            stacklevel=2,
        )
        return globals()[new]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
