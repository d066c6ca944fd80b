"""Metamorphic and property-based tests of the physics: relations between runs that must hold
whatever the inputs (drawn by Hypothesis, derandomized, a few dozen small examples each).

- time reversal of a motion reverses the slow-time signal and mirrors the spectrogram in
  Doppler (LFM, CW; points, and a body moving in place through the ellipsoid model and the
  scatterer effects); reversing a constant velocity mirrors the Doppler in every radar (FMCW);
- an approaching point has positive Doppler and a receding one negative, in every radar;
- moving a radial scene along its line of sight by ``d`` multiplies the return by
  ``exp(-j 4 pi f_c d / c)`` and, with the range equation, by ``(R / (R + d))^2`` (LFM, CW);
- turning scene and radar together about any axis leaves the return unchanged (LFM, CW; FMCW
  about the vertical through the origin, at which it looks), and seeing a body from another
  bearing at the same aspect leaves it unchanged too;
- a record cut at ``motion.start = s`` equals the motion started where it is at ``s`` (every
  radar and effect: the physics has no clock);
- the dB map does not depend on the transmit power (every radar; noise and clutter by SNR, CSR),
  thermal noise neither, while clutter set by an RCS follows it as an echo does;
- a record cut from a recording is that part of the whole record's signal;
- scaling the carrier scales the Doppler of a constant velocity by the same factor;
- any ``processing.block_pulses`` gives the run of one block, for every radar and effect;
- a record resampled from its window equals resampling the whole recording (1e-9 m);
- the return of two scatterers is the sum of their returns (every radar, no nonlinear step);
- the torso feature is the hip centre's radial speed from any aspect (its sign the walk's);
- the seven features ignore a constant gain, follow a mirror of the Doppler axis and a shift
  of the velocity axis, and ignore the order of the frames.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st
from scenes import effect_sections, load_project_modules

from mdframework import CANONICAL_JOINTS, Motion, Skeleton
from mdframework.config import validate_run_config
from mdframework.constants import SPEED_OF_LIGHT
from mdframework.features import FEATURE_NAMES, spectrogram_features
from mdframework.physics import interpolation
from mdframework.physics.spectrogram import power_to_db
from mdframework.pipeline import RunResult, build_stages, simulate_motion
from mdframework.testing import walking_positions

# Hypothesis also draws constants of the loaded modules: the same examples whatever ran before
load_project_modules()

#: Every test draws its examples deterministically (no database, no random seed).
SETTINGS = settings(
    max_examples=25,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)

#: The radars with a slow-time signal that is a plain function of the ranges (LFM, CW), with
#: their pulse rates [Hz]; FMCW takes its own chirp timing.
LFM = {"kind": "lfm", "precision": "float64"}
CW = {"kind": "cw"}
#: A small FMCW radar (64 ADC samples: 0.4 m range cells under a 4 m gate; 25 m reach).
FMCW = {
    "kind": "fmcw",
    "points": False,
    "save_range_doppler": False,
    "n_samples": 64,
    "gate_width": 4.0,
}


def run_config(
    radar: dict[str, Any],
    *,
    scene: dict[str, Any] | None = None,
    processing: dict[str, Any] | None = None,
    effects: list[dict[str, Any]] | None = None,
    scatterers: dict[str, Any] | None = None,
    targets: list[dict[str, Any]] | None = None,
    length: float = 0.5,
) -> Any:
    """A validated run config: point targets (or the motion given to :func:`simulate_tracks`)
    seen from the origin, float64 spectrogram."""
    return validate_run_config(
        {
            "seed": 7,
            "motion": {
                "kind": "point_targets",
                "length": length,
                "targets": targets or [{"position": [10.0, 0.0, 0.0]}],
            },
            "scatterers": scatterers or {"kind": "points"},
            "radar": radar,
            "effects": effects or [],
            "scene": {"radar_position": [0.0, 0.0, 0.0], **(scene or {})},
            "processing": {"precision": "float64", **(processing or {})},
        }
    )


def body_config(
    radar: dict[str, Any],
    scatterers: dict[str, Any],
    effects: list[dict[str, Any]] | None = None,
    *,
    aspect_deg: float = 20.0,
    radar_position: list[float] | None = None,
    block_pulses: int = 4096,
) -> Any:
    """A run config of a body (the motion given to :func:`simulate_tracks`) placed at the
    origin at ``aspect_deg`` to the radar (default at (6, 1, 1.5) m), a tracking gate."""
    return run_config(
        radar,
        scatterers=scatterers,
        effects=effects,
        scene={
            "radar_position": radar_position or [6.0, 1.0, 1.5],
            "person": {"position": [0.0, 0.0], "aspect_deg": aspect_deg},
            "gate": "track",
        },
        processing={"window_length": 64, "hop": 32, "block_pulses": block_pulses},
    )


def simulate_points(cfg: Any) -> RunResult:
    """Simulate a config of constant-velocity point targets (its own source)."""
    stages = build_stages(cfg)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # an empty fixed gate, a warned aliasing
        return simulate_motion(cfg, stages, stages.source.load())


def simulate_tracks(
    cfg: Any, time: np.ndarray, positions: np.ndarray, rcs: np.ndarray | None = None
) -> RunResult:
    """Simulate point scatterers on the given tracks: ``time`` (n,) [s], ``positions``
    (n, k, 3) [m], one RCS per point (default 1 m^2). The tracks are resampled to the pulses by
    the pipeline's interpolation (cubic by default), as any recording's."""
    k = positions.shape[1]
    if positions.shape[1] == len(CANONICAL_JOINTS):
        names, mapping = CANONICAL_JOINTS, {j: j for j in CANONICAL_JOINTS}
    else:
        names, mapping = tuple(f"p{i}" for i in range(k)), None
    rcs = np.ones(k) if rcs is None else rcs
    motion = Motion(Skeleton(time, positions, names), {"source": "test"}, mapping, rcs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return simulate_motion(cfg, build_stages(cfg), motion)


def mirror_rows(doppler: np.ndarray) -> np.ndarray:
    """Row index of ``-f`` for each row ``f`` of an ascending two-sided Doppler axis of bins
    ``k = -(N // 2) .. N - N // 2 - 1`` (the bin ``-N/2`` of an even ``N`` is its own mirror,
    ``+N/2`` being the same frequency)."""
    n = doppler.size
    k = np.arange(-(n // 2), n - n // 2)
    return (-k - k[0]) % n


def peak_doppler(result: RunResult) -> np.ndarray:
    """The Doppler [Hz] of each spectrogram frame's strongest bin."""
    return result.spectrogram.doppler[np.argmax(result.spectrogram.power, axis=0)]


