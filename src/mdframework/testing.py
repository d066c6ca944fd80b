"""Contract checks for plugins: a public suite in the spirit of scikit-learn's estimator checks.

Every plugin of an interface must pass its interface's checks. Run them all on one plugin::

    from mdframework.testing import check_plugin

    def test_my_effect():
        check_plugin(MyEffect)                      # instantiated with MyEffect.Config()
        check_plugin(MySource(MySource.Config(file="walk.bvh")))

or one pytest test per check (the failing check is named in the test id)::

    from mdframework.testing import parametrize_with_checks

    @parametrize_with_checks([MyEffect, MySource(MySource.Config(file="walk.bvh"))])
    def test_contract(plugin, check):
        check(plugin)

:func:`plugin_checks` lists the checks of one plugin; each is also a public function taking the
plugin instance (``check_effect(effect)``), and raises ``AssertionError`` naming the plugin and
the broken contract. The checks build their own inputs: a walking body (:func:`walking_motion`),
a reference radar (:class:`ReferenceRadar`) and separable features for classifiers, so they need
no other plugin. The project runs them over each of its own plugins
(``tests/test_contracts.py``); a third party runs them over its plugins in its own tests.
"""

from __future__ import annotations

import copy
import json
import typing
import warnings
from collections.abc import Callable, Sequence
from functools import partial
from typing import Any, Literal

import numpy as np
from pydantic import Field, PydanticUserError, ValidationError
from pydantic_core import PydanticSerializationError

from .interfaces import (
    Classifier,
    Effect,
    Motion,
    MotionSource,
    Plugin,
    PluginConfig,
    PulseBlock,
    RadarConfig,
    RadarWaveform,
    Received,
    Recording,
    RecordingSource,
    ScattererModel,
    Scatterers,
    SceneContext,
    point_responses,
    receive_points,
)
from .physics import body as body_physics
from .physics import radar
from .plugins import INTERFACES, interface_name
from .skeleton import CANONICAL_JOINTS, Skeleton

#: A check: takes the plugin instance, raises AssertionError when a contract is broken (some
#: return what they checked, for further use).
Check = Callable[[Any], Any]

#: where the checks put the radar [m]
RADAR_POSITION = np.array([10.0, 0.0, 1.0])


# --------------------------------------------------------------------------- check inputs


def standing_body(height: float = 1.8) -> np.ndarray:
    """Canonical joints (17, 3) [m] of a person ``height`` [m] tall standing at the origin,
    facing +x, built from the body's segment-length fractions."""
    f = body_physics.SEGMENT_FRACTIONS
    z_hip = (f["upper_leg"] + f["lower_leg"]) * height
    top = z_hip + f["torso"] * height
    p: dict[str, tuple[float, float, float]] = {
        "base": (0.0, 0.0, z_hip),
        "neck": (0.0, 0.0, top),
        "head": (0.0, 0.0, top + f["head"] * height),
    }
    for s, y in (("l", 1.0), ("r", -1.0)):
        sh, hp = y * f["shoulder"] * height, y * f["hip"] * height
        p[f"{s}_shoulder"] = (0, sh, top)
        p[f"{s}_elbow"] = (0, sh, top - f["upper_arm"] * height)
        p[f"{s}_hand"] = (0, sh, top - (f["upper_arm"] + f["lower_arm"]) * height)
        p[f"{s}_hip"] = (0, hp, z_hip)
        p[f"{s}_knee"] = (0, hp, z_hip - f["upper_leg"] * height)
        p[f"{s}_ankle"] = (0, hp, 0.0)
        p[f"{s}_toe"] = (f["foot"] * height, hp, 0.0)
    return np.array([p[j] for j in CANONICAL_JOINTS], dtype=float)


def walking_positions(
    t: np.ndarray, speed: float = 1.0, swing_deg: float = 25.0, cadence_hz: float = 0.9
) -> np.ndarray:
    """Canonical joints (n, 17, 3) [m] at times ``t`` (n,) [s] of a body walking along +x at
    ``speed`` [m/s], legs and arms swinging ``swing_deg`` about hips and shoulders."""
    j = {n: i for i, n in enumerate(CANONICAL_JOINTS)}
    base = standing_body()
    pos = np.repeat(base[None], t.size, axis=0)
    ang = np.deg2rad(swing_deg) * np.sin(2 * np.pi * cadence_hz * t)
    for s, sign in (("l", 1.0), ("r", -1.0)):
        for pivot, limb in (("hip", ("knee", "ankle", "toe")), ("shoulder", ("elbow", "hand"))):
            a = sign * ang * (1 if pivot == "hip" else -1)
            piv = base[j[f"{s}_{pivot}"]]
            for name in limb:
                d = base[j[f"{s}_{name}"]] - piv
                x = d[0] * np.cos(a) - d[2] * np.sin(a)
                z = d[0] * np.sin(a) + d[2] * np.cos(a)
                pos[:, j[f"{s}_{name}"]] = piv + np.stack([x, np.full_like(x, d[1]), z], 1)
    pos[:, :, 0] += speed * t[:, None]
    return pos


