"""What a run config would do, without running it (``mdf check CONFIG``).

:func:`plan_run` validates the config, instantiates its plugins, loads the motion (reading the
input is part of checking it) and places the body, then reports the record, the spectrogram
geometry, the Doppler and velocity resolution, the unambiguous velocity, the aliasing risk and an
estimate of the memory the run needs. No pulses are simulated. It refuses what the run would
refuse before its first pulse, and a joint nearer the radar than ``scene.min_range``; what the
run finds only in the pulses (an empty range gate, an effect's own checks) it cannot see.

The memory estimate counts the scatterers a run's pulses get: the scatterer model's and those
the scatterer-stage effects add (``static_scene``'s reflectors, ``multipath``'s bounced paths),
found by passing the record's first two pulse times through the model and those effects (no
radar, no received signal), and what the radar says it holds beside them
(:meth:`~mdframework.interfaces.RadarWaveform.working_memory`: the raw path's fast-time arrays,
an FMCW radar's kept range-Doppler maps).

The aliasing risk is judged from the radial speed of the body's joints on the tracks the run
resamples (``processing.interpolation``, whose cubic spline overshoots the frames' differences:
10.61 against 10.16 m/s on CMU 09_06), at every pulse or 16 samples per motion frame, and at the
motion's own frame times: body-part scatterers sit on the segments between joints, so they move
no faster than the fastest joint.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np

from . import limits
from .errors import MdfError
from .interfaces import Motion, SceneContext
from .limits import SCATTERER_PULSE_BYTES
from .physics import interpolation, radar
from .pipeline import (
    Stages,
    apply_effects,
    build_stages,
    check_echo_power,
    effect_generators,
    frames_inside,
    gate_ranges,
    load_motion,
    placed,
    prepare_body,
    record_pulses,
    record_window,
    refuse_near,
    refuse_untracked,
    spectrogram_geometry,
    start_record,
)
from .plugins import Registry, blame, default_registry
from .settings import RunConfigBase
from .skeleton import Skeleton

MIB = 1024.0**2


@dataclass(frozen=True)
class RunPlan:
    """What a run would do. Units are in the field names."""

    plugins: dict[str, str]  # section -> "kind (provider)"
    effects: list[str]
    record_start_s: float
    record_length_s: float
    n_pulses: int
    prf_hz: float  # the slow-time sample rate: a PRF, a CW I/Q rate, an FMCW loop rate
    pulse_rate_hz: float  # pulses (FMCW chirps) per second of a record, gaps included
    pulsed: bool  # the radar's config has a ``prf``: its slow-time samples are its pulses
    carrier_frequency_hz: float
    wavelength_m: float
    n_joints: int
    n_scatterers: int  # per pulse, with those the scatterer-stage effects add
    window_pulses: int  # slow-time samples per spectrum
    hop_pulses: float  # slow-time samples from one spectrum to the next
    nfft: int
    n_frames: int
    spectrum_rate_hz: float  # rate of the slow-time samples the spectra are taken of
    doppler_bin_hz: float
    velocity_bin_mps: float
    window_resolution_hz: float
    window_resolution_mps: float
    max_unambiguous_velocity_mps: float
    max_joint_radial_speed_mps: float
    aliasing: bool
    prf_needed_hz: float
    #: what to change in the radar's config to reach ``prf_needed_hz``
    #: (:meth:`RadarWaveform.faster_sampling`)
    faster_sampling: str
    memory_mib: float
    memory_terms_mib: dict[str, float] = field(default_factory=dict)
    #: ``c / (2 B)`` and the largest unambiguous range (the LFM radar's ``c / (2 prf)``, the
    #: FMCW radar's maximum range); None for a radar without range (CW) or that gives none
    range_resolution_m: float | None = None
    max_range_m: float | None = None

    def as_dict(self) -> dict[str, Any]:
        """JSON-serialisable view."""
        return asdict(self)


def _provider(reg: Registry, interface: str, kind: str) -> str:
    info = reg.plugins[interface].get(kind)
    return f"{kind} ({info.provider})" if info is not None else kind


def max_joint_radial_speed(
    time: np.ndarray, positions: np.ndarray, valid: np.ndarray, radar_position: np.ndarray
) -> float:
    """Largest |d range / dt| [m/s] of any joint between consecutive frames where it is valid in
    both. ``time`` (n_frames,) [s], ``positions`` (n_frames, n_joints, 3) [m], ``valid``
    (n_frames, n_joints) bool, ``radar_position`` (3,) [m]."""
    if time.shape[0] < 2:
        return 0.0
    ranges = np.linalg.norm(positions - radar_position, axis=2)
    rate = np.abs(np.diff(ranges, axis=0)) / np.diff(time)[:, None]
    both = valid[1:] & valid[:-1]
    return float(np.max(rate[both], initial=0.0))


#: Interpolated samples per motion frame at which ``mdf check`` judges the radial speeds.
SPEED_SAMPLES_PER_FRAME = 16


def interpolated_radial_speed(
    body: Skeleton, t: np.ndarray, method: interpolation.Method, radar_position: np.ndarray
) -> float:
    """Largest |d range / dt| [m/s] of any joint on the tracks a run resamples at its pulse
    times ``t`` (n_pulses,) [s] (``method``: ``processing.interpolation``), taken at every
    pulse or, when the pulses are denser, at :data:`SPEED_SAMPLES_PER_FRAME` per motion frame,
    a block at a time. ``body``: the placed body [m]; ``radar_position`` (3,) [m]."""
    frames = interpolation.window_frames(body.time, float(t[0]), float(t[-1]))
    near = body.select_frames(frames)
    refuse_untracked(near, float(t[0]), float(t[-1]), float(body.time[0]))
    resample = interpolation.TrackResampler(near.time, near.positions, near.valid, method)
    n_frames = max(int(np.count_nonzero((near.time >= t[0]) & (near.time <= t[-1]))), 1)
    step = max(1, t.shape[0] // (SPEED_SAMPLES_PER_FRAME * n_frames))
    ts = np.append(t[::step], t[-1]) if (t.shape[0] - 1) % step else t[::step]
    speed, block = 0.0, 1 << 16
    for lo in range(0, ts.shape[0] - 1, block):
        tb = ts[lo : lo + block + 1]  # one sample of overlap: every difference is seen
        ranges = radar.distances(resample(tb), radar_position)
        speed = max(speed, float(np.max(np.abs(np.diff(ranges, axis=0)) / np.diff(tb)[:, None])))
    return speed


def memory_estimate(
    n_pulses: int,
    n_scatterers: int,
    n_doppler: int,
    n_frames: int,
    block_pulses: int,
    keep_scatterers: bool = False,
    stft_bytes: int = 4,
    motion_bytes: int = 0,
) -> dict[str, float]:
    """The arrays a run holds at once [MiB]: per pulse the time, gate, complex signal and the
    echo the received-stage effects refer to (8 + 8 + 16 + 16 bytes); the scatterers' arrays
    (:data:`SCATTERER_PULSE_BYTES` per scatterer) of one block of ``block_pulses`` (of every
    pulse with ``keep_scatterers``); the spectrogram's power (``stft_bytes`` per value) and its
    float32 dB map; with ``motion_bytes`` the motion's arrays (:func:`motion_memory`)."""
    rows = n_pulses if keep_scatterers else min(n_pulses, block_pulses)
    terms = {
        "signal": n_pulses * 48 / MIB,
        "scatterers": rows * n_scatterers * SCATTERER_PULSE_BYTES / MIB,
        "spectrogram": n_doppler * n_frames * (stft_bytes + 4) / MIB,
    }
    return terms | ({"motion": motion_bytes / MIB} if motion_bytes else {})