def unit(v: np.ndarray) -> np.ndarray:
    return np.asarray(v / np.linalg.norm(v), dtype=np.float64)


directions = st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-0.5, 0.5)).filter(
    lambda d: np.hypot(d[0], d[1]) > 0.3
)


def effect_lists() -> st.SearchStrategy[list[dict[str, Any]]]:
    """Any subset of the built-in effects in a valid order (the random scenes' effects), clutter
    with a range resolution (the CW and FMCW radars have none of their own)."""
    return effect_sections().map(
        lambda effects: [
            {**e, "range_resolution": 1.0} if e["kind"] == "clutter" else e for e in effects
        ]
    )


def scatterer_effects() -> st.SearchStrategy[list[dict[str, Any]]]:
    """Any subset of the effects on the scatterers (multipath, antenna, attenuation)."""
    return effect_lists().map(
        lambda effects: [e for e in effects if e["kind"] not in ("noise", "clutter")]
    )


def body_models() -> st.SearchStrategy[dict[str, Any]]:
    """The ellipsoid body models: ``ellipsoid`` (any placement, head, phase) or ``mujoco_body``."""
    return st.one_of(
        st.fixed_dictionaries(
            {
                "kind": st.just("ellipsoid"),
                "placement": st.sampled_from(["joints17", "chen16"]),
                "head": st.sampled_from(["sphere", "spheroid"]),
                "scattering_phase": st.sampled_from(["centre", "specular"]),
            }
        ),
        st.fixed_dictionaries(
            {"kind": st.just("mujoco_body"), "placement": st.sampled_from(["centres", "chen16"])}
        ),
    )


def body_effects() -> st.SearchStrategy[list[dict[str, Any]]]:
    """:func:`scatterer_effects`, after the body's self-shadowing or not."""
    return st.tuples(st.booleans(), scatterer_effects()).map(
        lambda s: [{"kind": "shadowing"}, *s[1]] if s[0] else s[1]
    )


# --------------------------------------------------------------------------- time reversal


@st.composite
def wobbling_tracks(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray]:
    """1 to 3 points 5 to 40 m from the origin, each drifting and oscillating (accelerating,
    radially up to about 3 m/s), on frames over 0 .. 0.5 s that are symmetric in time."""
    frame_rate = draw(st.sampled_from([30.0, 60.0, 100.0, 120.0]))
    t = np.arange(round(0.5 * frame_rate) + 1) / frame_rate
    tracks = []
    for _ in range(draw(st.integers(1, 3))):
        u = unit(np.array(draw(directions)))
        r0 = draw(st.floats(5.0, 40.0))
        drift = np.array([draw(st.floats(-1.0, 1.0)) for _ in range(3)])
        amp = np.array([draw(st.floats(0.0, 0.1)) for _ in range(3)])
        freq = draw(st.floats(0.5, 3.0))
        phase = draw(st.floats(0.0, 2 * np.pi))
        wobble = amp[None] * np.sin(2 * np.pi * freq * t + phase)[:, None]
        tracks.append(r0 * u[None] + drift[None] * t[:, None] + wobble)
    return t, np.stack(tracks, axis=1)