def walking_motion(duration: float = 1.0, rate: float = 2000.0) -> Motion:
    """A canonical body walking toward the radar at :data:`RADAR_POSITION`, sampled at ``rate``
    [Hz] (pulse-like), with unit point RCS per joint; ``duration`` [s]."""
    t = np.arange(0.0, duration, 1.0 / rate)
    pos = walking_positions(t)
    mapping = {name: name for name in CANONICAL_JOINTS}
    return Motion(
        Skeleton(t, pos, CANONICAL_JOINTS),
        {"source": "mdframework.testing", "activity": "walk"},
        mapping,
        np.ones(len(CANONICAL_JOINTS)),
    )


class ReferenceRadarConfig(RadarConfig):
    """The reference radar of the checks."""

    kind: Literal["reference"] = "reference"
    carrier_frequency: float = Field(10e9, gt=0, description="Carrier [Hz].")
    prf: float = Field(2000.0, gt=0, description="Pulse repetition frequency [Hz].")
    bandwidth: float = Field(100e6, gt=0, description="Bandwidth [Hz] (for effects that ask).")

    def pulse_rate(self) -> float:
        """One pulse per 1/PRF [Hz]."""
        return self.prf


class ReferenceRadar(RadarWaveform):
    """An ideal coherent radar for the checks: ``signal = sum_k sqrt(rcs_k) / R_k^2
    exp(-j 4 pi R_k / lambda)`` (no range gating, so every scatterer is seen)."""

    name = "reference"
    Config = ReferenceRadarConfig
    config: ReferenceRadarConfig

    @property
    def carrier_frequency(self) -> float:
        """Carrier [Hz]."""
        return self.config.carrier_frequency

    @property
    def prf(self) -> float:
        """PRF [Hz]."""
        return self.config.prf

    def receive(self, block: PulseBlock) -> Received:
        """The sum of the scatterers' phasors per pulse of the block."""
        lam = radar.wavelength(self.carrier_frequency)
        r = block.ranges
        rcs = block.scatterers.rcs
        phasor = np.sqrt(np.asarray(rcs, dtype=np.float64)) / r**2 * np.exp(-4j * np.pi * r / lam)
        return Received(np.asarray(phasor.sum(axis=1), dtype=np.complex128))


def scene_context(
    motion: Motion | None = None,
    waveform: RadarWaveform | None = None,
    seed: int = 0,
    stage: str = "scatterers",
) -> SceneContext:
    """The scene the effect checks use: ``motion`` (default :func:`walking_motion`) taken as
    already at the pulse times, the radar at :data:`RADAR_POSITION`, the gate on the hips; for
    the ``"received"`` stage the context has no skeleton (as in a run)."""
    motion = motion or walking_motion()
    wf = waveform or ReferenceRadar(ReferenceRadar.Config(prf=1.0 / _step(motion.skeleton.time)))
    body = motion.canonical()
    gate = np.linalg.norm(body.positions[:, 0] - RADAR_POSITION, axis=1)
    return SceneContext(
        RADAR_POSITION.copy(),
        wf.prf,
        wf.carrier_frequency,
        body.time,
        gate,
        body if stage == "scatterers" else None,
        wf,
        np.random.default_rng(seed),
    )


def _step(time: np.ndarray) -> float:
    return float(np.median(np.diff(time)))


# --------------------------------------------------------------------------- common checks


def _label(plugin: Any) -> str:
    cls = plugin if isinstance(plugin, type) else type(plugin)
    return f"{cls.__name__} ({getattr(cls, 'name', '?')!r})"


def _interface_of(cls: type) -> str:
    for interface, spec in INTERFACES.items():
        if issubclass(cls, spec.base):
            return interface
    raise AssertionError(f"{cls.__name__} implements none of the plugin interfaces")


def check_plugin_class(cls: type[Plugin], interface: str | None = None) -> None:
    """A plugin class has a name, a docstring, and a strict Config whose ``kind`` is its name
    (``Literal[name]``) and that can be shown as a JSON schema."""
    interface = interface_name(interface) if interface else _interface_of(cls)
    base = INTERFACES[interface].base
    assert isinstance(cls, type) and issubclass(cls, base), f"{cls!r} is not a {base.__name__}"
    assert isinstance(getattr(cls, "name", None), str) and cls.name, f"{cls.__name__} has no name"
    assert (cls.__doc__ or "").strip(), f"{cls.__name__} has no docstring"
    config = getattr(cls, "Config", None)
    assert config is not None, f"{cls.__name__} has no Config (a mdframework.PluginConfig)"
    assert isinstance(config, type) and issubclass(config, PluginConfig), (
        f"{cls.__name__}.Config must subclass mdframework.PluginConfig"
    )
    field = config.model_fields.get("kind")
    assert field is not None, f"{cls.__name__}.Config has no kind field"
    assert typing.get_args(field.annotation) == (cls.name,), (
        f"{cls.__name__}.Config.kind must be Literal[{cls.name!r}]"
    )
    assert config.model_config.get("extra") == "forbid", (
        f"{cls.__name__}.Config must forbid unknown fields"
    )
    try:
        config.model_json_schema()  # shown by `mdf config schema`
    except PydanticUserError as exc:
        raise AssertionError(
            f"{cls.__name__}.Config has no JSON schema (mdf config schema shows it): "
            f"{_first_line(exc)}"
        ) from None


