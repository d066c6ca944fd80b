"""End-to-end hard cases of physics.md section 6 that belong to the core path."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
import synthetic
from helpers import phase_increment_doppler, point_run

from mdframework.config import validate_run_config
from mdframework.errors import SceneError
from mdframework.pipeline import RunResult, simulate
from mdframework.plugins import Registry, build_registry


@pytest.fixture(scope="module")
def registry() -> Registry:
    return build_registry([synthetic], autoload=True)


def walk(registry: Registry, **sections: Any) -> RunResult:
    cfg: dict[str, Any] = {
        "motion": {"kind": "synthetic_walker"},
        "processing": {"keep_scatterers": True},
    }
    for key, value in sections.items():
        cfg[key] = value
    return simulate(validate_run_config(cfg, registry=registry), registry)


def test_large_range_same_doppler() -> None:
    """10 km gives the same Doppler as 10 m (section 6.1), to < 1e-6 Hz."""
    near = point_run([{"position": [10.0, 0, 0], "velocity": [-1.0, 0, 0]}], duration=1.0)
    far = point_run([{"position": [10_000.0, 0, 0], "velocity": [-1.0, 0, 0]}], duration=1.0)
    f_near = phase_increment_doppler(near.received.signal, 2400.0)
    f_far = phase_increment_doppler(far.received.signal, 2400.0)
    assert f_near == pytest.approx(100.069228559, rel=1e-8)
    assert abs(f_far - f_near) < 1e-6


@pytest.mark.parametrize("response", ["exact", "sinc", "phase_only"])
def test_constant_range_shift_only_changes_a_global_phase(
    rng: np.random.Generator, response: str
) -> None:
    """Shifting every range (and the gate) by 10 km leaves the slow-time signal unchanged but
    for one global phase (section 6.1)."""
    from mdframework.physics import radar

    t = np.arange(2400) / 2400.0
    ranges = 10.0 + rng.uniform(-0.5, 0.5, 17)[None, :] + np.outer(t, rng.uniform(-3, 3, 17))
    amp = rng.uniform(0.1, 1.0, (1, 17)) * np.ones_like(ranges)
    gate = ranges[:, 0]
    kw: dict[str, Any] = {
        "carrier_frequency": 15e9,
        "pulse_width": 1e-6,
        "bandwidth": 150e6,
        "response": response,
    }
    ya = radar.compressed_return_at_gate(ranges, amp, gate, **kw)
    yb = radar.compressed_return_at_gate(ranges + 10_000.0, amp, gate + 10_000.0, **kw)
    ratio = yb / ya
    assert np.allclose(np.abs(ratio), 1.0, atol=1e-9)
    assert np.ptp(np.angle(ratio * np.conj(ratio[0]))) < 1e-6


def test_target_at_the_radar_is_a_clear_error() -> None:
    with pytest.raises(SceneError, match="comes within 0 m of the radar"):
        point_run([{"position": [1.0, 0, 0], "velocity": [-1.0, 0, 0]}], duration=1.0)


def test_body_walking_into_the_radar_is_a_clear_error(registry: Registry) -> None:
    with pytest.raises(SceneError, match="of the radar"):
        walk(registry, scene={"radar_position": [2.0, 0.0, 1.0]})


def test_radar_straight_overhead_is_finite(registry: Registry) -> None:
    res = walk(
        registry,
        motion={"kind": "synthetic_walker", "speed": 0.0},
        scene={"radar_position": [0.0, 0.0, 8.0], "person": {"heading_deg": 0.0}},
    )
    assert np.all(np.isfinite(res.received.signal))
    assert np.all(np.isfinite(res.scatterers.rcs)) and np.all(res.scatterers.rcs > 0)


def test_aspect_needs_a_horizontal_direction(registry: Registry) -> None:
    with pytest.raises(SceneError, match="straight above"):
        walk(registry, scene={"radar_position": [0.0, 0.0, 8.0]})


@pytest.mark.parametrize(
    ("person", "radar_xy", "aspect", "heading", "expected"),
    [
        ((0.0, 0.0), (10.0, 0.0), 0.0, None, 0.0),  # radar on +x, faced
        ((0.0, 0.0), (10.0, 0.0), 180.0, None, 180.0),  # facing away
        ((1.0, 1.0), (1.0, 6.0), 0.0, None, 90.0),  # radar on +y of the person
        ((0.0, 0.0), (-3.0, -3.0), 45.0, None, -90.0),  # -135 deg, turned by 45
        ((0.0, 0.0), (0.0, 0.0), 30.0, 17.0, 17.0),  # heading wins, even straight below
    ],
)
def test_scene_heading(
    person: Any, radar_xy: Any, aspect: float, heading: Any, expected: float
) -> None:
    """The heading rule that the pipeline and a dataset's ``place = "record"`` share."""
    from mdframework.physics.scene import scene_heading_deg

    got = scene_heading_deg(
        np.array(person), np.array([*radar_xy, 2.0]), aspect_deg=aspect, heading_deg=heading
    )
    assert got == pytest.approx(expected, abs=1e-12)
    with pytest.raises(ValueError, match="straight above"):
        scene_heading_deg(np.array(person), np.array([*person, 5.0]), aspect_deg=aspect)


