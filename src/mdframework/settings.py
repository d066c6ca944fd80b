"""Config models shared by the pipeline, datasets and experiments (below the pipeline).

These are plain pydantic models with no knowledge of plugins: the scene, processing and
conditioning sections, the base of motion-source configs, and :data:`DataPath`. The run model
that adds the plugin sections is built from the registry in :mod:`mdframework.config`, above the
pipeline.

Relative paths inside a config are relative to the config file's folder (the validation context's
``base_dir``).

Numbers: every float field of every config model (these and every plugin's, through
:class:`~mdframework.interfaces.PluginConfig`) must be finite (``allow_inf_nan=False``), and every
numeric field is bounded on both sides. The shared bounded types below (:data:`Coordinate`,
:data:`Seconds`, :data:`FrameRate`, :data:`Decibels`, ...) take their limits from
:mod:`mdframework.limits`; ``docs/input-rules.md`` lists them.
"""

from __future__ import annotations

import stat
from pathlib import Path
from typing import Annotated, Literal

from pydantic import (
    AfterValidator,
    Field,
    ValidationInfo,
    field_validator,
    model_validator,
)

from . import limits
from .errors import unnameable
from .interfaces import ConfigSection, FloatArray, PluginConfig, RadarConfig
from .physics import radar
from .physics.interpolation import Method
from .skeleton import Axis, check_axes, check_motion_axes

# ----------------------------------------------------------------- bounded numeric types

#: A position coordinate [m], |value| <= limits.MAX_COORDINATE_M.
Coordinate = Annotated[float, Field(ge=-limits.MAX_COORDINATE_M, le=limits.MAX_COORDINATE_M)]
#: A horizontal position (x, y) [m].
Point2 = tuple[Coordinate, Coordinate]
#: A position (x, y, z) [m].
Point3 = tuple[Coordinate, Coordinate, Coordinate]
#: A distance > 0 [m], at most limits.MAX_COORDINATE_M.
Distance = Annotated[float, Field(gt=0, le=limits.MAX_COORDINATE_M)]
#: An angle [deg] within one turn either way.
AngleDeg = Annotated[float, Field(ge=-360.0, le=360.0)]
#: A time or time offset [s], 0 .. limits.MAX_DURATION_S.
Seconds = Annotated[float, Field(ge=0, le=limits.MAX_DURATION_S)]
#: A duration > 0 [s], at most limits.MAX_DURATION_S.
PositiveSeconds = Annotated[float, Field(gt=0, le=limits.MAX_DURATION_S)]
#: A frame rate [Hz] of a recording or generated track.
FrameRate = Annotated[float, Field(ge=limits.MIN_FRAME_RATE_HZ, le=limits.MAX_FRAME_RATE_HZ)]
#: A bandwidth or sample rate > 0 [Hz].
Bandwidth = Annotated[float, Field(gt=0, le=limits.MAX_BANDWIDTH_HZ)]
#: A decibel value (gain, ratio) [dB], |value| <= limits.MAX_DB.
Decibels = Annotated[float, Field(ge=-limits.MAX_DB, le=limits.MAX_DB)]
#: A loss or attenuation [dB], 0 .. limits.MAX_DB.
LossDb = Annotated[float, Field(ge=0, le=limits.MAX_DB)]
#: A level below a peak [dB], -limits.MAX_DB .. < 0.
BelowPeakDb = Annotated[float, Field(ge=-limits.MAX_DB, lt=0)]
#: A radar cross section [m^2], 0 .. limits.MAX_RCS_M2.
Rcs = Annotated[float, Field(ge=0, le=limits.MAX_RCS_M2)]
#: A seed of random draws (a 64-bit unsigned integer).
Seed = Annotated[int, Field(ge=0, lt=2**64)]
#: A step rate [steps/min].
Cadence = Annotated[float, Field(ge=0, le=1000)]
#: A leg's length [m], hip to knee to ankle (a bound of the motion size check).
LegLength = Annotated[float, Field(ge=0, le=100)]
#: A worker (process) count.
Workers = Annotated[int, Field(ge=1, le=1024)]


def _short_path(path: Path) -> str:
    """A path as an error shows it: at most 200 characters (the middle cut out)."""
    text = str(path)
    return text if len(text) <= 200 else f"{text[:100]}...{text[-97:]}"


