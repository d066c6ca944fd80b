"""The run pipeline: wires the stages, computes nothing itself.

motion source -> canonical body -> conditioning -> scene placement (whole recording) -> record
window -> then, block by block of pulses: resampling to the pulse times -> scatterers and RCS ->
effects (scatterers) -> ranges (checked) -> radar receive and pulse compression; then, on the
record's slow-time signal: effects (received) -> spectrogram.

Memory: the per-scatterer arrays (n_pulses, n_scatterers, ...) exist one block at a time
(``processing.block_pulses``); only per-pulse arrays (signal, gate) and the spectrogram span the
record.
"""

from __future__ import annotations

import time
import warnings
import weakref
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import conditioning, emptiness, limits, sanity
from .errors import DataFileError, MdfError, SceneError
from .fingerprint import motion_fingerprint
from .interfaces import (
    Effect,
    Motion,
    MotionSource,
    PulseBlock,
    RadarWaveform,
    Received,
    ReceiverInput,
    ScattererModel,
    Scatterers,
    SceneContext,
)
from .physics import interpolation, radar, scene
from .physics.spectrogram import (
    RecordTooShortError,
    Spectrogram,
    SpectrogramGeometry,
    power_to_db,
    spectrogram,
)
from .plugins import Registry, blame, default_registry, name_plugin_bug
from .progress import QUIET, Progress
from .settings import (
    ConditioningConfig,
    PersonConfig,
    ProcessingConfig,
    RadarPowerConfig,
    RunConfigBase,
    SanityConfig,
)
from .skeleton import Skeleton

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


class AliasingWarning(UserWarning):
    """A scatterer moves faster than the PRF can represent without Doppler aliasing."""


class EmptyResultWarning(UserWarning):
    """The record holds (almost) nothing of the target (see :mod:`mdframework.emptiness`)."""


#: Range-time rows a record keeps in memory (``Received.range_time``): every pulse's row up to
#: this many pulses, evenly spaced rows beyond (the map is for display; the slow-time ``signal``
#: keeps every pulse). ``output.MAX_SAVED_RANGE_TIME_ROWS`` bounds the rows saved to a file.
MAX_KEPT_RANGE_TIME_ROWS = 16384


@dataclass(frozen=True)
class RunResult:
    """Everything a run produces. Arrays: ``pulse_times`` (n_pulses,) [s from the first pulse];
    ``gate_range`` (n_pulses,) [m]; ``received.signal`` (n_pulses,) complex [sqrt(W)];
    ``spectrogram_db`` (n_doppler, n_frames) float32 [dB re peak]; ``velocity`` (n_doppler,)
    [m/s]; ``body``: the placed body at the source's own frame times within the record, times
    [s from the first pulse]; ``scatterers``: every pulse's scatterers, only when
    ``processing.keep_scatterers`` (else ``None``: the pipeline streams them block by block);
    ``metadata``: what the run did, saved as ``metadata.json`` (``metadata["scatterers"]``: the
    scatterers' names, in their order in the arrays)."""

    pulse_times: FloatArray
    gate_range: FloatArray
    received: Received
    spectrogram: Spectrogram
    spectrogram_db: NDArray[np.float32]
    velocity: FloatArray
    body: Skeleton
    scatterers: Scatterers | None = None
    metadata: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Stages:
    """The plugin instances of one run; ``effects`` holds only those the scene names."""

    source: MotionSource
    model: ScattererModel
    radar: RadarWaveform
    effects: tuple[Effect, ...] = ()


def build_stages(config: RunConfigBase, registry: Registry | None = None) -> Stages:
    """Instantiate the plugins a config names; each effect checks the radar
    (:meth:`Effect.check_radar`) and the other effects (:meth:`Effect.check_effects`)."""
    reg = registry or default_registry()
    cfg: Any = config

    def make(interface: str, section: Any) -> Any:
        try:
            cls = reg.get(interface, section.kind)
        except KeyError as exc:
            raise SceneError(str(exc.args[0])) from None
        try:
            return cls(section)
        except Exception as exc:  # a bug in the plugin: the CLI's internal error names it
            note = (
                f"in the {interface} plugin {section.kind!r} "
                f"({cls.__module__}.{cls.__qualname__}) while it was built from its config"
            )
            if isinstance(exc, MdfError):  # the plugin refuses the config: the user's
                exc.add_note(note)
            else:  # also a ValueError, which a dataset build would take for its record's
                name_plugin_bug(exc, note)
            raise

    source, model = make("motion", cfg.motion), make("scatterers", cfg.scatterers)
    waveform = make("radar", cfg.radar)
    waveform.seed = cfg.seed  # its own random draws (receiver noise) follow the run's seed
    effects = tuple(make("effects", e) for e in cfg.effects)
    for effect in effects:  # e.g. clutter needs a bandwidth: refused before any pulse
        with blame(effect, "check_radar"):
            effect.check_radar(waveform)
    for effect in effects:  # e.g. an antenna pattern listed before the multipath it must see
        with blame(effect, "check_effects"):
            effect.check_effects(effects)
    return Stages(source, model, waveform, effects)


def effect_generators(seed: int, effects: Sequence[Effect]) -> tuple[np.random.Generator, ...]:
    """Each effect's own random generator, in the order of ``effects``.

    A received-stage effect with ``k`` received-stage effects listed after it draws from stream
    ``k`` of the run's seed (``SeedSequence(seed).spawn(n)[k]``): listing an effect before
    another leaves the other's draws as they were, and a lone effect (the last of its stage)
    draws from stream 0 as every run always has. A scatterer-stage effect draws nothing (it
    must be block-invariant); it gets stream ``(k, 1)``, which no received-stage effect has."""
    streams: list[np.random.Generator] = []
    for i, effect in enumerate(effects):
        after = sum(e.stage == effect.stage for e in effects[i + 1 :])
        key = (after,) if effect.stage == "received" else (after, 1)
        streams.append(np.random.default_rng(np.random.SeedSequence(seed, spawn_key=key)))
    return tuple(streams)