def _first_line(exc: Exception) -> str:
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0]


def check_config_round_trip(plugin: Plugin) -> None:
    """The plugin keeps its validated config, and that config survives a JSON round trip (runs
    save it in ``config.resolved.json`` and must be reproducible from it)."""
    cfg, who = plugin.config, _label(plugin)
    assert isinstance(cfg, type(plugin).Config), f"{who}: self.config is not its Config"
    try:
        saved = json.loads(cfg.model_dump_json())
    except PydanticSerializationError as exc:
        raise AssertionError(
            f"{who}: its config cannot be saved as JSON (config.resolved.json): {exc}"
        ) from None
    try:  # pydantic does not check defaults: a default its own field refuses is found here
        again = type(cfg).model_validate(saved)
    except ValidationError as exc:
        error = exc.errors()[0]
        where = ".".join(map(str, error["loc"]))
        raise AssertionError(f"{who}: its config is not valid: {where}: {error['msg']}") from None
    assert again == cfg, f"{who}: its config changes in a JSON round trip"


# --------------------------------------------------------------------------- motion sources


def check_motion_source(source: MotionSource) -> Motion:
    """``load()`` gives a consistent Motion: JSON metadata, a complete canonical map whose
    canonical body is finite where valid, RCS per joint when given; loading twice gives the
    same motion."""
    motion = source.load()
    who = _label(source)
    assert isinstance(motion, Motion), f"{who}: load() must return a Motion, got {motion!r}"
    assert isinstance(motion.skeleton, Skeleton), f"{who}: Motion.skeleton must be a Skeleton"
    assert motion.skeleton.n_frames >= 2, f"{who}: a recording needs at least two frames"
    try:
        json.dumps(dict(motion.metadata))
    except TypeError as exc:
        raise AssertionError(f"{who}: metadata must be JSON-serialisable: {exc}") from None
    sk = motion.skeleton
    assert np.all(np.isfinite(sk.positions[sk.valid])), f"{who}: valid joints must be finite"
    if motion.canonical_map is not None:
        canonical = motion.canonical()
        assert canonical.joint_names == CANONICAL_JOINTS
        assert np.all(np.isfinite(canonical.positions[canonical.valid])), (
            f"{who}: valid canonical joints must be finite"
        )
    if motion.point_rcs is not None:
        assert motion.point_rcs.shape == (sk.n_joints,), f"{who}: point_rcs is (n_joints,)"
        assert np.all(motion.point_rcs >= 0), f"{who}: RCS must be >= 0"
    again = source.load()
    assert np.array_equal(again.skeleton.positions, sk.positions, equal_nan=True), (
        f"{who}: load() must give the same motion every time"
    )
    return motion


# --------------------------------------------------------------------------- scatterer models


def check_scatterer_model(
    model: ScattererModel,
    skeleton: Skeleton | None = None,
    motion: Motion | None = None,
    wavelength: float = 0.02,
) -> Scatterers:
    """Scatterers for a walking body 10 m from the radar: one row per pulse, finite positions,
    finite non-negative RCS, one name per scatterer (block invariance:
    :func:`check_scatterer_model_blocks`)."""
    motion = motion or walking_motion()
    if skeleton is None:
        skeleton = motion.canonical() if model.needs_canonical else motion.skeleton
    who = _label(model)
    model.start_record(skeleton)
    scat = model.scatterers(motion, skeleton, RADAR_POSITION, wavelength)
    assert isinstance(scat, Scatterers), f"{who}: scatterers() must return Scatterers"
    n = skeleton.n_frames
    assert scat.positions.shape[0] == n and scat.rcs.shape[0] == n, f"{who}: one row per pulse"
    assert np.all(np.isfinite(scat.positions)), f"{who}: positions must be finite"
    assert np.all(np.isfinite(scat.rcs)) and np.all(scat.rcs >= 0), (
        f"{who}: RCS must be finite and >= 0"
    )
    _check_dtypes(who, "scatterers()", scat)
    return scat


# --------------------------------------------------------------------------- radar waveforms