def motion_memory(motion: Motion, body: Skeleton, window_frames: int) -> int:
    """The motion's arrays a run holds [bytes]: the recording's positions, the canonical body
    when it is another array (``body``: the body the run uses, whole recording), and three of
    the record's window of ``window_frames`` frames (the placed body and the interpolants of
    the unplaced and the placed window): 8 bytes a coordinate each. A 380 Hz walker holds
    about four times its joints' frames (93 MB a copy for 10 minutes)."""
    source = motion.skeleton.positions
    canonical = 0 if body.positions is source else body.positions.nbytes
    return int(source.nbytes + canonical + 3 * window_frames * body.n_joints * 3 * 8)


def count_scatterers(
    config: RunConfigBase,
    stages: Stages,
    motion: Motion,
    body: Skeleton,
    t: np.ndarray,
) -> int:
    """The scatterers of a run's pulses: those of the model and of the scatterer-stage effects
    at the record's first two pulse times ``t[:2]`` [s] (``body``: the placed body; the model
    and effects must have been started, :func:`~mdframework.pipeline.start_record`)."""
    radar_pos = np.asarray(config.scene.radar_position, dtype=np.float64)
    tb = t[:2]
    near = body.select_frames(interpolation.window_frames(body.time, float(tb[0]), float(tb[-1])))
    resample = interpolation.TrackResampler(near.time, near.positions, near.valid, "linear")
    at_pulses = Skeleton.resampled(tb, resample(tb), body.joint_names)
    wf = stages.radar
    with blame(stages.model, "scatterers"):
        scat = stages.model.scatterers(
            motion, at_pulses, radar_pos, radar.wavelength(wf.carrier_frequency)
        )
    generators = effect_generators(config.seed, stages.effects)
    rng = generators[0] if generators else np.random.default_rng(config.seed)
    gate = gate_ranges(config.scene.gate, at_pulses, radar_pos)
    context = SceneContext(radar_pos, wf.prf, wf.carrier_frequency, tb, gate, at_pulses, wf, rng, 0)
    scat = apply_effects(stages, "scatterers", scat, context, generators)
    return int(scat.positions.shape[1])