@pytest.mark.parametrize("collapse", ["l_forearm", "all"])
@pytest.mark.parametrize("placement", ["joints17", "chen16"])
def test_zero_length_segments_stay_finite(
    registry: Registry, collapse: str, placement: str
) -> None:
    res = walk(
        registry,
        motion={"kind": "synthetic_walker", "collapse": collapse},
        scatterers={"kind": "ellipsoid", "placement": placement, "height": 1.8},
    )
    assert np.all(np.isfinite(res.scatterers.rcs))
    assert np.all(np.isfinite(res.received.signal))
    assert np.all(np.isfinite(res.spectrogram_db))
    if collapse == "all":
        # a part whose segment never has a length is a sphere of its radius: pi a^2 at every
        # pulse; the others keep a spheroid's aspect-dependent RCS
        from mdframework.physics import body as bodymodel

        parts = bodymodel.body_parts(placement)  # type: ignore[arg-type]
        a, _ = bodymodel.part_semi_axes(parts, 1.8)
        motion = synthetic.SyntheticWalker(synthetic.SyntheticConfig(collapse="all")).load()
        _, axes = bodymodel.part_geometry(parts, motion.skeleton.positions)
        never = np.all(np.linalg.norm(axes, axis=-1) == 0.0, axis=0)
        never &= ~np.array([p.sphere for p in parts])
        assert 3 <= np.sum(never) < len(parts)
        rcs = res.scatterers.rcs
        want = np.broadcast_to(np.pi * a[never] ** 2, rcs[:, never].shape)
        np.testing.assert_allclose(rcs[:, never], want, rtol=1e-12)