def check_radar_waveform(waveform: RadarWaveform) -> None:
    """Positive carrier and PRF; increasing ``pulse_times``; ``receive`` returns one finite
    complex sample per pulse; an approaching scatterer (5 m away, at a quarter of the radar's
    unambiguous velocity) has positive Doppler (the project's sign convention);
    ``receive_signal`` gives the same signal; two scatterers give the sum of their separate
    returns (superposition), and ``receive_each`` gives those separate returns (receiver noise
    is left out of all these receives). The pulses are the radar's own ``pulse_times`` and the
    Doppler is read from the phase steps between consecutive pulses at
    most 1.5 / prf apart, so radars whose slow time has gaps (FMCW frames) are checked too.
    The spectrogram of the signal has the geometry ``spectrogram_geometry`` reports,
    ``smaller_spectrogram`` gives a field and an advice, and ``working_memory`` names byte
    counts."""
    who = _label(waveform)
    fc, prf = waveform.carrier_frequency, waveform.prf
    assert fc > 0 and prf > 0, f"{who}: carrier and PRF must be > 0"
    t = waveform.pulse_times(0.0, 512 / prf)
    n = t.shape[0]
    assert n >= 2 and np.all(np.diff(t) > 0), f"{who}: pulse_times must increase"
    v = 0.25 * waveform.max_unambiguous_velocity  # approaching, well inside the limit
    ranges = (5.0 - v * (t - t[0]))[:, None]
    received = receive_points(waveform, ranges, np.ones_like(ranges), ranges[:, 0], times=t)
    assert isinstance(received, Received), f"{who}: receive() must return Received"
    memory = dict(waveform.working_memory())
    assert all(isinstance(k, str) and isinstance(b, int) and b >= 0 for k, b in memory.items()), (
        f"{who}: working_memory() must name byte counts >= 0, got {memory}"
    )
    y = received.signal
    assert y.shape == (n,) and np.iscomplexobj(y), f"{who}: signal must be (n_pulses,) complex"
    _check_dtypes(who, "receive()", received)
    assert np.all(np.isfinite(y)), f"{who}: the signal must be finite"
    only = receive_points(
        waveform, ranges, np.ones_like(ranges), ranges[:, 0], times=t, signal_only=True
    ).signal
    assert np.array_equal(only, y), f"{who}: receive_signal() must equal receive().signal"
    dt = np.diff(t)
    near = dt <= 1.5 / prf
    steps = np.angle(y[1:] * np.conj(y[:-1]))[near]
    doppler = float(np.sum(steps) / (2 * np.pi * np.sum(dt[near])))
    expected = float(radar.velocity_to_doppler(v, fc))
    assert abs(doppler - expected) < 1e-3 * expected, (
        f"{who}: an approaching target must show +{expected:.3f} Hz, got {doppler:.3f} Hz"
    )
    second = ranges + 0.05  # a second scatterer 5 cm behind the first, same gate
    both = receive_points(
        waveform, np.hstack([ranges, second]), np.ones((n, 2)), ranges[:, 0], times=t
    ).signal
    alone = receive_points(waveform, second, np.ones_like(second), ranges[:, 0], times=t).signal
    scale = np.max(np.abs(both)) + 1e-300
    assert np.max(np.abs(both - (y + alone))) <= 1e-6 * scale, (
        f"{who}: the return of two scatterers must be the sum of their returns"
    )
    each = point_responses(
        waveform, np.hstack([ranges, second]), np.ones((n, 2)), ranges[:, 0], times=t
    )
    assert each.shape == (2, n) and np.max(np.abs(each - np.stack([y, alone]))) <= 1e-6 * scale, (
        f"{who}: receive_each() must give each scatterer's own return, (n_scatterers, n_pulses)"
    )
    _check_spectrogram_geometry(who, waveform, y, t)


def _check_spectrogram_geometry(
    who: str, waveform: RadarWaveform, signal: np.ndarray, times: np.ndarray
) -> None:
    """The run's spectrogram of ``signal`` has the geometry ``spectrogram_geometry`` reports
    (what ``mdf check`` prints): its shape and the spacing of its Doppler bins."""
    from .pipeline import record_spectrogram
    from .settings import ProcessingConfig

    proc = ProcessingConfig(window_length=64, hop=16, nfft=128)
    geometry = waveform.spectrogram_geometry(times.shape[0], proc)
    spec = record_spectrogram(waveform, signal, times, proc)
    assert spec.power.shape == geometry.shape, (
        f"{who}: the spectrogram is {spec.power.shape} but spectrogram_geometry() says "
        f"{geometry.shape}: override both together"
    )
    step = float(np.mean(np.diff(spec.doppler)))
    assert abs(step - geometry.doppler_bin) <= 1e-9 * geometry.doppler_bin, (
        f"{who}: the Doppler bins are {step:.6g} Hz apart but spectrogram_geometry() says "
        f"{geometry.doppler_bin:.6g} Hz"
    )
    fields = waveform.smaller_spectrogram(proc)
    assert (
        isinstance(fields, tuple) and len(fields) == 2 and all(isinstance(f, str) for f in fields)
    ), f"{who}: smaller_spectrogram() must give (field, advice), two strings, got {fields!r}"