def _resolve_path(value: Path, info: ValidationInfo) -> Path:
    base = (info.context or {}).get("base_dir")
    path = Path(value).expanduser()
    if not path.is_absolute() and base is not None:
        path = Path(base) / path
    why = unnameable(path)
    if why is not None:
        raise ValueError(f"{path}: {why}")
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        raise ValueError(f"file not found: {path}") from None
    except OSError as exc:  # a name too long, a folder on the way that cannot be read
        raise ValueError(f"{_short_path(path)}: cannot read: {exc.strerror or exc}") from None
    if stat.S_ISDIR(mode):
        raise ValueError(f"{path} is a folder; name a file in it")
    return path.absolute()  # a resolved config read from anywhere names the same file


#: A path to an existing file, relative to the config file's folder (absolute once validated).
DataPath = Annotated[Path, AfterValidator(_resolve_path)]


def _motion_axes(value: tuple[str, str, str], info: ValidationInfo) -> tuple[str, str, str]:
    if info.data.get("handedness") == "left":
        check_axes(value)  # a mirror, as a left-handed file needs: OrientedMotionConfig's check
    else:
        check_motion_axes(value)
    return value


#: A motion source's ``axes``: the file axis (with sign) that becomes x (forward), y (left) and
#: z (up); x, y and z once each, and a rotation, not a mirror
#: (:func:`mdframework.skeleton.check_motion_axes`), unless the config declares the file's
#: frame left-handed (:class:`OrientedMotionConfig`).
MotionAxes = Annotated[tuple[Axis, Axis, Axis], AfterValidator(_motion_axes)]


class StrictModel(ConfigSection):
    """Base of every config model that is not a plugin's (see
    :class:`~mdframework.interfaces.ConfigSection`)."""


class SanityConfig(StrictModel):
    """Motion sanity checks (:mod:`mdframework.sanity`), run on every human motion right after
    its source reads it. Thresholds and their basis are documented in ``docs/motion-formats.md``.
    """

    enabled: bool = Field(True, description="Run the checks at all.")
    glitches: Literal["warn", "repair", "ignore", "error"] = Field(
        "warn",
        description="Single-frame glitches: flag them in the metadata and warn (default), "
        "repair them (the frame is replaced by interpolation from its neighbours), flag "
        "silently, or stop.",
    )
    glitch_min_m: float = Field(
        0.02,
        gt=0,
        le=10,
        description="Smallest glitch [m]: a frame's distance from the line between its two "
        "neighbours must reach this.",
    )
    glitch_ratio: float = Field(
        1.6,
        gt=1,
        le=1000,
        description="A glitch stands out from its neighbours: its deviation is at least this "
        "many times theirs (a pure one-frame spike gives 2).",
    )
    glitch_local_ratio: float = Field(
        5.0,
        gt=1,
        le=1000,
        description="... and at least this many times the median deviation of the 13 frames "
        "around it (fast but smooth motion has no such outlier).",
    )
    glitch_return_ratio: float = Field(
        0.3,
        ge=0,
        le=1000,
        description="... and the joint comes back: its velocity after the frame differs from "
        "the one before by at most this fraction of the deviation (as a distance, |v_after - "
        "v_before| dt1 dt2 / (dt1 + dt2)): a one-frame spike gives 0, a real change of "
        "velocity made within one frame (a foot leaving the floor at 30 Hz) 1 or more.",
    )
    limits: Literal["warn", "ignore", "error"] = Field(
        "warn",
        description="A joint faster or more accelerated than the human limits "
        "(speed_limits_mps, accel_limits_mps2): warn, flag silently, or stop.",
    )
    speed_scale: float = Field(
        1.0, gt=0, le=1000, description="Multiplies every speed and acceleration limit."
    )
    bone_tolerance: float = Field(
        0.1,
        gt=0,
        le=100,
        description="Largest coefficient of variation (std / mean) of a limb bone's length "
        "before the motion is flagged (optical and depth-camera tracks; a rigid rig gives 0).",
    )
    cadence: bool = Field(
        True, description="Check the step rate of motions labelled walk or run/jog."
    )
    walk_cadence: tuple[Cadence, Cadence] = Field(
        (70.0, 150.0), description="Plausible walking cadence [steps/min]."
    )
    run_cadence: tuple[Cadence, Cadence] = Field(
        (130.0, 230.0), description="Plausible running or jogging cadence [steps/min]."
    )
    upright: Literal["warn", "ignore", "error"] = Field(
        "warn",
        description="A body whose head is not above its pelvis (median over the frames below "
        "upright_min_m: lying flat or upside down, usually a file read with the wrong up axis; "
        "see the sources' axes option): warn, flag silently, or stop.",
    )
    upright_min_m: float = Field(
        0.2,
        ge=0,
        le=10,
        description="Smallest median height [m] of the head above the pelvis of an upright "
        "body (the shipped recordings give 0.45-0.8 m).",
    )
    gaps: Literal["warn", "ignore", "error"] = Field(
        "warn",
        description="A joint untracked, or every joint without a frame (a step longer than "
        "1.5 frame periods too), for longer than max_gap_s between tracked frames (markers "
        "hidden from the cameras, frames a tracker dropped), which the simulation bridges by "
        "interpolation: warn, flag silently, or stop.",
    )
    max_gap_s: PositiveSeconds = Field(
        0.2,
        description="Longest gap [s] bridged without a finding (0.2 s: about a fifth of a gait "
        "cycle, conditioning's max_gap_s).",
    )
    size: Literal["warn", "ignore", "error"] = Field(
        "warn",
        description="A body whose legs (hip to knee to ankle, median over the frames) are "
        "outside leg_length_m: a file read in the wrong length unit (see the sources' unit_m "
        "or units): warn, flag silently, or stop.",
    )
    leg_length_m: tuple[LegLength, LegLength] = Field(
        (0.4, 1.5),
        description="Plausible length [m] of a leg, hip to knee to ankle (the shipped "
        "recordings give 0.76-1.04 m).",
    )
    mirrored: Literal["warn", "ignore", "error"] = Field(
        "warn",
        description="An upright body whose feet point backwards from the way its left and "
        "right joints face (a mirror image: a left-handed file, which the sources' handedness "
        "option reads, or left and right joints named the other way round): warn, flag "
        "silently, or stop.",
    )

    @model_validator(mode="after")
    def _check_ranges(self) -> SanityConfig:
        for name in ("walk_cadence", "run_cadence", "leg_length_m"):
            lo, hi = getattr(self, name)
            if lo > hi:
                raise ValueError(f"{name}: the lower bound {lo:g} is above the upper {hi:g}")
        return self