def plan_run(
    config: RunConfigBase, registry: Registry | None = None, motion: Motion | None = None
) -> RunPlan:
    """Resolve ``config`` into a :class:`RunPlan` (see the module docstring); ``motion``: its
    source's motion when already loaded (a dataset's records share their recording's)."""
    reg = registry or default_registry()
    cfg: Any = config
    stages = build_stages(config, reg)
    wf = stages.radar
    fc, prf = float(wf.carrier_frequency), float(wf.prf)
    lam = radar.wavelength(fc)
    radar_pos = np.asarray(config.scene.radar_position, dtype=np.float64)
    proc = config.processing

    if motion is None:
        motion = load_motion(stages.source)
    unplaced, _, _, where = prepare_body(config, stages, motion, radar_pos)
    body = placed(unplaced, where)
    t_start, t_end = record_window(body, cfg.motion.start, cfg.motion.duration)
    limits.check_pulses(
        t_end - t_start, wf.pulse_rate, body.n_joints, "motion.duration", proc.keep_scatterers
    )
    t = record_pulses(wf, t_start, t_end)
    n_pulses = int(t.shape[0])
    geometry = spectrogram_geometry(wf, n_pulses, proc)
    check_echo_power(wf)
    record_body = body.select_frames(frames_inside(body.time, t_start, t_end))
    # what the radar refuses (or warns about) before a pulse
    max_range = start_record(stages, record_body, t, radar_pos, config.scene.gate)

    inside = (body.time >= t_start - 1e-9) & (body.time <= t_end + 1e-9)
    # a joint nearer than scene.min_range: refused as the run refuses the scatterer there
    seen = body.valid[inside]
    ranges = np.where(seen, radar.distances(body.positions[inside], radar_pos), np.inf)
    since = body.time[inside] - body.time[inside][:1]
    start = float(body.time[inside][0] - body.time[0]) if np.any(inside) else 0.0
    refuse_near(ranges, body.joint_names, since, config.scene.min_range, "joint", start)
    speed = max_joint_radial_speed(
        body.time[inside], body.positions[inside], body.valid[inside], radar_pos
    )
    # the run interpolates the tracks (a cubic spline overshoots the frames' differences)
    method = "linear" if motion.linear_tracks else proc.interpolation
    speed = max(speed, interpolated_radial_speed(body, t, method, radar_pos))
    v_max = float(wf.max_unambiguous_velocity)
    n_scatterers = count_scatterers(config, stages, motion, body, t)
    window = interpolation.window_frames(body.time, float(t[0]), float(t[-1]))
    terms = memory_estimate(
        n_pulses,
        n_scatterers,
        geometry.nfft,
        geometry.n_frames,
        proc.block_pulses,
        proc.keep_scatterers,
        4 if proc.precision == "float32" else 8,
        motion_memory(motion, unplaced, int(window.stop - window.start)),
    )
    terms.update({name: size / MIB for name, size in wf.working_memory().items()})
    return RunPlan(
        plugins={
            "motion": _provider(reg, "motion", cfg.motion.kind),
            "scatterers": _provider(reg, "scatterers", cfg.scatterers.kind),
            "radar": _provider(reg, "radar", cfg.radar.kind),
        },
        effects=[_provider(reg, "effects", e.kind) for e in cfg.effects],
        record_start_s=t_start - float(body.time[0]),
        record_length_s=t_end - t_start,
        n_pulses=n_pulses,
        prf_hz=prf,
        pulse_rate_hz=float(wf.pulse_rate),
        pulsed="prf" in type(cfg.radar).model_fields,
        carrier_frequency_hz=fc,
        wavelength_m=lam,
        n_joints=body.n_joints,
        n_scatterers=n_scatterers,
        window_pulses=geometry.window,
        hop_pulses=geometry.hop,
        nfft=geometry.nfft,
        n_frames=geometry.n_frames,
        spectrum_rate_hz=geometry.sample_rate,
        doppler_bin_hz=geometry.doppler_bin,
        velocity_bin_mps=float(radar.doppler_to_velocity(geometry.doppler_bin, fc)),
        window_resolution_hz=geometry.window_resolution,
        window_resolution_mps=float(radar.doppler_to_velocity(geometry.window_resolution, fc)),
        max_unambiguous_velocity_mps=v_max,
        max_joint_radial_speed_mps=speed,
        aliasing=speed > v_max,
        prf_needed_hz=prf * speed / v_max,  # v_max grows in proportion to the PRF
        # nothing to reach when nothing moves radially (a rate of 0 Hz has no chirp period)
        faster_sampling=wf.faster_sampling(prf * speed / v_max) if speed > 0 else "",
        memory_mib=sum(terms.values()),
        memory_terms_mib=terms,
        range_resolution_m=wf.range_resolution,
        max_range_m=max_range,
    )