# --------------------------------------------------------------------------- classifiers


def check_classifier(classifier: Classifier) -> None:
    """``fit`` returns the classifier; ``predict`` gives one training label per row; two
    well-separated classes are learnt without error; the inputs are not modified; a fresh
    instance fitted on the same data predicts the same."""
    who = _label(classifier)
    rng = np.random.default_rng(0)
    centres = np.array([[0.0, 0.0, 0.0], [10.0, 10.0, 10.0]])
    x = np.concatenate([c + rng.normal(0, 0.5, (20, 3)) for c in centres])
    y = np.array(["walk"] * 20 + ["run"] * 20)
    x_copy, y_copy = x.copy(), y.copy()
    fitted = copy.deepcopy(classifier).fit(x, y)
    assert isinstance(fitted, Classifier), f"{who}: fit() must return the classifier"
    pred = np.asarray(fitted.predict(x))
    assert pred.shape == (x.shape[0],), f"{who}: predict() must give one label per row"
    assert set(pred.tolist()) <= set(y.tolist()), f"{who}: predict() gave unknown labels"
    assert np.array_equal(pred, y), f"{who}: two well-separated classes were not learnt"
    assert np.array_equal(x, x_copy) and np.array_equal(y, y_copy), (
        f"{who}: fit/predict must not modify their inputs"
    )
    again = copy.deepcopy(classifier).fit(x, y).predict(centres)
    assert np.array_equal(np.asarray(again), np.asarray(fitted.predict(centres))), (
        f"{who}: the same data must give the same predictions"
    )


# --------------------------------------------------------------------------- effects


def _effect_input(
    effect: Effect, context: SceneContext, model: ScattererModel | None, body: Skeleton
) -> Any:
    """The data an effect of the checks gets: the walking body's scatterers (by default one
    point per joint whose RCS swings over time, :func:`swinging_rcs`), or what the context's
    radar receives of them."""
    if model is None:
        rcs = swinging_rcs(body.time, body.n_joints)
        scat = Scatterers(body.positions, rcs, body.joint_names)
    else:
        model.start_record(body)
        scat = model.scatterers(walking_motion(), body, context.radar_position, 0.03)
    if effect.stage == "scatterers":
        return scat
    ranges = scat.ranges(context.radar_position)
    block = PulseBlock(
        0, context.pulse_times, scat, ranges, context.gate_range, context.radar_position
    )
    return context.waveform.receive(block)


def swinging_rcs(time: np.ndarray, n_points: int, swing: float = 0.5) -> np.ndarray:
    """RCS (n, n_points) float64 [m^2] of points whose RCS swings about 1 m^2 over ``time``
    (n,) [s]: ``1 + swing sin(2 pi 1.3 Hz t + k)`` for the k-th point, so that effects whose
    output depends on the RCS (smoothing it over pulses, say) are checked on an RCS that
    changes from pulse to pulse and from point to point."""
    phase = 2 * np.pi * 1.3 * np.asarray(time, dtype=np.float64)[:, None] + np.arange(n_points)
    return np.asarray(1.0 + swing * np.sin(phase), dtype=np.float64)


#: dtype of each array of the data passed between stages (see :mod:`mdframework.interfaces`)
DTYPES = {
    "positions": np.dtype(np.float64),
    "rcs": np.dtype(np.float64),
    "signal": np.dtype(np.complex128),
}


def _arrays(data: Any) -> dict[str, np.ndarray]:
    """The arrays of ``Scatterers`` or ``Received`` that :data:`DTYPES` names."""
    if isinstance(data, Scatterers):
        return {"positions": data.positions, "rcs": data.rcs}
    return {"signal": data.signal}


def _check_dtypes(who: str, what: str, data: Any) -> None:
    for name, array in _arrays(data).items():
        found = np.asarray(array).dtype
        assert found == DTYPES[name], (
            f"{who}: {what} must give {type(data).__name__}.{name} as {DTYPES[name]} "
            f"(mdframework.interfaces), got {found}"
        )