class MotionConfig(PluginConfig):
    """Base of motion-source configs: every source can be cut to a time window, and its
    motion is checked for sanity after loading."""

    start: Seconds = Field(0.0, description="Start of the window [s], from the first frame.")
    duration: PositiveSeconds | None = Field(
        None, description="Length of the window [s]; default: to the end."
    )
    sanity: SanityConfig = Field(
        default_factory=SanityConfig,
        description="Motion sanity checks (speed and acceleration limits, single-frame "
        "glitches, bone lengths, cadence).",
    )

    def known_length(self) -> float | None:
        """Length of the record [s] when the config alone fixes it (``duration``), else
        ``None`` (known once the motion is loaded). Generators override it."""
        return self.duration


class OrientedMotionConfig(MotionConfig):
    """Base of the configs of motion sources that read a file's frame with ``axes``
    (:data:`MotionAxes`, which a subclass declares): declares whether that frame is
    right-handed, as motion files are and ``axes`` then must be a rotation, or left-handed (a
    Unity export, say), whose ``axes`` must then be a mirror, so that the body is read as it is,
    not as its mirror image."""

    handedness: Literal["right", "left"] = Field(
        "right",
        description="The file's frame: right-handed (motion files' usual; axes a rotation) or "
        "left-handed (a Unity export, say; axes then mirror it, e.g. the default's y axis with "
        "its sign changed). A left-handed file read as right-handed gives the body's mirror "
        "image, which the mirrored sanity check flags.",
    )

    @model_validator(mode="after")
    def _check_handedness(self) -> OrientedMotionConfig:
        axes = getattr(self, "axes")  # noqa: B009 (each subclass declares its own default)
        check_motion_axes(axes, left_handed=self.handedness == "left")
        return self