def apply_effects(
    stages: Stages,
    stage: str,
    data: Any,
    context: SceneContext,
    generators: Sequence[np.random.Generator],
    skip: frozenset[int] = frozenset(),
) -> Any:
    """``data`` (a block's ``Scatterers`` or the record's ``Received``) through the effects of
    ``stage`` (``"scatterers"`` or ``"received"``) in the listed order, each with its own
    generator (:func:`effect_generators`), but those of index in ``skip`` (the radar simulated
    them: :func:`hand_to_radar`); an effect's exception is named as its plugin's bug."""
    for i, (effect, rng) in enumerate(zip(stages.effects, generators, strict=True)):
        if effect.stage == stage and i not in skip:
            try:
                out = effect.apply(data, replace(context, rng=rng))
                _check_effect_output(out, data)
            except Exception as exc:  # a bug in the plugin: the CLI's internal error names it
                cls = type(effect)
                name_plugin_bug(
                    exc,
                    f"in the effects plugin {effect.name!r} ({cls.__module__}.{cls.__qualname__})"
                    f" on the {stage!r} stage; check it with mdframework.testing.check_effect",
                )
                raise
            data = out
    return data


def hand_to_radar(
    stages: Stages, context: SceneContext, generators: Sequence[np.random.Generator]
) -> frozenset[int]:
    """Before a record's blocks: give a radar that simulates received-stage effects in its raw
    samples (:attr:`RadarWaveform.takes_receiver_inputs`) what each of them puts there
    (:meth:`Effect.receiver_input`, with the effect's own generator), so that they reach all
    its products; the indices of those effects, which then do not act on the slow-time signal
    again."""
    wf, inputs, handed = stages.radar, [], set()
    for i, (effect, rng) in enumerate(zip(stages.effects, generators, strict=True)):
        if effect.stage != "received":
            continue
        with blame(effect, "receiver_input"):
            got = effect.receiver_input(replace(context, rng=rng))
            if got is None:
                continue
            _check_receiver_input(got)
        inputs.append(got)
        handed.add(i)
    with blame(wf, "set_receiver_inputs"):
        wf.set_receiver_inputs(inputs)
    return frozenset(handed)


def _check_receiver_input(got: Any) -> None:
    """Refuse what an effect's ``receiver_input`` returned when it breaks the contract (the
    radar would fail with it, named as the culprit): another type than :class:`ReceiverInput`,
    a noise power that is not finite and >= 0, static ranges and RCS that are not two (P,)
    arrays of finite values (RCS >= 0)."""
    if not isinstance(got, ReceiverInput):
        raise TypeError(
            f"receiver_input() returned {type(got).__name__} instead of ReceiverInput or None"
        )
    if not (np.isfinite(got.noise_power) and got.noise_power >= 0):
        raise ValueError(f"receiver_input() gave a noise power of {got.noise_power} W")
    ranges, rcs = np.asarray(got.static_ranges), np.asarray(got.static_rcs)
    if ranges.ndim != 1 or rcs.shape != ranges.shape:
        raise ValueError(
            f"receiver_input() gave static ranges of shape {ranges.shape} and RCS of shape "
            f"{rcs.shape}, not (P,) each"
        )
    if not (np.all(np.isfinite(ranges)) and np.all(np.isfinite(rcs)) and np.all(rcs >= 0)):
        raise ValueError("receiver_input() gave static ranges or RCS not finite (RCS >= 0)")


def _check_effect_output(out: Any, data: Scatterers | Received) -> None:
    """Refuse what an effect's ``apply`` returned for ``data`` when it breaks the contract:
    another type, another number of pulses, or values that are not finite (RCS below 0). Any
    ``Scatterers`` answers ``Scatterers``: an effect that adds scatterers (ground images, a
    room) returns the base class for a model's own subclass of it."""
    expected = Scatterers if isinstance(data, Scatterers) else type(data)
    if not isinstance(out, expected):
        raise TypeError(f"apply() returned {type(out).__name__} instead of {expected.__name__}")
    if isinstance(out, Scatterers) and isinstance(data, Scatterers):
        n = data.positions.shape[0]
        if out.positions.shape[0] != n:
            raise ValueError(
                f"apply() returned {out.positions.shape[0]} pulses' scatterers, not {n}"
            )
        rcs = np.asarray(out.rcs)
        if not (np.all(np.isfinite(out.positions)) and np.all(np.isfinite(rcs) & (rcs >= 0))):
            raise ValueError(
                "apply() returned positions that are not finite or RCS not finite and >= 0"
            )
    elif isinstance(out, Received) and isinstance(data, Received):
        shape = np.shape(data.signal)
        if not isinstance(out.signal, np.ndarray) or out.signal.shape != shape:
            raise ValueError(
                f"apply() returned a signal of shape {np.shape(out.signal)} instead of {shape}"
            )
        if not np.all(np.isfinite(out.signal)):
            raise ValueError("apply() returned a signal that is not finite")