def check_effect(effect: Effect, model: ScattererModel | None = None) -> None:
    """An effect declares its stage; ``apply`` returns the same kind of data it was given
    (``Scatterers`` or ``Received``, never None), for the same pulses, finite, with the dtypes
    of :mod:`mdframework.interfaces` (float64 positions and RCS, complex128 signal), and leaves
    its input unchanged; ``describe()`` is a JSON-serialisable dict; the same seed gives the
    same output; a scatterer-stage effect gives the same scatterers and signal whether the
    record comes as one block or many. ``model`` makes the scatterers (default: one point per
    joint of a walking body, its RCS swinging over time: :func:`swinging_rcs`)."""
    who = _label(effect)
    stage = getattr(effect, "stage", None)
    assert stage in ("scatterers", "received"), f"{who}: stage must be 'scatterers' or 'received'"
    body = walking_motion().canonical()

    def run() -> Any:
        context = scene_context(stage=stage)
        effect.start_record(body, context.radar_position)
        data = _effect_input(effect, context, model, body)
        before = {name: np.array(array, copy=True) for name, array in _arrays(data).items()}
        out = effect.apply(data, context)
        for name, array in _arrays(data).items():
            assert np.array_equal(array, before[name], equal_nan=True), (
                f"{who}: apply() changed its input's {name} in place: return new arrays "
                f"(e.g. data.replace({name}=...)) and leave the input as it is"
            )
        return out

    out = run()
    expected = Scatterers if stage == "scatterers" else Received
    assert isinstance(out, expected), (
        f"{who}: apply() on the {stage!r} stage must return {expected.__name__}, got {out!r}"
    )
    n = body.n_frames
    if isinstance(out, Scatterers):
        assert out.positions.shape[0] == n, f"{who}: apply() must keep one row per pulse"
        assert np.all(np.isfinite(out.positions)), f"{who}: positions must be finite"
        assert np.all(np.isfinite(out.rcs)) and np.all(out.rcs >= 0), f"{who}: RCS finite, >= 0"
        first: np.ndarray = out.rcs
    else:
        assert out.signal.shape == (n,), f"{who}: apply() must keep one sample per pulse"
        assert np.all(np.isfinite(out.signal)), f"{who}: the signal must be finite"
        first = out.signal
    _check_dtypes(who, "apply()", out)
    described = effect.describe()
    assert isinstance(described, dict), f"{who}: describe() must return a dict"
    try:
        json.dumps(described)
    except TypeError as exc:
        raise AssertionError(f"{who}: describe() must be JSON-serialisable: {exc}") from None
    again = run()
    second = again.rcs if isinstance(again, Scatterers) else again.signal
    assert np.array_equal(first, second), (
        f"{who}: the same seed must give the same output for two records in a row (draw random "
        "numbers from context.rng only, and reset in start_record what apply accumulates)"
    )
    if stage == "scatterers":
        points = JointPoints(JointPoints.Config(rcs_swing=0.5))
        _invariant(who, points, _reference_radar(body), body, (effect,))


class JointPointsConfig(PluginConfig):
    """Isotropic points at the joints."""

    kind: Literal["joint_points"] = "joint_points"
    rcs_swing: float = Field(
        0.0,
        ge=0,
        lt=1,
        description="How far each point's RCS swings about 1 m^2 over time (swinging_rcs); "
        "0: unit RCS.",
    )


class JointPoints(ScattererModel):
    """An isotropic point scatterer at every joint, of unit RCS or one that swings over time
    (the checks' scatterer model)."""

    name = "joint_points"
    Config = JointPointsConfig
    config: JointPointsConfig
    needs_canonical = False

    def scatterers(
        self, motion: Motion, skeleton: Skeleton, radar_position: Any, wavelength: float
    ) -> Scatterers:
        """One point per joint, its RCS :func:`swinging_rcs` at the block's times."""
        rcs = swinging_rcs(skeleton.time, skeleton.n_joints, self.config.rcs_swing)
        return Scatterers(skeleton.positions, rcs, skeleton.joint_names)


def _reference_radar(body: Skeleton) -> ReferenceRadar:
    return ReferenceRadar(ReferenceRadar.Config(prf=1.0 / _step(body.time)))


def _invariant(
    who: str,
    model: ScattererModel,
    waveform: RadarWaveform,
    body: Skeleton,
    effects: tuple[Effect, ...] = (),
) -> None:
    try:
        check_block_invariance(model, waveform, body, walking_motion(), effects)
    except AssertionError as exc:
        raise AssertionError(f"{who}: {exc}") from None


def check_scatterer_model_blocks(model: ScattererModel) -> None:
    """A walking body's scatterers (and the reference radar's signal) are the same whether the
    record comes as one block or in blocks of 37 pulses."""
    motion = walking_motion()
    body = motion.canonical() if model.needs_canonical else motion.skeleton
    _invariant(_label(model), model, _reference_radar(body), body)


def check_radar_waveform_blocks(waveform: RadarWaveform) -> None:
    """The waveform's signal for a walking body (unit points at its joints, at the waveform's own
    pulse times) is the same whether the record comes as one block or in blocks of 37 pulses."""
    t = waveform.pulse_times(0.0, 0.25)
    pos = walking_positions(t)
    pos[:, :, 0] -= 2.0  # 12 m from the radar at the start, approaching
    body = Skeleton(t, pos, CANONICAL_JOINTS)
    _invariant(_label(waveform), JointPoints(JointPoints.Config()), waveform, body)