class RadarPowerConfig(RadarConfig):
    """Base of radar configs: transmit power, gains and losses, and the amplitude model."""

    transmit_power: float = Field(
        1.0, gt=0, le=1e9, description="Peak transmit power [W], at most 1 GW."
    )
    gain_dbi: Decibels = Field(0.0, description="Antenna gain (transmit = receive) [dBi].")
    system_loss_db: LossDb = Field(0.0, description="System loss L_s [dB].")
    atmospheric_loss_db: LossDb = Field(0.0, description="Atmospheric loss L_a [dB].")
    amplitude: radar.AmplitudeModel = Field(
        "range_equation",
        description="Scatterer amplitude: the radar range equation, or sqrt(rcs) with no range "
        "dependence (Chen's walker code; power, gain and losses unused).",
    )

    def amplitudes(self, rcs: FloatArray, ranges: FloatArray, wavelength: float) -> FloatArray:
        """Amplitude [sqrt(W)] of each scatterer (:func:`physics.radar.scatterer_amplitudes`)."""
        return radar.scatterer_amplitudes(
            rcs,
            ranges,
            model=self.amplitude,
            wavelength=wavelength,
            transmit_power=self.transmit_power,
            gain=10.0 ** (self.gain_dbi / 10.0),
            system_loss=10.0 ** (self.system_loss_db / 10.0),
            atmospheric_loss=10.0 ** (self.atmospheric_loss_db / 10.0),
        )


class PersonConfig(StrictModel):
    """Where the person is and how they move."""

    motion: Literal["recorded", "treadmill", "straight"] = Field(
        "recorded",
        description="recorded: keep the recording's translation; treadmill: remove it; "
        "straight: replace it by a straight path at `speed`.",
    )
    position: Point2 = Field(
        (0.0, 0.0), description="Horizontal position (x, y) of the hip centre at the start [m]."
    )
    heading_deg: AngleDeg | None = Field(
        None, description="Direction the person faces, degrees from +x toward +y."
    )
    aspect_deg: AngleDeg | None = Field(
        None,
        description="Facing direction relative to the radar: 0 = toward it, 90 = crossing, "
        "180 = away. Default 0 when neither this nor heading_deg is given.",
    )
    speed: float | None = Field(
        None,
        ge=0,
        le=limits.MAX_PERSON_SPEED_MPS,
        description="Speed for motion = 'straight' [m/s].",
    )
    facing: Literal["auto", "hips", "travel"] = Field(
        "auto",
        description="How the recording's own facing direction is found: from the hip line, "
        "from the direction of travel, or auto (travel if the hip centre moves > 0.5 m).",
    )

    @model_validator(mode="after")
    def _check(self) -> PersonConfig:
        if self.heading_deg is not None and self.aspect_deg is not None:
            raise ValueError("give heading_deg or aspect_deg, not both")
        if self.motion == "straight" and self.speed is None:
            raise ValueError("motion = 'straight' needs a speed")
        if self.motion != "straight" and self.speed is not None:
            raise ValueError("speed is used only with motion = 'straight'")
        return self


class SceneConfig(StrictModel):
    """The radar's position, the person's placement and the range gate."""

    radar_position: Point3 = Field(
        (10.0, 0.0, 2.0), description="Radar antenna position (x, y, z) [m]."
    )
    person: PersonConfig = Field(
        default_factory=PersonConfig, description="Where the person is and how they move."
    )
    gate: Literal["track"] | Distance = Field(
        "track",
        description="'track': the gate follows the hip centre (or the first point target); "
        "a number: a fixed gate range [m].",
    )
    min_range: float = Field(
        0.5, gt=0, le=1000, description="Smallest allowed scatterer range [m]; closer is an error."
    )