def _hz(value: float) -> str:
    for unit, scale in (("GHz", 1e9), ("MHz", 1e6), ("kHz", 1e3)):
        if abs(value) >= scale:
            return f"{value / scale:.4g} {unit}"
    return f"{value:.4g} Hz"


def _metres(value: float, digits: int) -> str:
    return f"{value / 1e3:.{digits}g} km" if value >= 1e3 else f"{value:.{digits}g} m"


def _mib(value: float) -> str:
    return f"{value:.3g}" if value < 1000 else f"{value:,.0f}"


def format_plan(plan: RunPlan, source: str) -> str:
    """The plan as the lines ``mdf check`` prints."""
    p = plan
    # a pulse-Doppler radar's slow time is its PRF; a CW radar's its I/Q rate, an FMCW radar's
    # its loop rate (several chirps, its pulses, per sample; none between frames)
    rate = f"PRF {_hz(p.prf_hz)}" if p.pulsed else f"slow time {_hz(p.prf_hz)}"
    chirps = abs(p.pulse_rate_hz - p.prf_hz) > 1e-9 * p.prf_hz
    if chirps:
        rate += f" ({p.pulse_rate_hz:.4g} pulses per second of record)"
    # the spectrogram's window counts slow-time samples, the record its pulses (chirps)
    window_unit = "pulses" if p.pulsed else "samples"
    record_unit = "pulses" if p.pulsed or chirps else "samples"
    lines = [f"{source}: valid"]
    for section, chosen in p.plugins.items():
        lines.append(f"  {section:<12}{chosen}")
    lines += [
        f"  {'effects':<12}{', '.join(p.effects) or 'none'}",
        f"  {'carrier':<12}{_hz(p.carrier_frequency_hz)} (wavelength "
        f"{p.wavelength_m * 100:.3g} cm), {rate}",
        f"  {'record':<12}{p.record_length_s:.3f} s from {p.record_start_s:.3f} s: "
        f"{p.n_pulses} {record_unit}; joints: {p.n_joints}, scatterers: {p.n_scatterers}",
        f"  {'spectrogram':<12}window {p.window_pulses} {window_unit} "
        f"({1e3 * p.window_pulses / p.spectrum_rate_hz:.1f} ms), hop {p.hop_pulses:.4g} "
        f"({1e3 * p.hop_pulses / p.spectrum_rate_hz:.2f} ms), nfft {p.nfft}: {p.n_frames} frames",
        f"  {'resolution':<12}Doppler bin {p.doppler_bin_hz:.3g} Hz = "
        f"{p.velocity_bin_mps:.3g} m/s; window {p.window_resolution_hz:.3g} Hz = "
        f"{p.window_resolution_mps:.3g} m/s",
        f"  {'unambiguous':<12}+-{p.max_unambiguous_velocity_mps:.3g} m/s "
        f"(+-{p.prf_hz / 2:.4g} Hz)",
    ]
    if p.range_resolution_m is not None:  # a radar without a range has no range line
        unambiguous = (
            "" if p.max_range_m is None else f", unambiguous to {_metres(p.max_range_m, 4)}"
        )
        lines.append(f"  {'range':<12}resolution {_metres(p.range_resolution_m, 3)}{unambiguous}")
    speed = f"fastest joint {p.max_joint_radial_speed_mps:.3g} m/s radially"
    if p.aliasing:
        lines.append(f"  {'aliasing':<12}LIKELY: {speed}; {p.faster_sampling}")
    else:
        lines.append(f"  {'aliasing':<12}none expected: {speed}")
    terms = ", ".join(f"{k} {_mib(v)}" for k, v in p.memory_terms_mib.items())
    lines.append(f"  {'memory':<12}about {_mib(p.memory_mib)} MiB of arrays ({terms} MiB)")
    return "\n".join(lines)