# --------------------------------------------------------------------------- recordings


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
    (``skeleton``: the body at the pulse times, in the scene frame). Each pass starts as a run
    starts a record: ``start_record`` of the model, of every scatterer-stage effect (with
    ``skeleton``) and of the waveform, so an effect may carry state across blocks and reset it
    there. A failure names the first stage whose output differs: the model, an effect (in
    their order) or, when the scatterers agree, the waveform."""
    radar_position = RADAR_POSITION.copy()
    lam = float(radar.wavelength(waveform.carrier_frequency))
    t = skeleton.time
    span = np.linalg.norm(skeleton.positions - radar_position, axis=-1)
    scatterer_effects = tuple(e for e in effects if e.stage == "scatterers")
    stages = [f"scatterer model {model.name!r}"]
    stages += [f"effect {e.name!r}" for e in scatterer_effects]

    def cut(size: int) -> int:  # blocks hold a multiple of the waveform's block_multiple
        return max(waveform.block_multiple, size - size % waveform.block_multiple)

    def run(size: int) -> tuple[list[list[Scatterers]], np.ndarray]:
        model.start_record(skeleton)
        for effect in scatterer_effects:
            effect.start_record(skeleton, radar_position)
        waveform.start_record(t, (float(span.min()), float(span.max())))
        outputs: list[list[Scatterers]] = [[] for _ in stages]  # per stage, per block
        signal_parts = []
        for lo in range(0, t.shape[0], cut(size)):
            sk = skeleton.select_frames(slice(lo, lo + cut(size)))
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
            _check_block_output(stages[0], scat, sk.n_frames, lo, outputs[0])
            outputs[0].append(scat)
            for i, effect in enumerate(scatterer_effects, start=1):
                scat = effect.apply(scat, ctx)
                _check_block_output(stages[i], scat, sk.n_frames, lo, outputs[i])
                outputs[i].append(scat)
            ranges = scat.ranges(radar_position)
            rec = waveform.receive(PulseBlock(lo, sk.time, scat, ranges, gate, radar_position))
            signal_parts.append(rec.signal)
        return outputs, np.concatenate(signal_parts)

    one, sig_one = run(t.shape[0])
    many, sig_many = run(block)
    step = cut(block)
    for name, whole, blocks in zip(stages, one, many, strict=True):
        _compare_blocks(name, whole, blocks, step)
    scale = float(np.max(np.abs(sig_one))) or 1.0
    assert np.max(np.abs(sig_one - sig_many)) <= 1e-9 * scale, (
        f"received signal differs between one block and blocks of {step} pulses although the "
        f"scatterers agree: the radar {waveform.name!r} is not block-invariant"
    )


def _check_block_output(
    stage: str, scat: Any, n_pulses: int, start: int, earlier: list[Scatterers]
) -> None:
    """One block's output of a stage: Scatterers, one row per pulse, and the same scatterers
    (names) as the stage's earlier blocks."""
    where = f"the block at pulse {start}"
    made = "scatterers()" if stage.startswith("scatterer model") else "apply()"
    assert isinstance(scat, Scatterers), (
        f"{stage}: {made} must return Scatterers, got {type(scat).__name__} for {where}"
    )
    rows = scat.positions.shape[0]
    assert rows == n_pulses, (
        f"{stage}: {made} must give one row per pulse: {rows} rows for the {n_pulses} "
        f"pulses of {where}"
    )
    if earlier and scat.names != earlier[0].names:
        k0, k = len(earlier[0].names), len(scat.names)
        raise AssertionError(
            f"{stage}: every block must have the same scatterers, but it gives {k0} "
            f"scatterers in the block at pulse 0 and {k} ({', '.join(scat.names[:5])}...) "
            f"in {where}: it is not block-invariant"
        )


def _compare_blocks(
    stage: str, whole: list[Scatterers], blocks: list[Scatterers], step: int
) -> None:
    """A stage's output for the record as one block (``whole``: one block, or two when the
    record is no multiple of the waveform's ``block_multiple``) against its output in
    blocks of ``step`` pulses."""
    how = f"for the record as one block and in blocks of {step} pulses"
    fix = (
        "it is not block-invariant (take record-wide quantities in start_record, reset what it "
        "accumulates there, and take the pulse index from context.block_start)"
    )
    k_whole, k_blocks = len(whole[0].names), len(blocks[0].names)
    assert whole[0].names == blocks[0].names, (
        f"{stage} gives {k_whole} scatterers for the record as one block but {k_blocks} in "
        f"blocks of {step} pulses: {fix}"
    )
    for field_name in ("positions", "rcs"):
        a = np.concatenate([getattr(s, field_name) for s in whole])
        b = np.concatenate([getattr(s, field_name) for s in blocks])
        if not np.allclose(a, b, rtol=1e-12, atol=0):
            worst = float(np.max(np.abs(a - b)))
            unit = "m" if field_name == "positions" else "m^2"
            raise AssertionError(
                f"{stage} gives different scatterer {field_name} {how} (by up to "
                f"{worst:.3g} {unit}): {fix}"
            )


def check_recording_source(source: RecordingSource) -> list[Recording]:
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


# --------------------------------------------------------------------------- the suite