def _check_received(out: Any, n_pulses: int) -> None:
    """Refuse what a radar's ``receive`` returned for a block of ``n_pulses`` pulses when it is
    not ``Received`` with a signal of one sample per pulse."""
    if not isinstance(out, Received):
        raise TypeError(f"receive() returned {type(out).__name__} instead of Received")
    if not isinstance(out.signal, np.ndarray) or out.signal.shape != (n_pulses,):
        raise ValueError(
            f"receive() returned a signal of shape {np.shape(out.signal)} for a block of "
            f"{n_pulses} pulses instead of ({n_pulses},)"
        )


def _describe(stages: Stages, stage: str) -> list[dict[str, Any]]:
    """What the effects of one stage did, for the metadata (after the record)."""
    return [
        {"kind": e.name, "stage": stage, **e.describe()} for e in stages.effects if e.stage == stage
    ]


def place_body(body: Skeleton, person: PersonConfig, radar_position: FloatArray) -> Skeleton:
    """Put a canonical body into the scene as ``person`` says (the whole recording; see
    :func:`body_placement`)."""
    return placed(body, body_placement(body, person, radar_position))


def placed(body: Skeleton, where: scene.Placement | None) -> Skeleton:
    """``body``'s frames placed by ``where`` (any frames of the recording it was found
    from); ``body`` itself when ``where`` is None (used as given)."""
    if where is None:
        return body
    return body.with_positions(where.apply(body.time, body.positions))


def body_placement(
    body: Skeleton, person: PersonConfig, radar_position: FloatArray, source: str | None = None
) -> scene.Placement:
    """How ``person`` places a canonical body (the whole recording) in the scene: apply it to
    any of its frames (:meth:`physics.scene.Placement.apply`). The placement starts at the
    first frame whose hip centre is tracked; a body tracked in no frame is refused, naming
    ``source`` (the motion's file) where given."""
    base = body.joint("base")
    if not np.any(np.all(np.isfinite(base), axis=1)):
        message = "the hip centre (base) is tracked in no frame: no body to place"
        raise DataFileError(source, message) if source else SceneError(message)
    try:
        heading_now = scene.body_heading(
            base, body.joint("l_hip"), body.joint("r_hip"), rule=person.facing
        )
    except ValueError as exc:
        raise SceneError(f"scene.person.facing: {exc}") from None
    try:
        heading = scene.scene_heading_deg(
            np.asarray(person.position, dtype=np.float64),
            radar_position,
            aspect_deg=person.aspect_deg,
            heading_deg=person.heading_deg,
        )
    except ValueError as exc:
        raise SceneError(f"scene.person.aspect_deg: {exc}") from None
    return scene.placement(
        body.time,
        base,
        heading_now=heading_now,
        heading=float(np.deg2rad(heading)),
        position=np.asarray(person.position),
        mode=person.motion,
        speed=person.speed or 0.0,
    )


def _is_default_placement(person: PersonConfig) -> bool:
    return person == PersonConfig()


def simulate(
    config: RunConfigBase, registry: Registry | None = None, progress: Progress = QUIET
) -> RunResult:
    """Run one config end to end; ``progress`` reports the steps that take more than a second
    (:class:`~mdframework.progress.Progress`; silent by default). The metadata's
    ``motion.fingerprint`` is the loaded motion's digest
    (:func:`~mdframework.fingerprint.motion_fingerprint`)."""
    stages = build_stages(config, registry)
    t0 = time.perf_counter()
    with progress.step(f"loading the motion ({stages.source.name})"):
        motion = load_motion(stages.source)
    timings = {"load": time.perf_counter() - t0}
    result = simulate_motion(config, stages, motion, timings, progress)
    result.metadata["motion"]["fingerprint"] = motion_fingerprint(motion)
    return result


def load_motion(source: MotionSource) -> Motion:
    """``source.load()``, with a plugin's own check of its input (``ValueError``) reported as
    a one-line user error naming the source, followed by the motion sanity checks
    (:func:`mdframework.sanity.check_motion`, with the source config's ``sanity`` section)."""
    try:
        with blame(source, "load"):
            motion = source.load()
    except ValueError as exc:
        raise SceneError(f"motion {source.name!r}: {exc}") from None
    return sanity.check_motion(motion, getattr(source.config, "sanity", SanityConfig()))


def spectrogram_geometry(
    wf: RadarWaveform, n_pulses: int, proc: ProcessingConfig
) -> SpectrogramGeometry:
    """The geometry of the spectrogram the radar ``wf`` makes of ``n_pulses`` pulses
    (:meth:`RadarWaveform.spectrogram_geometry`); a record too short for it is a
    :class:`SceneError` naming ``processing.window_length``, and one of more than
    ``limits.MAX_SPECTROGRAM_CELLS`` values one naming the fields that set its size
    (:meth:`RadarWaveform.smaller_spectrogram`: ``processing.hop`` for an STFT). ``mdf check``
    reports both."""
    try:
        with blame(wf, "spectrogram_geometry"):
            geometry = wf.spectrogram_geometry(n_pulses, proc)
    except RecordTooShortError as exc:
        raise SceneError(f"processing.window_length: {exc}") from None
    item_bytes = 4 if proc.precision == "float32" else 8
    with blame(wf, "smaller_spectrogram"):  # (a wrong return fails in the check: the plugin's)
        fields = wf.smaller_spectrogram(proc)
        limits.check_spectrogram_cells(geometry.nfft, geometry.n_frames, item_bytes, fields)
    return geometry