@dataclass(frozen=True)
class DatasetPlan:
    """What ``mdf dataset build`` would build: the records per label and, for each label's first
    simulated record, its :class:`RunPlan` (before its motion augmentations)."""

    n_records: int
    records: dict[str, int]  # label -> records
    first: dict[str, RunPlan]  # label -> plan of its first simulated record that runs
    #: the records' float32 spectrograms, from each label's first (None: histogram records)
    spectrogram_mib: float | None
    #: label -> the first of its records a run refuses (``on_error = "skip"``: the build skips
    #: them), named with its cause, and how many of those planned it refuses
    skipped: dict[str, str] = field(default_factory=dict)
    n_skipped: dict[str, int] = field(default_factory=dict)
    #: with every record planned (``every``): label -> records planned, records whose Doppler
    #: aliases, and the largest memory estimate [MiB]
    n_planned: dict[str, int] = field(default_factory=dict)
    n_aliasing: dict[str, int] = field(default_factory=dict)
    max_memory_mib: dict[str, float] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        """JSON-serialisable view."""
        return asdict(self)


def plan_dataset(
    config: Any, base_dir: Any, registry: Registry | None = None, *, every: bool = False
) -> DatasetPlan:
    """Plan a dataset config (:class:`~mdframework.dataset.DatasetConfig`, its folder
    ``base_dir``) as a build does before its first record: every record's config is validated,
    with its draws, and each source's first simulated record that runs is planned
    (:func:`plan_run`; the report shows each label's first), or with ``every`` each simulated
    record (what a run refuses stops the plan, naming the record, unless the config's
    ``on_error = "skip"``: then it is counted as the build would skip it)."""
    from .dataset import (
        is_record_failure,
        plan_records,
        record_failure,
        record_motion,
        validate_record,
    )

    specs = plan_records(config, base_dir)
    plan = DatasetPlan(len(specs), {}, {}, None)
    planned: set[int | None] = set()  # the sources of which a record is planned
    for spec in specs:
        label = spec.label
        plan.records[label] = plan.records.get(label, 0) + 1
        if (spec.source in planned and not every) or "recording" in spec.run_config:
            continue
        where = f"record {spec.record_id}"
        try:
            run = validate_record(
                spec.run_config, where, spec.base_dir, spec.draws, spec.draw_origins
            )
            p = plan_run(run, registry, record_motion(spec))
        except (MdfError, ValueError) as exc:
            if not is_record_failure(exc):  # a bug, as in the build
                raise
            named, cause, _ = record_failure(spec, exc)
            if spec.on_error != "skip":
                raise MdfError(f"{named}: {cause}") from None
            plan.skipped.setdefault(label, f"{named}: {cause}")
            plan.n_skipped[label] = plan.n_skipped.get(label, 0) + 1
            continue
        plan.first.setdefault(label, p)
        planned.add(spec.source)
        if every:
            plan.n_planned[label] = plan.n_planned.get(label, 0) + 1
            plan.n_aliasing[label] = plan.n_aliasing.get(label, 0) + int(p.aliasing)
            plan.max_memory_mib[label] = max(plan.max_memory_mib.get(label, 0.0), p.memory_mib)
    if config.representation != "histogram" and plan.first:
        cells = sum(plan.records[k] * p.nfft * p.n_frames for k, p in plan.first.items())
        plan = replace(plan, spectrogram_mib=cells * 4 / MIB)
    return plan


