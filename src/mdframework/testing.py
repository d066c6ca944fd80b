"""Contract checks every plugin of an interface must pass, for plugin authors' own tests.

Each ``check_*`` function raises ``AssertionError`` naming the broken contract::

    from mdframework.testing import check_plugin_class, check_motion_source

    def test_my_source():
        check_plugin_class(MySource, "motion")
        check_motion_source(MySource(MySource.Config(...)))

The project runs them over every installed plugin (``tests/test_contracts.py``).
"""

from __future__ import annotations

import json
import typing

import numpy as np

from .interfaces import (
    Effect,
    Motion,
    MotionSource,
    Plugin,
    PulseBlock,
    RadarRecordingSource,
    RadarWaveform,
    Recording,
    ScattererModel,
    Scatterers,
    SceneContext,
    receive_points,
)
from .physics import radar
from .plugins import INTERFACES
from .skeleton import CANONICAL_JOINTS, Skeleton


def check_plugin_class(cls: type[Plugin], interface: str) -> None:
    """A plugin class has a name, a docstring, and a strict Config whose ``kind`` is its name."""
    base = INTERFACES[interface][1]
    assert issubclass(cls, base), f"{cls.__name__} is not a {base.__name__}"
    assert isinstance(cls.name, str) and cls.name, f"{cls.__name__} has no name"
    assert (cls.__doc__ or "").strip(), f"{cls.__name__} has no docstring"
    field = cls.Config.model_fields.get("kind")
    assert field is not None, f"{cls.__name__}.Config has no kind field"
    assert typing.get_args(field.annotation) == (cls.name,), (
        f"{cls.__name__}.Config.kind must be Literal[{cls.name!r}]"
    )
    assert cls.Config.model_config.get("extra") == "forbid", (
        f"{cls.__name__}.Config must forbid unknown fields"
    )


def check_motion_source(source: MotionSource) -> Motion:
    """``load()`` gives a consistent Motion: JSON metadata, a complete canonical map whose
    canonical body is finite where valid, and RCS per joint when given."""
    motion = source.load()
    assert isinstance(motion, Motion), "load() must return a Motion"
    assert isinstance(motion.skeleton, Skeleton)
    assert motion.skeleton.n_frames >= 2, "a recording needs at least two frames"
    json.dumps(dict(motion.metadata))  # JSON-serialisable
    if motion.canonical_map is not None:
        body = motion.canonical()
        assert body.joint_names == CANONICAL_JOINTS
        assert np.all(np.isfinite(body.positions[body.valid])), "valid joints must be finite"
    if motion.point_rcs is not None:
        assert motion.point_rcs.shape == (motion.skeleton.n_joints,)
        assert np.all(motion.point_rcs >= 0), "RCS must be >= 0"
    return motion


def check_scatterer_model(
    model: ScattererModel, skeleton: Skeleton, motion: Motion, wavelength: float = 0.02
) -> Scatterers:
    """Scatterers for a body at 10 m: shapes, finite positions, finite non-negative RCS."""
    radar_position = np.array([10.0, 0.0, 1.0])
    scat = model.scatterers(motion, skeleton, radar_position, wavelength)
    n = skeleton.n_frames
    assert scat.positions.shape[0] == n and scat.rcs.shape[0] == n, "one row per pulse"
    assert np.all(np.isfinite(scat.positions)), "positions must be finite"
    assert np.all(np.isfinite(scat.rcs)) and np.all(scat.rcs >= 0), "RCS finite and >= 0"
    return scat


def check_waveform(waveform: RadarWaveform) -> None:
    """Positive carrier and PRF; increasing ``pulse_times``; ``receive`` returns one complex
    sample per pulse; an approaching scatterer (100 m^2, 5 m away, at a quarter of the radar's
    unambiguous velocity) has positive Doppler (the project's sign convention). The Doppler is
    read from the phase steps between consecutive pulses at most 1.5 / prf apart, so radars
    whose slow time has gaps (FMCW frames) are checked the same way."""
    fc, prf = waveform.carrier_frequency, waveform.prf
    assert fc > 0 and prf > 0
    t = waveform.pulse_times(0.0, 512 / prf)
    n = t.shape[0]
    assert n >= 2 and np.all(np.diff(t) > 0), "pulse_times must increase"
    v = 0.25 * waveform.max_unambiguous_velocity  # approaching, well inside the limit
    ranges = (5.0 - v * (t - t[0]))[:, None]
    rcs = np.full_like(ranges, 100.0)  # strong, so that a radar's own receiver noise is small
    received = receive_points(waveform, ranges, rcs, ranges[:, 0], times=t)
    y = received.signal
    assert y.shape == (n,) and np.iscomplexobj(y), "signal must be (n_pulses,) complex"
    assert np.all(np.isfinite(y))
    dt = np.diff(t)
    near = dt <= 1.5 / prf
    steps = np.angle(y[1:] * np.conj(y[:-1]))[near]
    doppler = float(np.sum(steps) / (2 * np.pi * np.sum(dt[near])))
    expected = float(radar.velocity_to_doppler(v, fc))
    assert abs(doppler - expected) < 1e-3 * expected, (
        f"an approaching target must show +{expected:.3f} Hz, got {doppler:.3f} Hz"
    )