def check_echo_power(wf: RadarWaveform) -> None:
    """Refuse a radar whose range equation makes echoes too strong or too weak for the
    pipeline's float32 arithmetic (:func:`limits.check_echo_power`: ``radar.gain_dbi`` of 300 dB,
    or 400 dB of losses, say), before any pulse; ``mdf check`` refuses it too."""
    cfg = getattr(wf, "config", None)
    if isinstance(cfg, RadarPowerConfig) and cfg.amplitude == "range_equation":
        wavelength = radar.wavelength(wf.carrier_frequency)
        power = float(cfg.amplitudes(np.ones(1), np.ones(1), wavelength)[0]) ** 2
        # the setting most to blame: the largest term of the range equation in dB (the
        # smallest for too weak an echo)
        terms = {
            "radar.gain_dbi": 2.0 * cfg.gain_dbi,
            "radar.transmit_power": 10.0 * float(np.log10(cfg.transmit_power)),
            "radar.system_loss_db": -cfg.system_loss_db,
            "radar.atmospheric_loss_db": -cfg.atmospheric_loss_db,
        }
        pick = max if power > limits.MAX_ECHO_POWER_W else min
        limits.check_echo_power(power, pick(terms, key=terms.__getitem__))


def processing_stft(
    signal: ComplexArray, sample_rate: float, proc: ProcessingConfig
) -> Spectrogram:
    """The STFT of ``signal`` (n,) sampled at ``sample_rate`` [Hz] with the ``processing``
    window, window length, hop, FFT size and precision (:func:`physics.spectrogram.spectrogram`;
    :class:`RecordTooShortError` for a record shorter than the window)."""
    return spectrogram(
        signal,
        sample_rate,
        window=proc.window,
        window_length=proc.window_length,
        hop=proc.hop,
        nfft=proc.nfft,
        precision=proc.precision,
    )


def record_spectrogram(
    wf: RadarWaveform, signal: ComplexArray, times: FloatArray, proc: ProcessingConfig
) -> Spectrogram:
    """The record's spectrogram: the radar's own (:meth:`RadarWaveform.spectrogram`, for a slow
    time that is not uniform) or the STFT of ``signal`` (n_pulses,) at its PRF with the
    ``processing`` window; ``times`` (n_pulses,) [s]. Its power is
    :func:`spectrogram_geometry`'s shape (the radar contract checks this)."""
    try:
        with blame(wf, "spectrogram"):
            spec = wf.spectrogram(signal, times, proc)  # a waveform's own slow time (FMCW)
        if spec is None:
            spec = processing_stft(signal, wf.prf, proc)
    except RecordTooShortError as exc:
        raise SceneError(f"processing.window_length: {exc}") from None
    return spec


def simulate_motion(
    config: RunConfigBase,
    stages: Stages,
    motion: Motion,
    timings: dict[str, float] | None = None,
    progress: Progress = QUIET,
) -> RunResult:
    """Run the stages after the motion source on an already loaded motion.

    The body is conditioned and placed over the whole recording (facing, drift and outlier
    statistics need it); only the record's window (plus a margin of frames) is resampled; then
    pulses stream through scatterers, effects, ranges and the receive chain in blocks of
    ``processing.block_pulses``, and the slow-time signal goes to the spectrogram. ``progress``
    reports the steps (placing the body, the pulses, the spectrogram).
    """
    try:
        return _simulate_motion(
            config, stages, motion, {} if timings is None else timings, progress
        )
    finally:
        progress.end()