def format_dataset_plan(plan: DatasetPlan, source: str) -> str:
    """The dataset plan as the lines ``mdf dataset check`` prints."""
    lines = [f"{source}: valid, {plan.n_records} records"]
    for label, n in plan.records.items():
        p = plan.first.get(label)
        if p is not None:
            alias = "LIKELY" if p.aliasing else "none expected"
            lines.append(
                f"  {label}: {n} records; the first that runs: {p.record_length_s:.3f} s, "
                f"{p.n_pulses} pulses, {p.n_scatterers} scatterers, spectrogram {p.nfft} x "
                f"{p.n_frames}, aliasing {alias} (fastest joint "
                f"{p.max_joint_radial_speed_mps:.3g} m/s, unambiguous "
                f"+-{p.max_unambiguous_velocity_mps:.3g} m/s), memory about "
                f"{_mib(p.memory_mib)} MiB"
            )
        elif label not in plan.skipped:
            lines.append(f"  {label}: {n} records of a real radar's recordings")
        if label in plan.n_planned:
            lines.append(
                f"  {label}: {plan.n_planned[label]} records run: {plan.n_aliasing[label]} with "
                f"aliasing, memory at most {_mib(plan.max_memory_mib[label])} MiB"
            )
        if label in plan.skipped:
            lines.append(
                f"  {label}: {plan.n_skipped[label]} record(s) refused, which the build skips "
                f"(on_error = 'skip'), the first: {plan.skipped[label]}"
            )
    if plan.spectrogram_mib:
        lines.append(
            f"  spectrograms about {_mib(plan.spectrogram_mib)} MiB "
            "(float32; records are stored uncompressed)"
        )
    return "\n".join(lines)