class ProcessingConfig(StrictModel):
    """Resampling and spectrogram settings."""

    interpolation: Method = Field(
        "cubic", description="Joint resampling: cubic (C2 spline), pchip, akima, linear."
    )
    window: str = Field("hann", description="STFT window (any scipy.signal window name).")

    @field_validator("window")
    @classmethod
    def _known_window(cls, value: str) -> str:
        from .physics.spectrogram import stft_window

        try:
            stft_window(value, 8)
        except (ValueError, TypeError) as exc:
            raise ValueError(f"unknown window {value!r}: {exc}") from None
        return value

    window_length: int = Field(256, ge=2, le=65536, description="STFT window length [pulses].")
    hop: int = Field(32, ge=1, le=65536, description="STFT hop [pulses].")
    nfft: int = Field(1024, ge=2, le=2**20, description="FFT size (>= window_length).")
    floor_db: BelowPeakDb = Field(-60.0, description="Spectrogram floor, dB below its peak.")
    precision: Literal["float32", "float64"] = Field(
        "float32",
        description="STFT arithmetic: float32 (complex64 FFTs and float32 power, the default: "
        "the accuracy ladder measures its cost at under 0.001 dB) or float64.",
    )
    block_pulses: int = Field(
        4096,
        ge=16,
        le=1_000_000,
        description="Pulses per block of the streaming pipeline: the per-scatterer arrays exist "
        "one block at a time, so memory is set by this, not by the record length.",
    )
    keep_scatterers: bool = Field(
        False,
        description="Keep every pulse's scatterer positions and RCS in the result (and write "
        "their ranges and RCS to result.npz); memory then grows with the record.",
    )
    aliasing: Literal["warn", "error"] = Field(
        "warn",
        description="When a scatterer's radial speed exceeds the unambiguous lambda*PRF/4 its "
        "Doppler folds over: 'warn' (the warning names the PRF that avoids it; the results are "
        "still written) or 'error' (stop, write nothing). `mdf check` predicts it.",
    )
    empty: Literal["warn", "error"] = Field(
        "warn",
        description="When the result is empty (an all-zero or underflowed echo, or more than "
        "max_lost_fraction of the scatterer returns lost to the range gate or to the scene "
        "effects): warn with the cause, or stop.",
    )
    max_lost_fraction: float = Field(
        0.5,
        gt=0,
        le=1,
        description="Largest share of scatterer returns (scatterer x pulse) that may be lost "
        "(weighted by -20 dB or less by the range gate or the scene effects) before the result "
        "counts as empty.",
    )

    @model_validator(mode="after")
    def _check(self) -> ProcessingConfig:
        if self.nfft < self.window_length:
            raise ValueError(
                f"nfft: {self.nfft} is shorter than window_length {self.window_length}: give an "
                "nfft of at least the window's length"
            )
        return self


class ConditioningConfig(StrictModel):
    """Skeleton conditioning (:mod:`mdframework.conditioning`), applied to the whole canonical
    recording before placement and windowing. Off by default; each step can be switched on its
    own. (Sorting time stamps and dropping duplicates happens in the motion sources, since a
    Skeleton's time stamps are strictly increasing by construction; they report it in their
    metadata.)"""

    enabled: bool = Field(False, description="Condition the body at all (default: off).")
    zeros_untracked: bool = Field(
        True, description="Treat an exact (0, 0, 0) joint as untracked (Kinect's lost joints)."
    )
    max_gap_s: PositiveSeconds = Field(
        0.2,
        description="Untracked gaps, and steps between frames (frames the file lacks), longer "
        "than this [s] are flagged (all gaps are bridged by the spline); about a fifth of a "
        "gait cycle.",
    )
    long_gaps: Literal["flag", "error"] = Field(
        "flag", description="A gap longer than max_gap_s: flag it in the metadata, or stop."
    )
    foot_outliers: bool = Field(
        True,
        description="Detect foot segments (ankle to toe) deviating from their mean beyond the "
        "histogram-derived threshold and predict them from past frames (Erol & Gurbuz).",
    )
    outlier_bin_m: float = Field(
        0.01, gt=0, le=1, description="Histogram bin width of the outlier deviations [m]."
    )
    outlier_min_threshold_m: float = Field(
        0.05,
        gt=0,
        le=10,
        description="Smallest outlier threshold [m], whatever the histogram says.",
    )
    foot_length_m: float | None = Field(
        None,
        gt=0,
        le=0.5,
        description="The subject's measured foot length (ankle to toe) [m]; when given, the toe "
        "is moved along the foot to this length in every frame.",
    )
    angle_check: bool = Field(
        True,
        description="Report the knee-ankle-foot angle of eq. (7) and its period (a check for "
        "walking and running).",
    )
    speed_limit: bool = Field(
        True, description="Replace frames where a joint moves faster than max_speed_mps."
    )
    max_speed_mps: float = Field(
        6.0,
        gt=0,
        le=100,
        description="Physical joint speed limit [m/s]: walking feet peak near 4-5 m/s; raise to "
        "about 10 for running (feet reach ~9 m/s).",
    )
    smoothing: Literal["none", "violating", "all"] = Field(
        "violating",
        description="Gaussian smoothing of the joint tracks, after the speed limit: of no joint, "
        "of the joints that exceeded the limit (none when speed_limit is false), or of all "
        "joints (with or without speed_limit).",
    )
    smoothing_sigma_s: float = Field(
        0.03, ge=0, le=10, description="Standard deviation of the smoothing kernel [s]."
    )


