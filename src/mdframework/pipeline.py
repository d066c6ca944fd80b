"""The run pipeline: wires the stages, computes nothing itself.

motion source -> canonical body -> conditioning -> scene placement -> window -> resampling to
pulse times -> scatterers and RCS -> effects (scatterers) -> ranges (checked) -> radar receive
and pulse compression -> effects (received) -> spectrogram.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import conditioning, sanity
from .errors import SceneError
from .interfaces import (
    Effect,
    Motion,
    MotionSource,
    RadarWaveform,
    Received,
    ScattererModel,
    Scatterers,
    SceneContext,
)
from .physics import interpolation, radar, scene
from .physics.spectrogram import RecordTooShortError, Spectrogram, power_to_db, spectrogram
from .plugins import Registry, default_registry
from .settings import ConditioningConfig, PersonConfig, RunConfigBase, SanityConfig
from .skeleton import Skeleton

FloatArray = NDArray[np.float64]


class AliasingWarning(UserWarning):
    """A scatterer moves faster than the PRF can represent without Doppler aliasing."""


@dataclass(frozen=True)
class RunResult:
    """Everything a run produces. Arrays: ``pulse_times`` (n_pulses,) [s from the first pulse];
    ``gate_range`` (n_pulses,) [m]; ``received.signal`` (n_pulses,) complex [sqrt(W)];
    ``spectrogram_db`` (n_doppler, n_frames) [dB re peak]; ``velocity`` (n_doppler,) [m/s]."""

    pulse_times: FloatArray
    gate_range: FloatArray
    scatterers: Scatterers
    received: Received
    spectrogram: Spectrogram
    spectrogram_db: FloatArray
    velocity: FloatArray
    metadata: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Stages:
    """The plugin instances of one run; ``effects`` holds only those the scene names."""

    source: MotionSource
    model: ScattererModel
    radar: RadarWaveform
    effects: tuple[Effect, ...] = ()


def build_stages(config: RunConfigBase, registry: Registry | None = None) -> Stages:
    """Instantiate the plugins a config names."""
    reg = registry or default_registry()
    cfg: Any = config

    def make(interface: str, section: Any) -> Any:
        try:
            return reg.get(interface, section.kind)(section)
        except KeyError as exc:
            raise SceneError(str(exc.args[0])) from None

    return Stages(
        make("motion", cfg.motion),
        make("scatterers", cfg.scatterers),
        make("radar", cfg.radar),
        tuple(make("effect", e) for e in cfg.effects),
    )


def _apply_effects(
    stages: Stages, stage: str, data: Any, context: SceneContext, ran: list[dict[str, Any]]
) -> Any:
    for effect in stages.effects:
        if effect.stage == stage:
            data = effect.apply(data, context)
            ran.append({"kind": effect.name, "stage": stage, **effect.describe()})
    return data


def place_body(body: Skeleton, person: PersonConfig, radar_position: FloatArray) -> Skeleton:
    """Put a canonical body into the scene as ``person`` says (see :func:`physics.scene.place`)."""
    base = body.joint("base")
    try:
        heading_now = scene.body_heading(
            base, body.joint("l_hip"), body.joint("r_hip"), rule=person.facing
        )
    except ValueError as exc:
        raise SceneError(f"scene.person.facing: {exc}") from None
    if person.heading_deg is not None:
        heading = np.deg2rad(person.heading_deg)
    else:
        to_radar = radar_position[:2] - np.asarray(person.position)
        if np.hypot(*to_radar) < 1e-9:
            raise SceneError(
                "scene.person.aspect_deg: the radar is straight above the person; "
                "give heading_deg instead"
            )
        heading = np.arctan2(to_radar[1], to_radar[0]) + np.deg2rad(person.aspect_deg or 0.0)
    positions = scene.place(
        body.time,
        body.positions,
        base=base,
        heading_now=heading_now,
        heading=float(heading),
        position=np.asarray(person.position),
        mode=person.motion,
        speed=person.speed or 0.0,
    )
    return body.with_positions(positions)


def _is_default_placement(person: PersonConfig) -> bool:
    return person == PersonConfig()


def simulate(config: RunConfigBase, registry: Registry | None = None) -> RunResult:
    """Run one config end to end."""
    stages = build_stages(config, registry)
    t0 = time.perf_counter()
    motion = load_motion(stages.source)
    timings = {"load": time.perf_counter() - t0}
    return simulate_motion(config, stages, motion, timings)


def load_motion(source: MotionSource) -> Motion:
    """``source.load()``, with a plugin's own check of its input (``ValueError``) reported as
    a one-line user error naming the source, followed by the motion sanity checks
    (:func:`mdframework.sanity.check_motion`, with the source config's ``sanity`` section)."""
    try:
        motion = source.load()
    except ValueError as exc:
        raise SceneError(f"motion {source.name!r}: {exc}") from None
    return sanity.check_motion(motion, getattr(source.config, "sanity", SanityConfig()))


def simulate_motion(
    config: RunConfigBase, stages: Stages, motion: Motion, timings: dict[str, float] | None = None
) -> RunResult:
    """Run the stages after the motion source on an already loaded motion."""
    cfg: Any = config
    timings = {} if timings is None else timings
    sc = config.scene
    proc = config.processing
    radar_pos = np.asarray(sc.radar_position, dtype=np.float64)
    wf = stages.radar
    lam = radar.wavelength(wf.carrier_frequency)

    clock = time.perf_counter()
    if stages.model.needs_canonical and motion.canonical_map is None:
        raise SceneError(
            f"scatterers.kind: the {stages.model.name!r} model needs a human body, but this "
            f"motion ({motion.metadata.get('source', 'unknown')}) has no canonical joints"
        )
    # conditioning and placement see the whole recording (facing, drift, outlier statistics);
    # the record is then a window of the placed recording
    body = motion.canonical() if stages.model.needs_canonical else motion.skeleton
    body, conditioning_report = _condition(body, config.conditioning)
    if stages.model.needs_canonical:
        body = place_body(body, sc.person, radar_pos)
        placement = sc.person.model_dump()
    elif not _is_default_placement(sc.person):
        raise SceneError(
            "scene.person: placement applies to human bodies only; this motion "
            f"({motion.metadata.get('source', 'unknown')}) is used as recorded"
        )
    else:
        placement = {"motion": "as given"}
    t_start, t_end = _window(body, cfg.motion.start, cfg.motion.duration)

    # the spline sees the whole recording, so a record has no end effects of its own
    t = interpolation.pulse_times(t_start, t_end, wf.prf)
    joints = interpolation.resample_tracks(
        body.time, body.positions, body.valid, t, proc.interpolation
    )
    at_pulses = Skeleton(t, joints, body.joint_names)
    timings["resample"] = time.perf_counter() - clock

    clock = time.perf_counter()
    scat = stages.model.scatterers(motion, at_pulses, radar_pos, lam)
    gate = _gate(sc.gate, at_pulses, radar_pos)
    effects_ran: list[dict[str, Any]] = []
    seeds = np.random.SeedSequence(config.seed).spawn(len(stages.effects) + 1)
    context = SceneContext(
        radar_pos,
        wf.prf,
        wf.carrier_frequency,
        t,
        gate,
        at_pulses,
        wf,
        np.random.default_rng(seeds[0]),
    )
    scat = _apply_effects(stages, "scatterers", scat, context, effects_ran)
    ranges = scat.ranges(radar_pos)
    _check_ranges(ranges, scat, t, sc.min_range)
    v_max = radar.max_unambiguous_velocity(wf.carrier_frequency, wf.prf)
    speed = _max_radial_speed(ranges, wf.prf)
    if speed > v_max:
        msg = (
            f"the fastest scatterer moves at {speed:.2f} m/s radially, beyond the unambiguous "
            f"{v_max:.2f} m/s of PRF {wf.prf:g} Hz: its Doppler aliases"
        )
        if proc.aliasing == "error":
            raise SceneError(msg)
        warnings.warn(msg, AliasingWarning, stacklevel=2)
    timings["scatterers"] = time.perf_counter() - clock

    clock = time.perf_counter()
    received = wf.receive(ranges, scat.rcs, gate)
    received = _apply_effects(stages, "received", received, context, effects_ran)
    timings["receive"] = time.perf_counter() - clock

    clock = time.perf_counter()
    try:
        spec = spectrogram(
            received.signal,
            wf.prf,
            window=proc.window,
            window_length=proc.window_length,
            hop=proc.hop,
            nfft=proc.nfft,
        )
    except RecordTooShortError as exc:
        raise SceneError(f"processing.window_length: {exc}") from None
    spec_db = power_to_db(spec.power, proc.floor_db)
    velocity = radar.doppler_to_velocity(spec.doppler, wf.carrier_frequency)
    timings["spectrogram"] = time.perf_counter() - clock

    metadata = {
        "motion": dict(motion.metadata),
        "placement": placement,
        "conditioning": conditioning_report,
        "scatterers": list(scat.names),
        "n_pulses": int(t.shape[0]),
        "prf_hz": wf.prf,
        "carrier_frequency_hz": wf.carrier_frequency,
        "wavelength_m": lam,
        "max_unambiguous_velocity_mps": v_max,
        "max_radial_speed_mps": speed,
        "radar_position_m": list(sc.radar_position),
        "record_start_s": t_start,
        "effects": effects_ran,
        "seed": config.seed,
        "timings_s": timings,
    }
    return RunResult(t - t[0], gate, scat, received, spec, spec_db, velocity, metadata)


def _gate(gate: str | float, at_pulses: Skeleton, radar_pos: FloatArray) -> FloatArray:
    """Range gate per pulse [m]: tracking the hip centre (or the first joint), or fixed."""
    if gate == "track":
        ref = at_pulses.index("base") if "base" in at_pulses.joint_names else 0
        d = at_pulses.positions[:, ref, :] - radar_pos
        return np.asarray(np.sqrt(np.sum(d * d, axis=1)), dtype=np.float64)
    return np.full(at_pulses.time.shape, float(gate))


def _window(body: Skeleton, start: float, duration: float | None) -> tuple[float, float]:
    """First and last time [s] of the record (``start``/``duration`` from the first frame)."""
    end = start + duration if duration is not None else body.duration
    if start >= body.duration:
        raise SceneError(
            f"motion.start: {start:g} s is not before the end of the recording "
            f"({body.duration:.3f} s)"
        )
    if end > body.duration + 1e-9:
        raise SceneError(
            f"motion.duration: the window {start:g}..{end:g} s ends after the recording "
            f"({body.duration:.3f} s)"
        )
    return float(body.time[0] + start), float(body.time[0] + min(end, body.duration))


def _condition(body: Skeleton, cfg: ConditioningConfig) -> tuple[Skeleton, dict[str, Any]]:
    """Skeleton conditioning when enabled (:func:`conditioning.condition`)."""
    if not cfg.enabled:
        return body, {"enabled": False}
    try:
        return conditioning.condition(body, cfg)
    except ValueError as exc:
        raise SceneError(f"conditioning: {exc}") from None


def _check_ranges(ranges: FloatArray, scat: Scatterers, t: FloatArray, min_range: float) -> None:
    if not np.all(np.isfinite(ranges)):
        raise SceneError("a scatterer position is not finite")
    p, s = np.unravel_index(int(np.argmin(ranges)), ranges.shape)
    if ranges[p, s] < min_range:
        raise SceneError(
            f"scatterer {scat.names[s]!r} comes within {ranges[p, s]:.3g} m of the radar at "
            f"t = {t[p] - t[0]:.3f} s (scene.min_range = {min_range:g} m): the range equation "
            "and far-field RCS do not hold there"
        )


def _max_radial_speed(ranges: FloatArray, prf: float) -> float:
    if ranges.shape[0] < 2:
        return 0.0
    return float(np.max(np.abs(np.diff(ranges, axis=0))) * prf)