@st.composite
def reversible_radars(draw: st.DrawFn) -> tuple[dict[str, Any], dict[str, Any]]:
    """An LFM (either path, any gate response) or CW radar, and an STFT whose frames are
    symmetric in the 0.5 s record (the record's samples less one window are a whole number of
    hops) with a boxcar window (the periodic cosine windows are not symmetric)."""
    radar = draw(
        st.one_of(
            st.builds(
                lambda response, path: {**LFM, "gate_response": response, "path": path},
                st.sampled_from(["exact", "sinc", "phase_only"]),
                st.sampled_from(["analytic", "analytic", "raw"]),
            ),
            st.just(CW),
        )
    )
    hop = draw(st.sampled_from([4, 8, 25, 40, 50, 100]))  # divide 1200 (LFM) and 1000 (CW)
    window = hop * draw(st.integers(1, max(1, 400 // hop))) + 1
    nfft = draw(st.integers(window, 2 * window))
    processing = {"window": "boxcar", "window_length": window, "hop": hop, "nfft": nfft}
    return radar, processing


@SETTINGS
@given(wobbling_tracks(), reversible_radars())
def test_time_reversal_reverses_the_signal_and_mirrors_the_doppler(
    tracks: tuple[np.ndarray, np.ndarray], radar_stft: tuple[dict[str, Any], dict[str, Any]]
) -> None:
    """Playing a motion backwards (the frames reversed on the same times) plays the slow-time
    signal backwards, ``y'(n) = y(N - 1 - n)``, so every spectrogram frame ``m`` of the reversed
    run is frame ``M - 1 - m`` of the forward run mirrored in Doppler, ``P'(f) = P(-f)``, and
    the Doppler of each frame's peak changes sign."""
    t, pos = tracks
    radar, processing = radar_stft
    cfg = run_config(radar, processing=processing, scene={"gate": "track"})
    forward = simulate_tracks(cfg, t, pos)
    backward = simulate_tracks(cfg, t, pos[::-1].copy())
    y, y_rev = forward.received.signal, backward.received.signal
    scale = np.max(np.abs(y))
    assert scale > 0
    assert np.max(np.abs(y_rev - y[::-1])) < 1e-9 * scale
    p, p_rev = forward.spectrogram.power, backward.spectrogram.power
    mirrored = p[mirror_rows(forward.spectrogram.doppler)][:, ::-1]
    assert np.max(np.abs(p_rev - mirrored)) < 1e-8 * np.max(p)
    # the peaks' Doppler changes sign (where a frame's peak is clear of its runner-up)
    f, f_rev = peak_doppler(forward), peak_doppler(backward)[::-1]
    top2 = np.sort(p, axis=0)[-2:]
    clear = top2[1] > 1.01 * top2[0]
    doppler_bin = forward.spectrogram.doppler[1] - forward.spectrogram.doppler[0]
    even = forward.spectrogram.doppler.size % 2 == 0
    edge = even & (np.abs(f) >= forward.spectrogram.doppler[-1] + doppler_bin / 2)
    assert np.allclose(f_rev[clear & ~edge], -f[clear & ~edge], atol=1e-9)


# --------------------------------------------------------------------------- Doppler sign


@st.composite
def moving_points(draw: st.DrawFn) -> tuple[list[float], list[float], float]:
    """A point 4 to 8 m from the radar at the origin moving mostly along the line of sight, its
    radial speed 0.5 to 3 m/s (the sign drawn), a crossing component up to 0.3 of it; the
    radial velocity [m/s] (+ approaching) at the start."""
    u = unit(np.array(draw(directions)))
    r0 = draw(st.floats(4.0, 8.0))
    speed = draw(st.floats(0.5, 3.0)) * draw(st.sampled_from([-1.0, 1.0]))
    side = unit(np.cross(u, [0.0, 0.0, 1.0]))
    cross = draw(st.floats(-0.3, 0.3)) * abs(speed)
    velocity = -speed * u + cross * side
    return list(r0 * u), list(velocity), speed


def any_radar() -> st.SearchStrategy[dict[str, Any]]:
    """LFM (both paths), CW or FMCW (both paths)."""
    return st.sampled_from(
        [
            LFM,
            {**LFM, "path": "raw"},
            CW,
            FMCW,
            {**FMCW, "path": "raw"},
        ]
    )


@SETTINGS
@given(moving_points(), any_radar())
def test_an_approaching_point_has_positive_doppler_and_a_receding_one_negative(
    point: tuple[list[float], list[float], float], radar: dict[str, Any]
) -> None:
    """docs/concepts.md: an approaching target has positive Doppler, in every radar; and the
    motion reversed (the velocity negated, from the end point) mirrors every frame's peak."""
    position, velocity, v_radial = point
    length = 0.5
    cfg = run_config(
        radar,
        targets=[{"position": position, "velocity": velocity}],
        scene={"gate": "track"},
        processing={"window_length": 64, "hop": 32},
        length=length,
    )
    res = simulate_points(cfg)
    f = peak_doppler(res)
    assert np.all(np.sign(f) == np.sign(v_radial)), (f, v_radial)
    # at the end of the record the radial speed has changed by the crossing motion only: the
    # peak lies within the Doppler of the radial speeds over the record (and two bins)
    lam = SPEED_OF_LIGHT / res.metadata["carrier_frequency_hz"]
    end = np.array(position) + length * np.array(velocity)
    v_end = -float(np.dot(velocity, unit(end)))
    lo, hi = sorted((2 * v_radial / lam, 2 * v_end / lam))
    step = res.spectrogram.doppler[1] - res.spectrogram.doppler[0]
    window = res.metadata["prf_hz"] / 64
    assert np.all((f >= lo - window - step) & (f <= hi + window + step)), (f, lo, hi)
    back = run_config(
        radar,
        targets=[{"position": list(end), "velocity": list(-np.array(velocity))}],
        scene={"gate": "track"},
        processing={"window_length": 64, "hop": 32},
        length=length,
    )
    f_back = peak_doppler(simulate_points(back))
    assert np.all(np.sign(f_back) == -np.sign(v_radial))
    # frame for frame (FMCW frames are not symmetric in the record: within a frame's Doppler
    # span of the mirrored radial speed)
    assert np.all(np.abs(f_back + f[::-1]) <= abs(hi - lo) + 2 * step + 1e-9)


# --------------------------------------------------------------------------- translation


@st.composite
def radial_scenes(draw: st.DrawFn) -> dict[str, Any]:
    """Points on one ray from the radar (at the origin) moving along it, a shift ``d`` along
    the ray, an LFM (analytic, any gate response; a fixed or tracking gate) or CW radar. With
    the range equation, one point (the factor ``(R / (R + d))^2`` is then the same for all)."""
    u = unit(np.array(draw(directions)))
    amplitude = draw(st.sampled_from(["range_equation", "sqrt_rcs"]))
    n = 1 if amplitude == "range_equation" else draw(st.integers(1, 3))
    targets = [
        {
            "position": list(draw(st.floats(5.0, 60.0)) * u),
            "velocity": list(draw(st.floats(-3.0, 3.0)) * u),
            "rcs": draw(st.floats(0.1, 2.0)),
        }
        for _ in range(n)
    ]
    radar = draw(
        st.sampled_from(
            [
                {**LFM, "gate_response": "exact"},
                {**LFM, "gate_response": "sinc"},
                {**LFM, "gate_response": "phase_only"},
                CW,
            ]
        )
    )
    return {
        "radar": {**radar, "amplitude": amplitude},
        "targets": targets,
        "u": u,
        "shift": draw(st.floats(-4.0, 500.0)),
        "gate": draw(st.sampled_from(["track", "fixed"])),
    }


@SETTINGS
@given(radial_scenes())
def test_moving_a_radial_scene_along_the_line_of_sight_only_turns_and_scales_the_return(
    s: dict[str, Any],
) -> None:
    """Every range grows by ``d``: the return turns by the carrier phase of ``2 d`` and, with
    the range equation, scales by ``(R / (R + d))^2`` (the ``R^-4`` of the power); the gate's
    weights depend on range differences only. So the Doppler content (the spectrogram's
    power, up to that scale) does not change."""
    d = s["shift"]

    def run(offset: float) -> RunResult:
        targets = [
            {**tg, "position": list(np.array(tg["position"]) + offset * s["u"])}
            for tg in s["targets"]
        ]
        r0 = float(np.linalg.norm(targets[0]["position"]))
        gate = "track" if s["gate"] == "track" else r0
        return simulate_points(run_config(s["radar"], targets=targets, scene={"gate": gate}))

    near, far = run(0.0), run(d)
    y, y_far = near.received.signal, far.received.signal
    f_c = near.metadata["carrier_frequency_hz"]
    turn = np.exp(-4j * np.pi * f_c * d / SPEED_OF_LIGHT)
    expected = y * turn
    if s["radar"]["amplitude"] == "range_equation":
        tg = s["targets"][0]
        r = np.linalg.norm(
            np.array(tg["position"]) + near.pulse_times[:, None] * np.array(tg["velocity"]),
            axis=1,
        )
        expected *= (r / (r + d)) ** 2
    scale = np.max(np.abs(expected))
    assert np.max(np.abs(y_far - expected)) < 1e-7 * scale
    if s["radar"]["amplitude"] == "sqrt_rcs":
        p, p_far = near.spectrogram.power, far.spectrogram.power
        assert np.max(np.abs(p_far - p)) < 1e-6 * np.max(p)


# --------------------------------------------------------------------------- rotation


def rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """The rotation matrix (3, 3) by ``angle`` [rad] about ``axis`` (Rodrigues)."""
    k = unit(axis)
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * kx + (1.0 - np.cos(angle)) * (kx @ kx)


@SETTINGS
@given(
    st.lists(
        st.tuples(
            st.tuples(*[st.floats(-20.0, 20.0)] * 3),
            st.tuples(*[st.floats(-2.0, 2.0)] * 3),
        ),
        min_size=1,
        max_size=3,
    ),
    st.tuples(*[st.floats(-30.0, 30.0)] * 3),
    st.tuples(*[st.floats(-1.0, 1.0)] * 3).filter(lambda a: np.linalg.norm(a) > 0.1),
    st.floats(-np.pi, np.pi),
    st.sampled_from([LFM, {**LFM, "gate_response": "sinc"}, {**LFM, "path": "raw"}, CW]),
)
def test_turning_scene_and_radar_together_leaves_the_return_unchanged(
    points: list[tuple[tuple[float, ...], tuple[float, ...]]],
    radar_at: tuple[float, ...],
    axis: tuple[float, ...],
    angle: float,
    radar: dict[str, Any],
) -> None:
    """An isotropic point scene and the radar turned together about any axis through the
    origin: every range is the same, so is the return (LFM, CW: no antenna orientation)."""
    radar_pos = np.array(radar_at)
    pos = np.array([p for p, _ in points])
    vel = np.array([v for _, v in points])
    end = pos + 0.5 * vel
    assume(np.all(np.linalg.norm(pos - radar_pos, axis=1) > 3.0))
    assume(np.all(np.linalg.norm(end - radar_pos, axis=1) > 3.0))
    rot = rotation(np.array(axis), angle)

    def run(r: np.ndarray) -> RunResult:
        targets = [
            {"position": list(r @ p), "velocity": list(r @ v)}
            for p, v in zip(pos, vel, strict=True)
        ]
        scene = {"radar_position": list(r @ radar_pos), "gate": "track"}
        return simulate_points(run_config(radar, targets=targets, scene=scene))

    y, y_turned = run(np.eye(3)).received.signal, run(rot).received.signal
    assert np.max(np.abs(y_turned - y)) < 1e-7 * np.max(np.abs(y))


@settings(SETTINGS, max_examples=15)
@given(
    st.lists(
        st.tuples(
            st.tuples(*[st.floats(-3.0, 3.0)] * 2, st.floats(0.0, 2.0)),
            st.tuples(*[st.floats(-1.5, 1.5)] * 3),
        ),
        min_size=1,
        max_size=3,
    ),
    st.floats(5.0, 12.0),
    st.floats(-180.0, 180.0),
    st.floats(0.0, 2.5),
    st.floats(-np.pi, np.pi),
    st.sampled_from(["analytic", "raw"]),
)
def test_turning_the_fmcw_scene_about_the_vertical_leaves_its_return_and_maps_unchanged(
    points: list[tuple[tuple[float, ...], tuple[float, ...]]],
    distance: float,
    bearing_deg: float,
    height: float,
    angle: float,
    path: str,
) -> None:
    """The FMCW sensor looks horizontally at the scene origin by default, so turning the scene
    and the radar about the vertical through the origin turns the sensor with them: every
    antenna's delays, hence the slow-time signal and the range-Doppler maps, are unchanged."""
    b = np.deg2rad(bearing_deg)
    radar_pos = np.array([distance * np.cos(b), distance * np.sin(b), height])
    pos = np.array([p for p, _ in points])
    vel = np.array([v for _, v in points])
    rot = rotation(np.array([0.0, 0.0, 1.0]), angle)

    def run(r: np.ndarray) -> RunResult:
        targets = [
            {"position": list(r @ p), "velocity": list(r @ v)}
            for p, v in zip(pos, vel, strict=True)
        ]
        radar = {**FMCW, "path": path, "save_range_doppler": True}
        scene = {"radar_position": list(r @ radar_pos), "gate": "track"}
        return simulate_points(run_config(radar, targets=targets, scene=scene))

    one, turned = run(np.eye(3)), run(rot)
    y, y_turned = one.received.signal, turned.received.signal
    assert np.max(np.abs(y_turned - y)) < 1e-7 * np.max(np.abs(y))
    maps, maps_turned = (
        one.received.products["range_doppler"],
        turned.received.products["range_doppler"],
    )
    assert np.max(np.abs(maps_turned - maps)) < 1e-5 * np.max(maps)


@settings(SETTINGS, max_examples=10)
@given(
    st.floats(-180.0, 180.0),
    st.floats(-180.0, 180.0),
    st.floats(4.0, 15.0),
    st.floats(0.5, 3.0),
    body_models(),
    body_effects(),
)
def test_a_body_seen_from_another_bearing_at_the_same_aspect_gives_the_same_return(
    bearing_deg: float,
    aspect_deg: float,
    distance: float,
    height: float,
    model: dict[str, Any],
    effects: list[dict[str, Any]],
) -> None:
    """The scene turned about the vertical through the person: the radar at another bearing,
    the person placed at the same aspect to it. The ellipsoids' RCS depend on the line of
    sight in each part's frame only, the ground (multipath) is horizontal, the antenna aims at
    the body, the parts hide each other as before: the return is the same."""
    t = np.arange(31) / 60.0
    motion = walking_positions(t, speed=1.2)

    def run(bearing: float) -> RunResult:
        b = np.deg2rad(bearing)
        radar_pos = [distance * np.cos(b), distance * np.sin(b), height]
        cfg = body_config(LFM, model, effects, aspect_deg=aspect_deg, radar_position=radar_pos)
        return simulate_tracks(cfg, t, motion)

    y, y_turned = run(0.0).received.signal, run(bearing_deg).received.signal
    assert np.max(np.abs(y_turned - y)) < 1e-7 * np.max(np.abs(y))


# --------------------------------------------------------------------------- carrier


@SETTINGS
@given(
    moving_points(),
    st.floats(1e9, 20e9),
    st.sampled_from([2.0, 3.0, 0.5]),
    st.sampled_from(["lfm", "cw"]),
)
def test_scaling_the_carrier_scales_the_doppler_of_a_constant_velocity(
    point: tuple[list[float], list[float], float], carrier: float, factor: float, kind: str
) -> None:
    """``f_D = 2 v f_c / c``: the same motion at ``k f_c`` has ``k`` times the Doppler, from the
    mean pulse-to-pulse phase increment (to 1e-6) and at each frame's spectrogram peak (within
    the frequency resolution); the velocity axis then shows the same speed."""
    position, velocity, _ = point
    # far away (up to 8 km): the carrier phase must be reduced in float64 at any range
    far = list(np.array(position) * 1000.0)

    def run(f_c: float) -> RunResult:
        radar = {**(LFM if kind == "lfm" else CW), "carrier_frequency": f_c}
        radar["prf" if kind == "lfm" else "sample_rate"] = 1500.0
        cfg = run_config(
            radar,
            targets=[{"position": far, "velocity": velocity}],
            scene={"gate": "track"},
            processing={"window_length": 128, "hop": 64, "nfft": 1024},
        )
        return simulate_points(cfg)

    one, scaled = run(carrier), run(factor * carrier)
    assume(
        max(one.metadata["max_radial_speed_mps"], 1e-9)
        < scaled.metadata["max_unambiguous_velocity_mps"]
    )
    assume(one.metadata["max_radial_speed_mps"] < one.metadata["max_unambiguous_velocity_mps"])

    def increment(res: RunResult) -> float:
        y = res.received.signal
        return float(np.angle(np.sum(y[1:] * np.conj(y[:-1]))) * 1500.0 / (2 * np.pi))

    f1, fk = increment(one), increment(scaled)
    assert abs(fk - factor * f1) <= 1e-6 * abs(factor * f1)
    resolution = 1500.0 / 128
    assert np.all(
        np.abs(peak_doppler(scaled) - factor * peak_doppler(one)) <= (1 + factor) * resolution
    )
    v1 = one.velocity[np.argmax(one.spectrogram.power, axis=0)]
    vk = scaled.velocity[np.argmax(scaled.spectrogram.power, axis=0)]
    lam = SPEED_OF_LIGHT / carrier
    assert np.all(np.abs(vk - v1) <= resolution * lam / 2 * (1 + 1 / factor))


# --------------------------------------------------------------------------- blocks


@settings(SETTINGS, max_examples=20)
@given(
    st.one_of(any_radar(), st.just({**FMCW, "receiver_noise": True})),
    effect_lists(),
    st.one_of(
        st.none(),
        st.builds(
            lambda count, seed: {"kind": "static_scene", "count": count, "seed": seed},
            st.integers(1, 5),
            st.integers(0, 100),
        ),
    ),
    st.one_of(
        st.none(),
        st.builds(
            lambda d, bodies: {"kind": "shadowing", "decimation": d, "bodies": bodies},
            st.integers(1, 60),
            st.sampled_from(["auto", "capsules"]),
        ),
    ),
    st.sampled_from(["points", "ellipsoid", "mujoco_body"]),
    st.integers(16, 700),
)
# the last of the 721 pulses alone in a block, between two rays of every 7th pulse
@example(LFM, [], None, {"kind": "shadowing", "decimation": 7}, "ellipsoid", 16)
# the MuJoCo body's scatterers (their own class) given ground images and a room
@example(CW, [{"kind": "multipath"}], {"kind": "static_scene", "count": 2}, None, "mujoco_body", 99)
def test_any_block_size_gives_the_run_of_one_block(
    radar: dict[str, Any],
    effects: list[dict[str, Any]],
    room: dict[str, Any] | None,
    shadowing: dict[str, Any] | None,
    model: str,
    block: int,
) -> None:
    """docs/concepts.md: the slow-time signal stays within 1e-12 of its peak whatever
    ``processing.block_pulses``, for every radar (the FMCW receiver's noise included: seeded
    per frame), scatterer model and effect (an FMCW block holds whole frames: the pipeline
    rounds it up to one). Self-shadowing casts its rays on every d-th pulse of the record and
    holds them: a block may hold no such pulse."""
    t = np.arange(19) / 60.0  # 0.3 s
    motion = walking_positions(t, speed=1.5)
    scatterers = {"kind": model} if model != "points" else {"kind": "points", "body": True}
    if radar.get("receiver_noise"):  # the FMCW receiver's own noise (per frame) replaces it
        effects = [e for e in effects if e["kind"] != "noise"]
    # the room, then the body's self-shadowing (rays every d-th pulse of the record, the room
    # among the scatterers it can hide), before the effects on every scatterer
    effects = [e for e in (room, shadowing) if e is not None] + effects

    def run(block_pulses: int) -> RunResult:
        cfg = body_config(radar, scatterers, effects, block_pulses=block_pulses)
        return simulate_tracks(cfg, t, motion)

    one, cut = run(1_000_000), run(block)
    y, y_cut = one.received.signal, cut.received.signal
    assert np.max(np.abs(y)) > 0
    assert np.max(np.abs(y_cut - y)) <= 1e-12 * np.max(np.abs(y))
    assert np.array_equal(one.gate_range, cut.gate_range)


# --------------------------------------------------------------------------- reversal, clock, power


@settings(SETTINGS, max_examples=15)
@given(
    st.floats(0.5, 2.0),
    st.floats(5.0, 40.0),
    body_models(),
    body_effects(),
    st.sampled_from([LFM, {**LFM, "gate_response": "sinc"}, CW]),
    st.floats(-180.0, 180.0),
)
def test_a_body_moving_in_place_played_backwards_gives_the_signal_backwards(
    cadence: float,
    swing: float,
    model: dict[str, Any],
    effects: list[dict[str, Any]],
    radar: dict[str, Any],
    aspect: float,
) -> None:
    """A body swinging its limbs in place (placed as the forward motion is: its hips face the
    same way, its hip centre starts at the same point), played backwards: every part's
    position and orientation run backwards, so do its RCS, specular point, shadows, ground
    image, antenna gain and attenuation, and the slow-time signal runs backwards. (A body
    that travels is placed by its direction of travel and start point, which reversal
    changes.)"""
    t = np.arange(31) / 60.0
    pos = walking_positions(t, speed=0.0, swing_deg=swing, cadence_hz=cadence)
    cfg = body_config(radar, model, effects, aspect_deg=aspect)
    forward = simulate_tracks(cfg, t, pos)
    backward = simulate_tracks(cfg, t, pos[::-1].copy())
    y = forward.received.signal
    assert np.max(np.abs(y)) > 0
    assert np.max(np.abs(backward.received.signal - y[::-1])) < 1e-9 * np.max(np.abs(y))


@settings(SETTINGS, max_examples=20)
@given(
    st.tuples(*[st.floats(-1.5, 1.5)] * 3),
    st.integers(1, 60),
    st.one_of(any_radar(), st.just({**FMCW, "receiver_noise": True})),
    effect_lists(),
)
def test_a_record_cut_later_from_a_motion_equals_the_motion_started_there(
    velocity: tuple[float, ...],
    frames: int,
    radar: dict[str, Any],
    effects: list[dict[str, Any]],
) -> None:
    """The physics does not depend on the clock: a 0.5 s record cut at ``motion.start = s``
    from points moving at constant velocity is the record of the same points placed where they
    are at ``s`` and started there, to rounding, for every radar and effect (the random ones
    seeded per record, the FMCW receiver's noise per frame of the record). The start is a
    frame of the motion (100 Hz): a fixed antenna aims at the mean of the record's frames,
    which another frame grid samples a little differently."""
    start = frames / 100.0
    if radar.get("receiver_noise"):
        effects = [e for e in effects if e["kind"] != "noise"]
    p0 = np.array([7.0, 1.5, 0.8])
    v = np.array(velocity)
    scene = {"radar_position": [0.0, 0.0, 1.0], "gate": "track"}
    later = run_config(
        radar,
        effects=effects,
        targets=[{"position": list(p0), "velocity": list(v)}],
        scene=scene,
        length=start + 0.5,
    )
    later = later.model_copy(
        update={"motion": later.motion.model_copy(update={"start": start, "duration": 0.5})}
    )
    moved = run_config(
        radar,
        effects=effects,
        targets=[{"position": list(p0 + start * v), "velocity": list(v)}],
        scene=scene,
        length=0.5,
    )
    y_later, y_moved = (
        simulate_points(later).received.signal,
        simulate_points(moved).received.signal,
    )
    assert y_later.shape == y_moved.shape
    assert np.max(np.abs(y_later - y_moved)) < 1e-9 * np.max(np.abs(y_moved))


@settings(SETTINGS, max_examples=20)
@given(
    moving_points(),
    st.sampled_from([LFM, {**LFM, "path": "raw"}, CW, FMCW]),
    effect_lists(),
    st.integers(-6, 6),
)
def test_the_db_map_does_not_depend_on_the_transmit_power(
    point: tuple[list[float], list[float], float],
    radar: dict[str, Any],
    effects: list[dict[str, Any]],
    k: int,
) -> None:
    """Every echo scales with ``sqrt(P_t)``; the noise and clutter set by an SNR and a CSR
    scale with the signal: the spectrogram in dB re its peak is the same at any transmit power
    (``4^k`` W here: the amplitudes scale by ``2^k``, exactly in floating point)."""
    position, velocity, _ = point

    def run(power: float) -> RunResult:
        cfg = run_config(
            {**radar, "transmit_power": power},
            effects=effects,
            targets=[{"position": list(np.add(position, up)), "velocity": velocity}],
            scene={"radar_position": up, "gate": "track"},
            processing={"window_length": 64, "hop": 32},
        )
        return simulate_points(cfg)

    up = [0.0, 0.0, 1.0]  # the radar above the ground (multipath)
    one, scaled = run(1.0), run(4.0**k)
    assert np.max(np.abs(scaled.received.signal - 2.0**k * one.received.signal)) <= 1e-12 * (
        2.0**k * np.max(np.abs(one.received.signal))
    )
    assert np.max(np.abs(scaled.spectrogram_db - one.spectrogram_db)) < 1e-4


@settings(SETTINGS, max_examples=15)
@given(
    moving_points(),
    st.sampled_from([LFM, CW]),
    st.sampled_from(["thermal noise", "clutter of an RCS"]),
    st.integers(-4, 4),
)
def test_thermal_noise_ignores_the_transmit_power_and_clutter_of_an_rcs_follows_it(
    point: tuple[list[float], list[float], float], radar: dict[str, Any], kind: str, k: int
) -> None:
    """docs/effects.md: thermal noise is the receiver's ``k T F`` whatever is transmitted, while
    clutter set by an RCS is an echo like the target's: at ``4^k`` times the transmit power what
    the effect adds is the same noise, or ``2^k`` times the clutter."""
    position, velocity, _ = point
    if kind == "thermal noise":
        effect: dict[str, Any] = {"kind": "noise", "mode": "thermal"}
        if radar["kind"] == "cw":  # k T F per I/Q sample (no pulse of its own)
            effect |= {"pulse_width": 1 / 2000, "bandwidth": 2000.0}
    else:
        effect = {"kind": "clutter", "power": "rcs", "rcs_m2": 0.5, "range_resolution": 1.0}

    def added(power: float) -> np.ndarray:
        def run(effects: list[dict[str, Any]]) -> np.ndarray:
            cfg = run_config(
                {**radar, "transmit_power": power},
                effects=effects,
                targets=[
                    {"position": list(np.add(position, [0.0, 0.0, 1.0])), "velocity": velocity}
                ],
                scene={"radar_position": [0.0, 0.0, 1.0], "gate": "track"},
            )
            return simulate_points(cfg).received.signal

        return run([effect]) - run([])

    one, scaled = added(1.0), added(4.0**k)
    factor = 1.0 if kind == "thermal noise" else 2.0**k
    assert np.max(np.abs(one)) > 0
    assert np.max(np.abs(scaled - factor * one)) < 1e-6 * factor * np.max(np.abs(one))


# --------------------------------------------------------------------------- windows


@st.composite
def recordings(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray]:
    """A 4 to 8 s recording of 3 smooth joint tracks (a walk's drift, swing up to 0.5 m at
    0.5 to 3 Hz and its harmonics) at a mocap frame rate of 30 to 240 Hz, with jittered frame
    times."""
    rate = draw(st.sampled_from([30.0, 60.0, 100.0, 120.0, 240.0]))
    n = round(draw(st.floats(4.0, 8.0)) * rate)
    jitter = draw(st.floats(0.0, 0.2))
    rng = np.random.default_rng(draw(st.integers(0, 2**16)))
    t = (np.arange(n) + jitter * rng.uniform(-0.5, 0.5, n)) / rate
    pos = np.zeros((n, 3, 3))
    for j in range(3):
        for c in range(3):
            f = draw(st.floats(0.5, 3.0))
            pos[:, j, c] = draw(st.floats(-1.5, 1.5)) * t
            for h in (1, 2, 3):
                pos[:, j, c] += draw(st.floats(0.0, 0.5)) / h * np.sin(2 * np.pi * h * f * t + h)
    return t, pos


@SETTINGS
@given(
    recordings(),
    st.floats(0.0, 1.0),
    st.floats(0.05, 0.5),
    st.sampled_from((*interpolation.LINEAR_IN_DATA, "pchip", "akima")),
)
def test_resampling_a_window_matches_resampling_the_whole_recording(
    recording: tuple[np.ndarray, np.ndarray], where: float, length: float, method: str
) -> None:
    """docs/concepts.md: only the record's window is resampled, with 16 frames on either side,
    and matches resampling the whole recording to within 1e-9 m (the cubic spline's end
    condition decays by 0.27 per frame; the other methods are local)."""
    t, pos = recording
    t0 = t[0] + where * (t[-1] - t[0] - length)
    pulses = interpolation.pulse_times(t0, t0 + length, 2000.0)
    valid = np.ones(pos.shape[:2], dtype=bool)
    whole = interpolation.TrackResampler(t, pos, valid, method)(pulses)
    frames = interpolation.window_frames(t, float(pulses[0]), float(pulses[-1]))
    window = interpolation.TrackResampler(t[frames], pos[frames], valid[frames], method)(pulses)
    assert np.max(np.abs(window - whole)) < 1e-9


@settings(SETTINGS, max_examples=12)
@given(
    st.floats(0.0, 2.0),
    st.floats(10.0, 35.0),
    st.floats(0.5, 1.5),
    st.integers(0, 4000),
    st.integers(300, 2000),
    st.sampled_from(["cubic", "pchip", "akima", "linear"]),
    body_models(),
)
def test_a_record_cut_from_a_recording_is_that_part_of_the_whole_records_signal(
    speed: float,
    swing: float,
    cadence: float,
    first: int,
    n: int,
    method: str,
    model: dict[str, Any],
) -> None:
    """docs/concepts.md: only the record's window is resampled (with 16 frames on either side),
    to within 1e-9 m of resampling the whole recording, and the body is placed from the whole
    recording: a record cut from pulse ``k`` of a 3 s walk is the whole record's signal from
    pulse ``k`` on, to ``4 pi / lambda`` times 1e-9 m of phase (6e-7 at 15 GHz)."""
    t = np.arange(181) / 60.0
    motion = walking_positions(t, speed=speed, swing_deg=swing, cadence_hz=cadence)
    cfg = body_config(LFM, model, radar_position=[8.0, 1.0, 1.2])
    data = cfg.model_dump(mode="json")
    data["processing"]["interpolation"] = method
    whole = simulate_tracks(validate_run_config(data), t, motion).received.signal
    data["motion"] = {**data["motion"], "start": first / 2400, "duration": (n - 1) / 2400}
    part = simulate_tracks(validate_run_config(data), t, motion).received.signal
    assert part.size == n
    y = whole[first : first + n]
    assert np.max(np.abs(part - y)) < 1e-6 * np.max(np.abs(y))


# --------------------------------------------------------------------------- linearity


@st.composite
def point_pairs(draw: st.DrawFn) -> tuple[dict[str, Any], dict[str, Any]]:
    """Two constant-velocity points 3 to 12 m from the radar, within a few metres of each
    other's range, up to 3 m/s."""
    u = unit(np.array(draw(directions)))
    r0 = draw(st.floats(5.0, 12.0))

    def point() -> dict[str, Any]:
        offset = np.array([draw(st.floats(-1.5, 1.5)) for _ in range(3)])
        return {
            "position": list(r0 * u + offset),
            "velocity": [draw(st.floats(-2.0, 2.0)) for _ in range(3)],
            "rcs": draw(st.floats(0.05, 3.0)),
        }

    return point(), point()


@SETTINGS
@given(
    point_pairs(),
    st.sampled_from(
        [
            LFM,
            {**LFM, "gate_response": "sinc"},
            {**LFM, "path": "raw"},
            CW,
            FMCW,
            {**FMCW, "path": "raw", "range_window": "hamming"},
        ]
    ),
    st.lists(
        st.sampled_from(
            [
                {"kind": "multipath", "ground_height": -1.0, "reflection_magnitude": 0.7},
                {"kind": "antenna"},  # aimed below
                {"kind": "attenuation", "gas_db_per_km": 20.0},
            ]
        ),
        unique_by=lambda e: e["kind"],
        max_size=3,
    ),
)
def test_the_return_of_two_scatterers_is_the_sum_of_their_returns(
    pair: tuple[dict[str, Any], dict[str, Any]],
    radar: dict[str, Any],
    effects: list[dict[str, Any]],
) -> None:
    """Every receive chain up to the slow-time signal is linear in the echoes (no detection,
    no noise whose power follows the signal): two points together return the sum of what each
    returns alone, through the linear scatterer-stage effects too (a ground image per point, an
    antenna gain and an attenuation per path). The gate is fixed (a tracking gate would follow
    whichever point comes first)."""
    a, b = pair
    gate = float(np.linalg.norm(a["position"]))
    if any(e["kind"] == "antenna" for e in effects):  # aimed at the first point, both runs
        direction = np.array(a["position"])
        effects = [e for e in effects if e["kind"] != "antenna"]
        effects.append(
            {
                "kind": "antenna",
                "beamwidth_az_deg": 30.0,
                "pointing": "angles",
                "azimuth_deg": float(np.degrees(np.arctan2(direction[1], direction[0]))),
                "elevation_deg": float(np.degrees(np.arcsin(direction[2] / gate))),
            }
        )
    # multipath first (the antenna and attenuation after it), the antenna last
    effects = sorted(effects, key=lambda e: (e["kind"] != "multipath", e["kind"] == "antenna"))

    def run(targets: list[dict[str, Any]]) -> np.ndarray:
        cfg = run_config(radar, targets=targets, scene={"gate": gate}, effects=effects)
        return simulate_points(cfg).received.signal

    both, alone_a, alone_b = run([a, b]), run([a]), run([b])
    scale = max(np.max(np.abs(alone_a)), np.max(np.abs(alone_b)))
    assert scale > 0
    assert np.max(np.abs(both - (alone_a + alone_b))) < 1e-9 * scale


# --------------------------------------------------------------------------- features


@st.composite
def spectrograms(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray]:
    """A walking-like power map (n_doppler, n_frames): a torso line and a swinging limb over a
    noise floor of random level, on an ascending velocity axis [m/s] of uniform bins."""
    rng = np.random.default_rng(draw(st.integers(0, 2**16)))
    n_doppler, n_frames = draw(st.integers(32, 200)), draw(st.integers(4, 60))
    v = (np.arange(n_doppler) - n_doppler // 2) * draw(st.floats(0.01, 0.2))
    m = np.arange(n_frames)
    torso = draw(st.floats(-1.0, 1.0)) * v[-1]
    limb = torso + draw(st.floats(0.2, 1.0)) * v[-1] * np.sin(2 * np.pi * m / n_frames)
    width = 2 * (v[1] - v[0])
    power = np.exp(-(((v[:, None] - torso) / width) ** 2)) * np.ones(n_frames)
    power = power + draw(st.floats(0.01, 0.5)) * np.exp(-(((v[:, None] - limb[None]) / width) ** 2))
    power += 10 ** (draw(st.floats(-8.0, -2.0))) * rng.exponential(size=power.shape)
    return power, v


feature_options = st.fixed_dictionaries(
    {
        "method": st.sampled_from(["threshold", "percentile"]),
        "threshold_db": st.floats(-30.0, -3.0),
        "floor_db": st.floats(-60.0, -20.0),
        "torso_method": st.sampled_from(["median", "peak"]),
    }
)


@SETTINGS
@given(spectrograms(), feature_options, st.integers(-40, 40))
def test_features_ignore_a_constant_gain(
    spec: tuple[np.ndarray, np.ndarray], options: dict[str, Any], exponent: int
) -> None:
    """Every threshold is relative (to the column's peak, to the map's peak, to the column's
    total power), so a gain (here ``2^k``, exact in floating point) changes no feature, and the
    dB map (relative to its peak) not at all."""
    power, v = spec
    gain = 2.0**exponent
    assert np.array_equal(
        spectrogram_features(gain * power, v, **options), spectrogram_features(power, v, **options)
    )
    assert np.array_equal(power_to_db(gain * power, -80.0), power_to_db(power, -80.0))


@SETTINGS
@given(spectrograms(), feature_options, st.floats(-3.0, 3.0), st.randoms(use_true_random=False))
def test_features_follow_a_mirror_and_a_shift_of_the_velocity_axis_and_ignore_frame_order(
    spec: tuple[np.ndarray, np.ndarray], options: dict[str, Any], shift: float, order: Any
) -> None:
    """A motion reversed in time mirrors its velocities (``v -> -v``): the torso's mean changes
    sign, the upper and lower envelopes swap with their signs changed, the bandwidths stay.
    A body carried along at ``c`` m/s (a moving platform) shifts every velocity by ``c``: the
    means and extremes move by ``c``, the bandwidths stay. The features are statistics over the
    frames: their order does not matter. Exact for the threshold envelopes and the peak torso;
    the quantiles (percentile envelopes, median torso) take the first bin reaching their
    fraction, so mirrored they may land one bin off."""
    power, v = spec
    names = {n: i for i, n in enumerate(FEATURE_NAMES)}
    f = spectrogram_features(power, v, **options)
    f_mirror = spectrogram_features(power[::-1], -v[::-1], **options)
    expected = f.copy()
    expected[names["torso_mean"]] = -f[names["torso_mean"]]
    expected[names["upper_max"]] = -f[names["lower_min"]]
    expected[names["lower_min"]] = -f[names["upper_max"]]
    expected[names["upper_mean"]] = -f[names["lower_mean"]]
    expected[names["lower_mean"]] = -f[names["upper_mean"]]
    bin_width = v[1] - v[0]
    quantile = {
        "torso_mean": options["torso_method"] == "median",
        "torso_bandwidth": options["torso_method"] == "median",
    }
    for name, i in names.items():
        envelope_quantile = options["method"] == "percentile" and not name.startswith("torso")
        tol = 1e-9 if not (quantile.get(name, False) or envelope_quantile) else 1.0
        # one bin for a value, two for a difference of two values
        tol *= (2 if "bandwidth" in name else 1) * bin_width
        assert abs(f_mirror[i] - expected[i]) <= tol, (name, f_mirror[i], expected[i])
    shifted = spectrogram_features(power, v + shift, **options)
    offsets = np.array([shift, 0.0, shift, shift, 0.0, shift, shift])
    assert np.allclose(shifted, f + offsets, rtol=0, atol=1e-9)
    frames = list(range(power.shape[1]))
    order.shuffle(frames)
    assert np.allclose(spectrogram_features(power[:, frames], v, **options), f, rtol=0, atol=1e-12)


@settings(SETTINGS, max_examples=10)
@given(
    st.floats(-180.0, 180.0),
    st.floats(0.5, 2.0),
    st.tuples(st.floats(6.0, 15.0), st.floats(0.5, 3.0)),
    st.sampled_from(["joints17", "chen16"]),
    st.sampled_from(["centre", "specular"]),
)
def test_the_torso_feature_is_the_hip_centres_radial_speed_from_any_aspect(
    aspect_deg: float,
    speed: float,
    radar_at: tuple[float, float],
    placement: str,
    phase: str,
) -> None:
    """The median torso track follows the bulk of the body (``mdframework.features``), so a walk
    on a straight path at any aspect and speed has a torso mean equal to its hip centre's mean
    radial speed (+ approaching: its sign is the walk's toward or away from the radar), within
    1.5 times the window's velocity resolution (0.094 m/s here)."""
    t = np.arange(121) / 60.0
    radar_pos = [radar_at[0], 0.0, radar_at[1]]
    model = {"kind": "ellipsoid", "placement": placement, "scattering_phase": phase}
    cfg = run_config(
        LFM,
        scatterers=model,
        scene={
            "radar_position": radar_pos,
            "person": {
                "position": [0.0, 0.0],
                "aspect_deg": aspect_deg,
                "motion": "straight",
                "speed": speed,
            },
            "gate": "track",
        },
        processing={"window_length": 256, "hop": 64},
        length=2.0,
    )
    res = simulate_tracks(cfg, t, walking_positions(t, speed=1.0))
    torso_mean = spectrogram_features(res.spectrogram.power, res.velocity)[0]
    base = res.body.positions[:, res.body.index("base")]
    r = np.linalg.norm(base - np.array(radar_pos), axis=1)
    v_radial = (r[0] - r[-1]) / (res.body.time[-1] - res.body.time[0])
    resolution = res.metadata["prf_hz"] / 256 * res.metadata["wavelength_m"] / 2
    assert abs(torso_mean - v_radial) <= 1.5 * resolution, (torso_mean, v_radial)