def check_effect_class(cls: type[Effect]) -> None:
    """An effect declares the stage it acts on."""
    check_plugin_class(cls, "effect")
    assert getattr(cls, "stage", None) in ("scatterers", "received"), (
        f"{cls.__name__}.stage must be 'scatterers' or 'received'"
    )


def check_block_invariance(
    model: ScattererModel,
    waveform: RadarWaveform,
    skeleton: Skeleton,
    motion: Motion,
    effects: tuple[Effect, ...] = (),
    block: int = 37,
) -> None:
    """The streaming contract: scatterers, scatterer-stage ``effects`` and ``receive`` give the
    same result for a record processed as one block and as blocks of ``block`` pulses
    (``skeleton``: the body at the pulse times, in the scene frame)."""
    radar_position = np.array([10.0, 0.0, 1.0])
    lam = float(radar.wavelength(waveform.carrier_frequency))
    t = skeleton.time
    span = np.linalg.norm(skeleton.positions - radar_position, axis=-1)

    def run(size: int) -> tuple[np.ndarray, np.ndarray]:
        model.start_record(skeleton)
        waveform.start_record(t, (float(span.min()), float(span.max())))
        rcs_parts, signal_parts = [], []
        step = max(waveform.block_multiple, size - size % waveform.block_multiple)
        for lo in range(0, t.shape[0], step):
            sk = skeleton.select_frames(slice(lo, lo + step))
            scat = model.scatterers(motion, sk, radar_position, lam)
            gate = np.linalg.norm(sk.positions[:, 0, :] - radar_position, axis=-1)
            rng = np.random.default_rng(0)
            ctx = SceneContext(
                radar_position,
                waveform.prf,
                waveform.carrier_frequency,
                sk.time,
                gate,
                sk,
                waveform,
                rng,
                lo,
            )
            for effect in effects:
                if effect.stage == "scatterers":
                    scat = effect.apply(scat, ctx)
                    assert isinstance(scat, Scatterers), (
                        f"effect {effect.name!r}: apply must return Scatterers"
                    )
            ranges = scat.ranges(radar_position)
            rec = waveform.receive(PulseBlock(lo, sk.time, scat, ranges, gate, radar_position))
            rcs_parts.append(scat.rcs)
            signal_parts.append(rec.signal)
        return np.concatenate(rcs_parts), np.concatenate(signal_parts)

    rcs_one, sig_one = run(t.shape[0])
    rcs_many, sig_many = run(block)
    assert np.allclose(rcs_one, rcs_many, rtol=1e-12, atol=0), (
        "scatterer RCS differs between one block and many: the model or an effect is not "
        "block-invariant (take record-wide quantities in start_record)"
    )
    scale = float(np.max(np.abs(sig_one))) or 1.0
    assert np.max(np.abs(sig_one - sig_many)) <= 1e-9 * scale, (
        "received signal differs between one block and many: the waveform is not block-invariant"
    )


def check_recording_source(source: RadarRecordingSource) -> list[Recording]:
    """``load()`` gives named recordings with consistent point clouds: unique names, frame
    indices within the recording, finite positions and velocities, a positive frame period and
    JSON metadata."""
    recordings = source.load()
    assert recordings, "load() must return at least one recording"
    names = [r.name for r in recordings]
    assert len(set(names)) == len(names), "recording names must be unique"
    for rec in recordings:
        assert isinstance(rec, Recording), "load() must return Recording objects"
        cloud = rec.cloud
        assert cloud.n_frames >= 1 and cloud.frame_period > 0
        assert np.all(np.isfinite(cloud.positions)) and np.all(np.isfinite(cloud.velocity))
        assert np.all(np.diff(cloud.frame) >= 0), "points must be in frame order"
        json.dumps(dict(rec.metadata))
    return recordings