def _simulate_motion(
    config: RunConfigBase,
    stages: Stages,
    motion: Motion,
    timings: dict[str, float],
    progress: Progress,
) -> RunResult:
    cfg: Any = config
    sc, proc, wf, model = config.scene, config.processing, stages.radar, stages.model
    radar_pos = np.asarray(sc.radar_position, dtype=np.float64)
    lam = radar.wavelength(wf.carrier_frequency)

    clock = time.perf_counter()
    progress.stage("conditioning and placing the body")
    body, conditioning_report, placement, where = prepare_body(config, stages, motion, radar_pos)
    t_start, t_end = record_window(body, cfg.motion.start, cfg.motion.duration)
    limits.check_pulses(
        t_end - t_start,
        wf.pulse_rate,
        body.n_joints,
        "motion.duration",
        keep_scatterers=proc.keep_scatterers,
    )
    t = record_pulses(wf, t_start, t_end)
    spectrogram_geometry(wf, t.shape[0], proc)  # a record too short: refused before any pulse
    check_echo_power(wf)
    frames = interpolation.window_frames(body.time, float(t[0]), float(t[-1]))
    near = body.select_frames(frames)
    refuse_untracked(near, float(t[0]), float(t[-1]), float(body.time[0]))
    exact_linear = motion.linear_tracks and body is motion.skeleton
    method = "linear" if exact_linear else proc.interpolation
    # The placement (where) comes from the whole recording and applies to the window alone.
    # Interpolants linear in their data are built unplaced (shared by the records of one
    # window) and placed through their coefficients.
    if where is not None and method in interpolation.LINEAR_IN_DATA:
        resample = _window_resampler(body, near, frames, method).mapped(where.apply)
        near = placed(near, where)
    else:
        near = placed(near, where)
        resample = interpolation.TrackResampler(near.time, near.positions, near.valid, method)
    record_body = near.select_frames(frames_inside(near.time, t_start, t_end))
    farthest = start_record(stages, record_body, t, radar_pos, sc.gate)
    timings["prepare"] = time.perf_counter() - clock

    n = t.shape[0]
    generators = effect_generators(config.seed, stages.effects)
    # the contexts' generator: apply_effects gives each effect its own in its place
    rng = generators[0] if generators else np.random.default_rng(config.seed)
    stream = _Stream(
        n, proc.keep_scatterers, proc.aliasing, wf, sc.min_range, t, float(t[0] - body.time[0])
    )
    losses = emptiness.Losses()
    blocks = _blocks(n, proc.block_pulses, wf.block_multiple)
    early_effects = any(e.stage == "scatterers" for e in stages.effects)
    handed: frozenset[int] = frozenset()
    if wf.takes_receiver_inputs:  # the record's gate from the body's frames around it
        span = np.interp(t, near.time, gate_ranges(sc.gate, near, radar_pos))
        context = SceneContext(radar_pos, wf.prf, wf.carrier_frequency, t, span, None, wf, rng)
        handed = hand_to_radar(stages, context, generators)
    for lo, hi in progress.counted(blocks, n, "simulating the pulses", "pulse"):
        clock = time.perf_counter()
        tb = t[lo:hi]
        at_pulses = Skeleton.resampled(tb, resample(tb), body.joint_names)
        timings["resample"] = timings.get("resample", 0.0) + time.perf_counter() - clock

        clock = time.perf_counter()
        with blame(model, "scatterers"):
            scat = model.scatterers(motion, at_pulses, radar_pos, lam)
            rcs_model = scat.rcs
        gate = gate_ranges(sc.gate, at_pulses, radar_pos)
        context = SceneContext(
            radar_pos, wf.prf, wf.carrier_frequency, tb, gate, at_pulses, wf, rng, lo
        )
        if early_effects:  # the body itself within scene.min_range: refused before any effect
            stream.check_near(lo, scat, scat.ranges(radar_pos))
        modelled = scat
        scat = apply_effects(stages, "scatterers", scat, context, generators)
        ranges = scat.ranges(radar_pos)
        stream.check(lo, scat, ranges)
        s = slice(None, None, emptiness.SAMPLE_EVERY)
        # the body's own returns count, not those an effect adds (static reflectors, multipath
        # images): a reflector away from the gate is no target lost
        own = ranges if scat.rcs.shape == rcs_model.shape else modelled.ranges(radar_pos)
        with blame(wf, "gate_gain"):
            gain = wf.gate_gain(own[s], gate[s])
        losses += emptiness.count_losses(own[s], gate[s], rcs_model[s], scat.rcs[s], gain)
        timings["scatterers"] = timings.get("scatterers", 0.0) + time.perf_counter() - clock

        clock = time.perf_counter()
        with blame(wf, "receive"):
            received_block = wf.receive(PulseBlock(lo, tb, scat, ranges, gate, radar_pos))
            _check_received(received_block, hi - lo)
        stream.add(lo, gate, scat, received_block)
        timings["receive"] = timings.get("receive", 0.0) + time.perf_counter() - clock

    clock = time.perf_counter()
    late = [e.name for e in stages.effects if e.stage == "received"]
    if late:
        progress.stage(f"effects on the received signal ({', '.join(late)})")
    stream.warn_aliasing()
    received = stream.received()
    if received.products:
        received = replace(received, products={**received.products, **wf.product_axes()})
    # the target's echo before the received-stage effects (with the noise and clutter of a
    # radar that puts them in its raw samples: its own receiver noise, those handed to it)
    echo = received.signal.copy()
    context = SceneContext(
        radar_pos, wf.prf, wf.carrier_frequency, t, stream.gate, None, wf, rng, echo=echo
    )
    received = apply_effects(stages, "received", received, context, generators, handed)
    folds = _folding_range(wf, farthest)
    _check_empty(echo, losses, proc, fixed_gate=sc.gate != "track", max_range=folds)
    effects_ran = _describe(stages, "scatterers") + _describe(stages, "received")
    timings["received_effects"] = time.perf_counter() - clock

    clock = time.perf_counter()
    progress.stage("spectrogram")
    spec = record_spectrogram(wf, received.signal, t, proc)
    spec_db = power_to_db(spec.power, proc.floor_db, dtype=np.float32)
    velocity = radar.doppler_to_velocity(spec.doppler, wf.carrier_frequency)
    timings["spectrogram"] = time.perf_counter() - clock

    metadata = {
        "motion": dict(motion.metadata),
        "placement": placement,
        "conditioning": conditioning_report,
        "scatterers": list(stream.names),
        "n_pulses": int(n),
        "prf_hz": wf.prf,
        "carrier_frequency_hz": wf.carrier_frequency,
        "wavelength_m": lam,
        "max_unambiguous_velocity_mps": stream.v_max,
        "max_radial_speed_mps": stream.speed,
        "radar_position_m": list(sc.radar_position),
        "record_start_s": t_start - float(body.time[0]),  # as motion.start counts
        "effects": effects_ran,
        "seed": config.seed,
        "timings_s": timings,
    }
    shifted = Skeleton(
        record_body.time - t[0], record_body.positions, record_body.joint_names, record_body.valid
    )
    return RunResult(
        t - t[0],
        stream.gate,
        received,
        spec,
        spec_db,
        velocity,
        shifted,
        stream.scatterers(),
        metadata,
    )