#: The matplotlib release whose colour maps :data:`COLORMAPS` lists: the lowest that
#: pyproject.toml allows, so that every name a config accepts draws (3.10 lacks okabe_ito; 3.8
#: and 3.9 also lack berlin, managua and vanimo, and the ``_r`` of Grays, grey, gist_grey and
#: gist_yerg).
COLORMAPS_MATPLOTLIB = "3.11"

#: matplotlib's built-in colour maps (each also reversed, with ``_r``), listed here so that
#: reading a config never imports matplotlib (a run without figures never does);
#: tests/test_figures.py checks the list against the installed matplotlib.
COLORMAPS = frozenset(
    (
        "Accent Blues BrBG BuGn BuPu CMRmap Dark2 GnBu Grays Greens Greys OrRd Oranges PRGn "
        "Paired Pastel1 Pastel2 PiYG PuBu PuBuGn PuOr PuRd Purples RdBu RdGy RdPu RdYlBu RdYlGn "
        "Reds Set1 Set2 Set3 Spectral Wistia YlGn YlGnBu YlOrBr YlOrRd afmhot autumn berlin "
        "binary bone brg bwr cividis cool coolwarm copper cubehelix flag gist_earth gist_gray "
        "gist_grey gist_heat gist_ncar gist_rainbow gist_stern gist_yarg gist_yerg gnuplot "
        "gnuplot2 gray grey hot hsv inferno jet magma managua nipy_spectral ocean okabe_ito pink "
        "plasma prism rainbow seismic spring summer tab10 tab20 tab20b tab20c terrain turbo "
        "twilight twilight_shifted vanimo viridis winter"
    ).split()
)


class FiguresConfig(StrictModel):
    """How a run's figures show the data (``spectrogram.png``, ``range_time.png``,
    ``range_doppler.png`` and the motion preview of ``mdf show``). The arrays in ``result.npz``
    are not affected."""

    enabled: bool = Field(
        True,
        description="Draw the run's figures (spectrogram.png, range_time.png, range_doppler.png, "
        "point_cloud.png). false writes the arrays and JSON/CSV files only, and the run never "
        "imports matplotlib (about half of a short run's wall time); `mdf run --no-figures` "
        "does the same.",
    )
    dynamic_range_db: float = Field(
        40.0,
        gt=0,
        le=limits.MAX_DB,
        description="Power range shown in colour, dB below the peak; weaker is drawn at the "
        "bottom of the colour map. 40 dB shows a walker's limbs above the window sidelobes.",
    )
    velocity_span: (
        Literal["auto", "full"] | Annotated[float, Field(gt=0, le=limits.MAX_TARGET_SPEED_MPS)]
    ) = Field(
        "auto",
        description="Velocity axis of spectrograms: 'auto' covers the velocities where the "
        "shown power is (with a margin, zero included); 'full' the whole unambiguous span "
        "+-lambda*PRF/4; a number v: -v..v [m/s].",
    )
    colormap: str = Field(
        "viridis",
        description="matplotlib colour map of power images; perceptually uniform ones "
        "(viridis, magma, inferno, plasma, cividis) keep equal dB steps equally visible.",
    )

    @field_validator("colormap")
    @classmethod
    def _known_colormap(cls, value: str) -> str:
        if value.removesuffix("_r") not in COLORMAPS:
            raise ValueError(f"unknown colour map {value!r}; try viridis, magma or cividis")
        return value


class RunConfigBase(StrictModel):
    """Fields every run config has besides the plugin sections."""

    seed: Seed = Field(
        0,
        description="Seed of every random draw in the run (noise, clutter, the FMCW radar's "
        "receiver noise), except the static_scene room, always drawn from that effect's own "
        "seed (default 0), and the FMCW radar's receiver noise when its noise_seed is given.",
    )

    scene: SceneConfig = Field(default_factory=SceneConfig, description="The scene.")
    processing: ProcessingConfig = Field(
        default_factory=ProcessingConfig, description="Resampling and spectrogram."
    )
    conditioning: ConditioningConfig = Field(
        default_factory=ConditioningConfig,
        description="Skeleton conditioning of the body (off by default).",
    )
    figures: FiguresConfig = Field(
        default_factory=FiguresConfig, description="How the run's figures show the data."
    )