#: interface -> the checks of its instances (besides the class check and the config round trip)
INSTANCE_CHECKS: dict[str, tuple[Check, ...]] = {
    "motion": (check_motion_source,),
    "scatterers": (check_scatterer_model, check_scatterer_model_blocks),
    "radar": (check_radar_waveform, check_radar_waveform_blocks),
    "classifier": (check_classifier,),
    "effects": (check_effect,),
    "recording": (check_recording_source,),
}


def _instance(plugin: Plugin | type[Plugin]) -> Plugin:
    if isinstance(plugin, Plugin):
        return plugin
    who, name = _label(plugin), plugin.__name__
    config = getattr(plugin, "Config", None)
    if config is None:
        raise AssertionError(
            f"{who} has no Config: give it one, a subclass of mdframework.PluginConfig with "
            f"kind: Literal[{getattr(plugin, 'name', '?')!r}]"
        )
    if not (isinstance(config, type) and issubclass(config, PluginConfig)):
        raise AssertionError(f"{who}: its Config must subclass mdframework.PluginConfig")
    try:
        instance = config()  # type: ignore[call-arg]
    except ValidationError as exc:
        missing = [".".join(map(str, e["loc"])) for e in exc.errors() if e["type"] == "missing"]
        if missing:
            raise AssertionError(
                f"{who}: its Config has required fields ({', '.join(missing)}); pass an "
                f"instance ({name}({name}.Config(...))) to the checks"
            ) from exc
        raise AssertionError(f"{who}: its Config's defaults are not valid: {exc}") from exc
    return plugin(instance)


def _class_check(plugin: Plugin) -> None:
    check_plugin_class(type(plugin))


def plugin_checks(plugin: Plugin | type[Plugin]) -> list[Check]:
    """The checks of one plugin (an instance, or a class whose default Config is valid), in
    order: the class contract, the config round trip, then its interface's checks. Each check
    takes the instance; its ``__name__`` names it."""
    cls = plugin if isinstance(plugin, type) else type(plugin)
    interface = _interface_of(cls)
    checks: list[Check] = [_named(_class_check, "check_plugin_class"), check_config_round_trip]
    return checks + list(INSTANCE_CHECKS[interface])


def _named(func: Check, name: str) -> Check:
    wrapped = partial(func)
    wrapped.__name__ = name  # type: ignore[attr-defined]
    return wrapped


def check_plugin(plugin: Plugin | type[Plugin]) -> None:
    """Run every check of ``plugin`` (see :func:`plugin_checks`); the first failure raises
    ``AssertionError`` naming the plugin and the check."""
    instance = _instance(plugin)
    for check in plugin_checks(instance):
        try:
            check(instance)
        except AssertionError as exc:
            name = getattr(check, "__name__", "check")
            raise AssertionError(f"{_label(instance)} fails {name}: {exc}") from exc


def parametrize_with_checks(plugins: Sequence[Plugin | type[Plugin]]) -> Any:
    """A ``pytest.mark.parametrize`` decorator over (plugin instance, check) pairs, with ids
    ``<kind>-<check name>``; the test body calls ``check(plugin)``."""
    import pytest

    cases: list[Any] = []
    for plugin in plugins:
        instance = _instance(plugin)
        for check in plugin_checks(instance):
            name = getattr(check, "__name__", "check")
            cases.append(pytest.param(instance, check, id=f"{instance.name}-{name}"))
    return pytest.mark.parametrize(("plugin", "check"), cases)


# --------------------------------------------------------------------------- old names


def _deprecated(old: str, new: Callable[..., Any]) -> Callable[..., Any]:
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        warnings.warn(
            f"mdframework.testing.{old} is deprecated: use {new.__name__}",
            DeprecationWarning,
            stacklevel=2,
        )
        return new(*args, **kwargs)

    wrapper.__name__ = old
    wrapper.__doc__ = f"Deprecated spelling of :func:`{new.__name__}`."
    return wrapper


def _check_effect_class(cls: type[Effect]) -> None:
    check_plugin_class(cls, "effects")
    assert getattr(cls, "stage", None) in ("scatterers", "received"), (
        f"{cls.__name__}.stage must be 'scatterers' or 'received'"
    )


check_waveform = _deprecated("check_waveform", check_radar_waveform)
check_effect_class = _deprecated("check_effect_class", _check_effect_class)

__all__ = [
    "INSTANCE_CHECKS",
    "RADAR_POSITION",
    "Check",
    "JointPoints",
    "ReferenceRadar",
    "check_block_invariance",
    "check_classifier",
    "check_config_round_trip",
    "check_effect",
    "check_motion_source",
    "check_plugin",
    "check_plugin_class",
    "check_radar_waveform",
    "check_radar_waveform_blocks",
    "check_recording_source",
    "check_scatterer_model",
    "check_scatterer_model_blocks",
    "parametrize_with_checks",
    "plugin_checks",
    "scene_context",
    "standing_body",
    "walking_motion",
    "walking_positions",
]