def test_held_orientation_for_collapsed_forearm(registry: Registry) -> None:
    res = walk(
        registry,
        motion={
            "kind": "synthetic_walker",
            "collapse": "l_forearm",
            "swing_deg": 0.0,
            "speed": 0.0,
        },
        scatterers={"kind": "ellipsoid", "height": 1.8},
    )
    k = res.scatterers.names.index("l_hand")
    rcs = res.scatterers.rcs[:, k]
    # a still body: after the collapse (one third in) the forearm keeps its last valid
    # orientation, so its RCS stays that of a hanging forearm seen from the radar
    n = rcs.size
    assert np.ptp(rcs[: n // 4]) / rcs[0] < 1e-4  # spline ringing from the jump only
    assert np.ptp(rcs[n // 2 :]) / rcs[0] < 0.05


def test_record_shorter_than_window_is_a_scene_error(registry: Registry) -> None:
    with pytest.raises(SceneError, match="window_length"):
        walk(registry, motion={"kind": "synthetic_walker", "length": 0.05})


def test_window_past_the_end_is_an_error(registry: Registry) -> None:
    with pytest.raises(SceneError, match="ends after the recording"):
        walk(registry, motion={"kind": "synthetic_walker", "start": 2.0, "duration": 2.0})


def test_aliasing_strict_refuses(registry: Registry) -> None:
    with pytest.raises(SceneError, match="unambiguous"):
        walk(
            registry,
            motion={"kind": "synthetic_walker", "speed": 3.0},
            radar={"kind": "lfm", "prf": 500.0},
            processing={"aliasing": "error"},
        )


def test_walker_torso_line_at_its_speed(registry: Registry) -> None:
    """Walking straight at the radar at 1.2 m/s from 20 m: the spectrogram's strongest line
    (the torso) sits at 1.2 m/s times the cosine of the small elevation angle."""
    res = walk(
        registry,
        motion={"kind": "synthetic_walker", "speed": 1.2},
        scene={"radar_position": [20.0, 0.0, 1.0]},
    )
    v_peak = res.velocity[np.argmax(res.spectrogram.power, axis=0)]
    dv = res.velocity[1] - res.velocity[0]
    assert np.median(v_peak) == pytest.approx(1.2, abs=2 * dv + 0.01)


@pytest.mark.parametrize("aspect", [0.0, 90.0, 180.0])
def test_aspect_angle_sets_the_torso_doppler(registry: Registry, aspect: float) -> None:
    res = walk(
        registry,
        motion={"kind": "synthetic_walker", "speed": 1.0, "length": 2.0},
        scene={"radar_position": [30.0, 0.0, 1.0], "person": {"aspect_deg": aspect}},
    )
    est = phase_increment_doppler(res.received.signal, 2400.0)
    lam = res.metadata["wavelength_m"]
    assert est * lam / 2 == pytest.approx(np.cos(np.deg2rad(aspect)), abs=0.05)


def test_treadmill_removes_translation(registry: Registry) -> None:
    res = walk(
        registry,
        motion={"kind": "synthetic_walker", "speed": 1.5},
        scene={"person": {"motion": "treadmill"}},
    )
    gate = res.gate_range
    assert np.ptp(gate) < 1e-6
    straight = walk(
        registry,
        motion={"kind": "synthetic_walker", "speed": 1.5},
        scene={"radar_position": [30.0, 0.0, 1.0], "person": {"motion": "straight", "speed": 0.7}},
    )
    v = -np.diff(straight.gate_range) * 2400.0
    assert np.median(v) == pytest.approx(0.7, abs=0.01)


def test_points_model_on_a_placed_body(registry: Registry) -> None:
    """`points` with body = true: one isotropic point per canonical joint, placed like any body;
    the torso line still sits at the walking speed."""
    res = walk(
        registry,
        motion={"kind": "synthetic_walker", "speed": 1.2},
        scatterers={"kind": "points", "body": True, "rcs": 0.1},
        scene={"radar_position": [20.0, 0.0, 1.0]},
    )
    assert res.scatterers.names[0] == "base" and len(res.scatterers.names) == 17
    assert np.all(res.scatterers.rcs == 0.1)
    v_peak = res.velocity[np.argmax(res.spectrogram.power, axis=0)]
    assert np.median(v_peak) == pytest.approx(1.2, abs=0.1)


def test_constant_velocity_targets_resample_linearly_as_exactly_as_a_spline() -> None:
    """Point targets declare linear tracks; the pipeline resamples them linearly (no spline).
    The signal is the spline path's to 1e-9 (relative): both are exact for linear motion, the
    difference is rounding. Two targets, one crossing the radar's axis obliquely."""
    import dataclasses

    from mdframework.pipeline import build_stages, load_motion, simulate_motion

    config = validate_run_config(
        {
            "motion": {
                "kind": "point_targets",
                "length": 0.5,
                "frame_rate": 37.0,
                "targets": [
                    {"position": [50.0, 2.0, 1.0], "velocity": [-2.0, 0.5, 0.1]},
                    {"position": [30.0, -3.0, 0.0], "velocity": [1.5, 2.0, -0.3], "rcs": 0.1},
                ],
            },
            "scatterers": {"kind": "points"},
            "processing": {"interpolation": "cubic"},
        }
    )
    stages = build_stages(config)
    motion = load_motion(stages.source)
    assert motion.linear_tracks
    linear = simulate_motion(config, stages, motion).received.signal
    spline = simulate_motion(
        config, build_stages(config), dataclasses.replace(motion, linear_tracks=False)
    ).received.signal
    assert np.max(np.abs(linear - spline)) <= 1e-9 * np.max(np.abs(spline))


@pytest.mark.parametrize("facing_deg", [0.0, 90.0, 180.0, -60.0])
def test_facing_heading_is_a_quarter_turn_clockwise_from_the_hip_line(facing_deg: float) -> None:
    """Scene frame right-handed, z up: a body facing heading h has its left hip on the side of
    h + 90 deg, so hips at +-0.1 m along h + 90 deg (plus a common offset and height) face h
    (a right/left mix-up, or the wrong quarter turn, faces the body away from the radar)."""
    from mdframework.physics.scene import facing_heading

    h = np.radians(facing_deg)
    side = 0.1 * np.array([np.cos(h + np.pi / 2), np.sin(h + np.pi / 2), 0.0])
    centre = np.array([[2.0, -1.0, 0.9], [2.1, -1.0, 0.92]])
    got = facing_heading(centre + side, centre - side)
    assert np.angle(np.exp(1j * (got - h))) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("mode", ["treadmill", "straight"])
def test_placement_removes_the_drift_whatever_the_turn(mode: str) -> None:
    """A recording drifting at (0.8, -0.5) m/s with a sway, turned from heading 0.3 rad to
    1.4 rad (a turn that is not a half turn): placed on a treadmill, its base's least-squares
    drift is zero to 1e-12 m/s; moved straight at 1.2 m/s it is 1.2 m/s along the new heading.
    The drift is fitted to the turned recording, so turning it the other way would leave
    part of it."""
    from mdframework.physics.scene import linear_drift_rate, placement

    t = np.linspace(0.0, 4.0, 121)
    base = np.stack([1.0 + 0.8 * t, 2.0 - 0.5 * t + 0.03 * np.sin(4 * t), 0.9 + 0.0 * t], axis=1)
    p = placement(
        t, base, heading_now=0.3, heading=1.4, position=np.array([5.0, 6.0]), mode=mode, speed=1.2
    )
    placed = p.apply(t, base)
    speed = 1.2 if mode == "straight" else 0.0
    expected = speed * np.array([np.cos(1.4), np.sin(1.4)])
    np.testing.assert_allclose(linear_drift_rate(t, placed[:, :2]), expected, atol=1e-12)
    np.testing.assert_allclose(placed[0, :2], [5.0, 6.0], atol=1e-12)


def _line_body(t0: float = 0.0) -> Any:
    """A 3 s body at 10 Hz whose clock starts at ``t0``: joint 'head' at x = 1 m, 'base' at
    x = 4 m (not the first joint), both 1 m up."""
    from mdframework import Skeleton

    time = t0 + np.arange(31) / 10.0
    pos = np.zeros((31, 2, 3))
    pos[:, 0] = [1.0, 0.0, 1.0]
    pos[:, 1] = [4.0, 0.0, 1.0]
    return Skeleton(time, pos, ("head", "base"))


def test_record_window_counts_from_the_first_frame_and_refuses_what_is_outside() -> None:
    """motion.start and motion.duration count from the recording's first frame (a clock that
    starts at 5 s gives the record 6..8 s for start 1, duration 2); a start at the recording's
    end, or a window ending 0.2 s after it, is refused naming the field."""
    from mdframework.pipeline import record_window

    assert record_window(_line_body(5.0), 1.0, 2.0) == pytest.approx((6.0, 8.0), abs=1e-12)
    assert record_window(_line_body(5.0), 1.0, None) == pytest.approx((6.0, 8.0), abs=1e-12)
    assert record_window(_line_body(), 2.0, 1.0) == pytest.approx((2.0, 3.0), abs=1e-12)
    with pytest.raises(SceneError, match=r"motion\.duration: the window 2\.2\.\.3\.4 s"):
        record_window(_line_body(), 2.2, 1.2)
    with pytest.raises(SceneError, match=r"motion\.start: 3 s is not before the end"):
        record_window(_line_body(), 3.0, None)


def test_frames_inside_includes_both_ends() -> None:
    """Frames at 0.0, 0.1, ... : the record 0.1..0.3 s holds frames 1, 2 and 3."""
    from mdframework.pipeline import frames_inside

    time = np.arange(10) / 10.0
    assert frames_inside(time, 0.1, 0.3) == slice(1, 4)
    assert frames_inside(time, 0.15, 0.25) == slice(2, 3)


def test_gate_tracks_the_pelvis_wherever_it_is_listed_or_stays_fixed() -> None:
    """gate = "track" follows the 'base' joint (4 m from a radar at the origin, not the first
    joint's 1 m); a fixed gate is that range in every pulse."""
    from mdframework.pipeline import gate_ranges

    body = _line_body()
    radar = np.zeros(3)
    np.testing.assert_allclose(gate_ranges("track", body, radar), np.hypot(4.0, 1.0), rtol=1e-12)
    np.testing.assert_allclose(gate_ranges(2.5, body, radar), 2.5, rtol=0)


def test_a_joint_tracked_one_frame_late_is_refused() -> None:
    """A joint first tracked 0.1 s into the record cannot be interpolated at its first pulse
    (no extrapolation): refused, saying from when it is tracked."""
    from mdframework import Skeleton
    from mdframework.pipeline import refuse_untracked

    body = _line_body()
    valid = np.ones((31, 2), dtype=bool)
    valid[0, 1] = False
    late = Skeleton(body.time, body.positions, body.joint_names, valid)
    with pytest.raises(SceneError, match=r"joint 'base' is tracked only from 0\.100 s"):
        refuse_untracked(late, 0.0, 3.0, 0.0)
    refuse_untracked(late, 0.1, 3.0, 0.0)