def start_record(
    stages: Stages,
    record_body: Skeleton,
    t: FloatArray,
    radar_pos: FloatArray,
    gate: float | str = "track",
) -> float | None:
    """Tell the scatterer model, the radar and the effects the record about to be simulated:
    the placed body at its frame times within the record, the pulse times ``t`` (n_pulses,) [s]
    and the radar position (3,) [m]. The radar refuses here what it cannot simulate (an FMCW
    scatterer beyond its maximum range, range-Doppler maps over the product limit). A fixed
    ``gate`` [m] (``scene.gate``) beyond the radar's unambiguous range is warned about.
    Returns that range [m] (None: the radar has none)."""
    with blame(stages.model, "start_record"):
        stages.model.start_record(record_body)
    with blame(stages.radar, "start_record"):
        stages.radar.start_record(t, _range_span(record_body, radar_pos))
    with blame(stages.radar, "unambiguous_range"):
        farthest = stages.radar.unambiguous_range()
    if not isinstance(gate, str) and farthest is not None and gate >= farthest:
        warnings.warn(
            f"scene.gate: the fixed range gate at {gate:g} m is beyond the radar's unambiguous "
            f"range {farthest:.4g} m (an FMCW radar's maximum range, a pulse radar's "
            "c / (2 prf)), which no gate of the real sensor reaches: set a gate within it, or "
            "scene.gate = 'track'",
            UserWarning,
            stacklevel=2,
        )
    for effect in stages.effects:
        with blame(effect, "start_record"):
            effect.start_record(record_body, radar_pos)
    return farthest


def _folding_range(wf: RadarWaveform, farthest: float | None) -> float | None:
    """``farthest``, the radar's unambiguous range [m], where its range gate folds ranges at it
    as an FMCW radar's cyclic range FFT does (a scatterer that far beyond the gate reaches the
    gate), else None: the LFM radar's simulation gates every echo at its true range, so a body
    beyond ``c / (2 prf)`` loses nothing to it and the empty-result advice must not blame it."""
    if farthest is None:
        return None
    gate = np.array([0.5 * farthest])
    with blame(wf, "gate_gain"):
        gain = wf.gate_gain(gate[:, None] + farthest, gate)
        folded = gain is not None and float(np.asarray(gain).ravel()[0]) > emptiness.LOST_GAIN
    return farthest if folded else None


def _check_empty(
    echo: NDArray[np.complex128],
    losses: emptiness.Losses,
    proc: Any,
    *,
    fixed_gate: bool,
    max_range: float | None,
) -> None:
    """Warn (or stop, with ``processing.empty = "error"``) when the record is empty;
    ``max_range``: the range [m] at which the radar's gate folds ranges (:func:`_folding_range`),
    or None."""
    why = emptiness.empty_result(
        echo,
        losses,
        max_lost_fraction=proc.max_lost_fraction,
        fixed_gate=fixed_gate,
        max_range=max_range,
    )
    if why is None:
        return
    if proc.empty == "error":
        raise SceneError(f"{why} (processing.empty = 'error')")
    warnings.warn(
        f"{why} (processing.empty = 'error' makes this an error)", EmptyResultWarning, stacklevel=4
    )


def prepare_body(
    config: RunConfigBase, stages: Stages, motion: Motion, radar_pos: FloatArray
) -> tuple[Skeleton, dict[str, Any], dict[str, Any], scene.Placement | None]:
    """The conditioned body (whole recording, not yet placed), the conditioning report, the
    placement recorded in the metadata, and the placement to apply to the body's frames (None:
    the body is used as given)."""
    sc = config.scene
    if stages.model.needs_canonical and motion.canonical_map is None:
        raise SceneError(
            f"scatterers.kind: the {stages.model.name!r} model needs a human body, but this "
            f"motion ({motion.metadata.get('source', 'unknown')}) has no canonical joints"
        )
    body = motion.canonical() if stages.model.needs_canonical else motion.skeleton
    body, conditioning_report = condition_body(body, config.conditioning)
    if stages.model.needs_canonical:
        where = body_placement(body, sc.person, radar_pos, sanity.motion_file(motion))
        return body, conditioning_report, sc.person.model_dump(), where
    if not _is_default_placement(sc.person):
        raise SceneError(
            "scene.person: placement applies to human bodies only; this motion "
            f"({motion.metadata.get('source', 'unknown')}) is used as recorded"
        )
    return body, conditioning_report, {"motion": "as given"}, None


#: The last window resampler built (one): the records of one window seen from several aspects
#: (a dataset's variations, built one after another) share its interpolants, placed for each.
_LAST_WINDOW: list[tuple[weakref.ref[Skeleton], int, int, str, interpolation.TrackResampler]] = []


def _window_resampler(
    body: Skeleton, near: Skeleton, frames: slice, method: interpolation.Method
) -> interpolation.TrackResampler:
    """The resampler of the frames ``frames`` of ``body`` (``near``, not placed), kept for the
    next record of the same window of the same body (same object)."""
    key = (int(frames.start), int(frames.stop), method)
    if _LAST_WINDOW:
        ref, start, stop, last_method, resampler = _LAST_WINDOW[0]
        if ref() is body and (start, stop, last_method) == key:
            return resampler
    resampler = interpolation.TrackResampler(near.time, near.positions, near.valid, method)
    _LAST_WINDOW[:] = [(weakref.ref(body, _forget_window), *key, resampler)]
    return resampler


def _forget_window(dead: weakref.ref[Skeleton]) -> None:
    """Drop the kept resampler once its body is gone (no record can share it any more): a
    long record's interpolants are not held after its run, while its files are written."""
    if _LAST_WINDOW and _LAST_WINDOW[0][0] is dead:
        _LAST_WINDOW.clear()


def _blocks(n: int, size: int, multiple: int) -> list[tuple[int, int]]:
    """Consecutive ``(lo, hi)`` pulse ranges of about ``size`` pulses, multiples of
    ``multiple`` (the last block may be shorter)."""
    step = max(multiple, (size // multiple) * multiple)
    return [(lo, min(lo + step, n)) for lo in range(0, n, step)]


def frames_inside(time_s: FloatArray, t_first: float, t_last: float) -> slice:
    """The frames with ``t_first <= time <= t_last`` (at least the nearest one)."""
    lo = int(np.searchsorted(time_s, t_first - 1e-12, side="left"))
    hi = int(np.searchsorted(time_s, t_last + 1e-12, side="right"))
    return slice(min(lo, time_s.shape[0] - 1), max(hi, lo + 1))


def refuse_untracked(near: Skeleton, t_first: float, t_last: float, origin: float) -> None:
    """A :class:`SceneError` naming the first joint whose valid frames in ``near`` (the frames
    the run interpolates, :func:`~mdframework.physics.interpolation.window_frames`) do not span
    the pulses from ``t_first`` to ``t_last`` [s]: interpolation never extrapolates (it was the
    interpolant's ValueError, an internal error of ``mdf run``). Times are said from the
    recording's first frame at ``origin`` [s], as ``motion.start`` counts them."""
    for j, name in enumerate(near.joint_names):
        seen = near.time[near.valid[:, j]]
        if seen.size < 2:
            where = "is not tracked near the record"
        elif seen[0] > t_first + 1e-12:
            where = f"is tracked only from {seen[0] - origin:.3f} s"
        elif seen[-1] < t_last - 1e-12:
            where = f"is tracked only until {seen[-1] - origin:.3f} s"
        else:
            continue
        raise SceneError(
            f"motion: joint {name!r} {where} of the recording, but the record runs from "
            f"{t_first - origin:.3f} to {t_last - origin:.3f} s, and interpolation never "
            "extrapolates: choose a record (motion.start, motion.duration) where it is tracked"
        )


def _range_span(body: Skeleton, radar_pos: FloatArray) -> tuple[float, float]:
    """Smallest and largest distance [m] of the record's valid joints to the radar."""
    d = radar.distances(body.positions, radar_pos)[body.valid]
    if d.size == 0 or not np.all(np.isfinite(d)):
        raise SceneError("the record has no valid, finite joint positions")
    return float(d.min()), float(d.max())


class _Stream:
    """Collects a record's blocks: the slow-time signal, gate, range-time rows and products
    (arrays of n_pulses or fewer rows), and checks ranges and radial speeds as blocks pass."""

    def __init__(
        self,
        n: int,
        keep: bool,
        aliasing: str,
        wf: RadarWaveform,
        min_range: float,
        t: FloatArray,
        start: float = 0.0,
    ) -> None:
        self.n, self.keep, self.aliasing, self.min_range, self.t = n, keep, aliasing, min_range, t
        self.start = start  # where the record starts in the recording [s]: named in refusals
        self.signal = np.empty(n, dtype=np.complex128)
        self.gate = np.empty(n, dtype=np.float64)
        self.v_max = wf.max_unambiguous_velocity
        self.prf = wf.prf
        self.faster_sampling = wf.faster_sampling
        self.speed = 0.0
        self.names: tuple[str, ...] = ()
        self._last: tuple[float, FloatArray] | None = None
        self._blocks: list[Scatterers] = []
        self._rt_step = max(1, -(-n // MAX_KEPT_RANGE_TIME_ROWS))
        self._rt: list[NDArray[np.complex128]] = []
        self._rt_axis: FloatArray | None = None
        self._products: dict[str, list[NDArray[Any]]] = {}

    def check_near(self, lo: int, scat: Scatterers, ranges: FloatArray) -> None:
        """Finite ranges (n_block, n_scatterers) [m] above ``scene.min_range``."""
        nearest = float(ranges.min())
        if not (np.isfinite(nearest) and np.isfinite(ranges.max())):
            raise SceneError("a scatterer position is not finite")
        if nearest < self.min_range:
            t = self.t[lo : lo + ranges.shape[0]] - self.t[0]
            refuse_near(ranges, scat.names, t, self.min_range, "scatterer", self.start)

    def check(self, lo: int, scat: Scatterers, ranges: FloatArray) -> None:
        """Finite ranges above ``scene.min_range``; the fastest radial speed so far."""
        self.check_near(lo, scat, ranges)
        tb = self.t[lo : lo + ranges.shape[0]]
        if ranges.shape[0] > 1:
            self.speed = max(self.speed, radar.max_range_rate(ranges, tb))
        if self._last is not None and self._last[1].shape == ranges[0].shape:
            jump = float(np.max(np.abs(ranges[0] - self._last[1])))
            self.speed = max(self.speed, jump / (float(tb[0]) - self._last[0]))
        self._last = (float(tb[-1]), ranges[-1].copy())
        if self.speed > self.v_max and self.aliasing == "error":
            raise SceneError(self._aliasing_message())

    def _aliasing_message(self) -> str:
        return (
            f"the fastest scatterer moves at {self.speed:.2f} m/s radially, beyond the "
            f"unambiguous {self.v_max:.2f} m/s of the {self.prf:g} Hz slow-time rate: its "
            f"Doppler aliases; {self.faster_sampling(self.prf * self.speed / self.v_max)} "
            "(processing.aliasing = 'error' stops such runs)"
        )

    def warn_aliasing(self) -> None:
        """Warn once when the record's fastest scatterer aliases."""
        if self.speed > self.v_max:
            warnings.warn(self._aliasing_message(), AliasingWarning, stacklevel=4)

    def add(self, lo: int, gate: FloatArray, scat: Scatterers, rec: Received) -> None:
        """Store one block's received data."""
        hi = lo + gate.shape[0]
        self.signal[lo:hi] = rec.signal
        self.gate[lo:hi] = gate
        self.names = scat.names
        if self.keep:
            self._blocks.append(scat)
        if rec.range_time is not None:
            first = (-lo) % self._rt_step
            # a copy: a view would keep the whole block's map alive
            self._rt.append(np.array(rec.range_time[first :: self._rt_step]))
            self._rt_axis = rec.range_axis
        for key, value in rec.products.items():
            self._products.setdefault(key, []).append(np.asarray(value))

    def received(self) -> Received:
        """The whole record's received data (each block's arrays released as they are joined;
        called once per record: it empties the stream's lists)."""
        products = {k: _join(self._products.pop(k)) for k in list(self._products)}
        if not self._rt:
            return Received(self.signal, products=products)
        rows = np.arange(0, self.n, self._rt_step, dtype=np.int64)
        range_time, self._rt = _join(self._rt), []
        return Received(
            self.signal, range_time, self._rt_axis, products, rows if self._rt_step > 1 else None
        )

    def scatterers(self) -> Scatterers | None:
        """Every pulse's scatterers (``processing.keep_scatterers``), else ``None``."""
        if not self._blocks:
            return None
        first = self._blocks[0]
        cat = [np.concatenate([getattr(b, f) for b in self._blocks]) for f in ("positions", "rcs")]
        axes = None
        if first.axes is not None:
            axes = np.concatenate([b.axes for b in self._blocks if b.axes is not None])
        centres = None
        if first.centres is not None:
            centres = np.concatenate([b.centres for b in self._blocks if b.centres is not None])
        return Scatterers(
            cat[0],
            cat[1],
            first.names,
            first.semi_axes,
            axes,
            centres=centres,
            specular=first.specular,
        )


def refuse_near(
    ranges: FloatArray,
    names: Sequence[str],
    time: FloatArray,
    min_range: float,
    what: str,
    start: float = 0.0,
) -> None:
    """A :class:`SceneError` naming the ``what`` (scatterer, joint) nearest the radar when it
    comes within ``min_range`` [m]: ``ranges`` (n, len(names)) [m] (inf where not seen) at
    ``time`` (n,) [s from the record's start]; ``start`` [s]: where the record starts in the
    recording (as ``motion.start`` counts), named too when the record does not start at its
    first frame."""
    if ranges.size == 0:
        return
    k, j = (int(i) for i in np.unravel_index(int(np.argmin(ranges)), ranges.shape))
    if ranges[k, j] < min_range:
        when = f"t = {time[k]:.3f} s"
        if abs(start) > 5e-4:  # the record starts after the recording's first frame
            when += f" into the record, {time[k] + start:.3f} s into the recording"
        raise SceneError(
            f"{what} {names[j]!r} comes within {ranges[k, j]:.3g} m of the radar at {when} "
            f"(scene.min_range = {min_range:g} m): the range equation and far-field RCS do not "
            "hold there"
        )


def _join(blocks: list[NDArray[Any]]) -> NDArray[Any]:
    """``np.concatenate(blocks)`` along the first axis, emptying ``blocks`` as each is copied
    (each block is released once it is in the result, not after the whole join)."""
    if len(blocks) == 1:
        return blocks.pop()
    first = blocks[0]
    if any(b.shape[1:] != first.shape[1:] for b in blocks):
        raise ValueError(f"blocks of different shapes: {sorted({b.shape[1:] for b in blocks})}")
    out = np.empty(
        (sum(b.shape[0] for b in blocks), *first.shape[1:]), dtype=np.result_type(*blocks)
    )
    pos = 0
    blocks.reverse()  # pop from the end, in order
    while blocks:
        block = blocks.pop()
        out[pos : pos + block.shape[0]] = block
        pos += block.shape[0]
    return out


def gate_ranges(gate: str | float, at_pulses: Skeleton, radar_pos: FloatArray) -> FloatArray:
    """Range gate per pulse [m]: tracking the hip centre (or the first joint), or fixed."""
    if gate == "track":
        ref = at_pulses.index("base") if "base" in at_pulses.joint_names else 0
        return radar.distances(at_pulses.positions[:, ref, :], radar_pos)
    return np.full(at_pulses.time.shape, float(gate))


def record_pulses(wf: RadarWaveform, t_start: float, t_end: float) -> FloatArray:
    """The radar's pulse times (n_pulses,) [s] of the record from ``t_start`` to ``t_end`` [s];
    a :class:`SceneError` naming ``motion.duration`` and the shortest record the radar can
    sample when there is none (a record shorter than one FMCW frame's chirps)."""
    with blame(wf, "pulse_times"):
        t = np.asarray(wf.pulse_times(t_start, t_end), dtype=np.float64)
    if t.size == 0:
        kind = getattr(wf, "name", "radar")
        raise SceneError(
            f"motion.duration: the {(t_end - t_start) * 1e3:.3f} ms record holds no pulse of "
            f"the {kind} radar, whose pulses need a record of at least "
            f"{wf.shortest_record * 1e3:.3f} ms: lengthen motion.duration"
        )
    return t


def record_window(body: Skeleton, start: float, duration: float | None) -> tuple[float, float]:
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


def condition_body(body: Skeleton, cfg: ConditioningConfig) -> tuple[Skeleton, dict[str, Any]]:
    """Skeleton conditioning when enabled (:func:`conditioning.condition`): the body and the
    conditioning report; a body it cannot condition is a :class:`SceneError`."""
    if not cfg.enabled:
        return body, {"enabled": False}
    try:
        return conditioning.condition(body, cfg)
    except ValueError as exc:
        raise SceneError(f"conditioning: {exc}") from None
