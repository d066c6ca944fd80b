"""Treadmill versus overground motion (the paper's explanation of its symmetric Kinect
spectrograms): on a treadmill the torso does not translate and the stance foot moves backward
with the belt, away from a radar the person faces, so it gives negative Doppler."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from mdframework.config import validate_run_config
from mdframework.constants import SPEED_OF_LIGHT
from mdframework.pipeline import RunResult, simulate

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
LAM = SPEED_OF_LIGHT / 15e9

SOURCES: dict[str, dict[str, Any]] = {
    "boulic": {"kind": "boulic", "duration": 4.0},
    "cmu_02_01": {"kind": "cmu", "file": "data/cmu/asf-amc/02_01.amc", "activity": "walk"},
}


def walk(source: str, motion: str) -> RunResult:
    cfg = {
        "motion": SOURCES[source],
        "scatterers": {"kind": "ellipsoid", "placement": "joints17"},
        "scene": {
            "radar_position": [10.0, 0.0, 1.0],
            "person": {"motion": motion, "position": [0.0, 0.0], "aspect_deg": 0.0},
        },
        "processing": {"hop": 32, "keep_scatterers": True},
    }
    return simulate(validate_run_config(cfg, base_dir=EXAMPLES))


def radial_velocity(res: RunResult, joint: str) -> np.ndarray:
    """Radial velocity [m/s] (positive approaching) of a joint's scatterer at every pulse."""
    i = res.scatterers.names.index(joint)
    r = res.scatterers.ranges(np.array([10.0, 0.0, 1.0]))[:, i]
    return -np.gradient(r, res.pulse_times)


def stance(res: RunResult, joint: str) -> np.ndarray:
    """Pulses where the ankle is within 2 cm of its lowest height in the record."""
    z = res.scatterers.positions[:, res.scatterers.names.index(joint), 2]
    return z < z.min() + 0.02


@pytest.mark.parametrize("source", list(SOURCES))
def test_treadmill_has_no_net_torso_translation(source: str) -> None:
    tread = walk(source, "treadmill")
    over = walk(source, "recorded")
    i = tread.scatterers.names.index("base")
    drift_t = np.linalg.norm(
        tread.scatterers.positions[-1, i, :2] - tread.scatterers.positions[0, i, :2]
    )
    drift_o = np.linalg.norm(
        over.scatterers.positions[-1, i, :2] - over.scatterers.positions[0, i, :2]
    )
    duration = tread.pulse_times[-1]
    assert drift_o > 0.6 * duration  # overground: walks at >= 0.6 m/s
    assert drift_t < 0.1  # treadmill: sway only (a few cm)
    # the torso's mean radial velocity is ~0 on the treadmill, ~walking speed overground
    assert abs(np.mean(radial_velocity(tread, "base"))) < 0.03
    assert np.mean(radial_velocity(over, "base")) > 0.6


@pytest.mark.parametrize("source", list(SOURCES))
def test_treadmill_stance_foot_gives_negative_doppler(source: str) -> None:
    tread = walk(source, "treadmill")
    over = walk(source, "recorded")
    speed = np.mean(radial_velocity(over, "base"))
    for ankle in ("l_ankle", "r_ankle"):
        on = stance(tread, ankle)
        assert on.mean() > 0.1
        v_t = np.median(radial_velocity(tread, ankle)[on])
        # the belt carries the planted foot away at about the walking speed
        assert v_t < -0.5 * speed
        assert v_t > -1.5 * speed
        # overground the planted foot is (nearly) still
        v_o = np.median(radial_velocity(over, ankle)[stance(over, ankle)])
        assert abs(v_o) < 0.25 * speed
    # and the spectrogram shows it: power at the belt's negative velocity during the record,
    # well above the floor, while the overground spectrogram's mass is on the positive side
    spec_t, spec_o = tread.spectrogram, over.spectrogram
    v = tread.velocity
    band = (v < -0.5 * speed) & (v > -1.5 * speed)
    share_t = spec_t.power[band].sum() / spec_t.power.sum()
    share_o = spec_o.power[band].sum() / spec_o.power.sum()
    assert share_t > 5 * share_o
    assert share_t > 1e-3


@pytest.mark.parametrize("mode", ["recorded", "treadmill", "straight"])
def test_a_window_is_placed_as_the_whole_recording(mode: str) -> None:
    """Records place only their window's frames, with the placement found from the whole
    recording (facing, drift): the window's placed joints equal the whole recording placed and
    then cut, to 1e-12 m, in every motion mode."""
    from mdframework.physics import scene

    rng = np.random.default_rng(5)
    time = np.cumsum(rng.uniform(0.005, 0.01, 400))
    base = np.column_stack([1.2 * time, 0.1 * np.sin(time), 1.0 + 0.02 * np.cos(3 * time)])
    joints = base[:, None, :] + rng.normal(0.0, 0.3, (400, 5, 3))
    where = scene.placement(
        time,
        base,
        heading_now=0.3,
        heading=2.0,
        position=np.array([4.0, -1.0]),
        mode=mode,
        speed=1.4,
    )
    whole = where.apply(time, joints)
    assert np.max(np.abs(where.apply(time[150:260], joints[150:260]) - whole[150:260])) < 1e-12
    # the rotation keeps every joint's distance to the base (a rigid motion per frame)
    for k in range(5):
        before = np.linalg.norm(joints[:, k] - base, axis=1)
        after = np.linalg.norm(whole[:, k] - where.apply(time, base[:, None, :])[:, 0], axis=1)
        assert np.max(np.abs(after - before)) < 1e-12


def test_drift_rate_is_the_least_squares_slope() -> None:
    """The treadmill's drift rate against numpy's polynomial fit (an independent least-squares
    solver) on uneven frame times, to 1e-12 m/s; a single frame has no drift."""
    from mdframework.physics import scene

    rng = np.random.default_rng(11)
    time = 3.0 + np.cumsum(rng.uniform(0.005, 0.02, 300))
    track = np.column_stack([0.9 * time, -0.2 * time]) + rng.normal(0.0, 0.05, (300, 2))
    expected = [np.polyfit(time, track[:, k], 1)[0] for k in range(2)]
    assert np.max(np.abs(scene.linear_drift_rate(time, track) - expected)) < 1e-12
    assert np.array_equal(scene.linear_drift_rate(time[:1], track[:1]), np.zeros(2))


@pytest.mark.parametrize("mode", ["recorded", "treadmill", "straight"])
def test_untracked_frames_at_the_ends_do_not_move_the_placement(mode: str) -> None:
    """A capture's first frames come before the tracker finds the person (base NaN): the
    placement is the one of the tracked frames alone (origin from the first tracked frame,
    drift and travel fitted to the tracked frames), to 1e-12 m on every tracked frame; it was
    NaN everywhere (origin from frame 0). A base tracked in no frame is refused."""
    from mdframework.physics import scene

    rng = np.random.default_rng(8)
    time = np.cumsum(rng.uniform(0.02, 0.04, 200))
    base = np.column_stack([1.1 * time, 0.2 * np.sin(time), 1.0 + 0.02 * np.cos(3 * time)])
    joints = base[:, None, :] + rng.normal(0.0, 0.3, (200, 4, 3))
    gappy, gappy_joints = base.copy(), joints.copy()
    gappy[:20] = np.nan
    gappy[-5:] = np.nan
    gappy_joints[:20] = np.nan
    kw: dict[str, Any] = dict(
        heading_now=0.3, heading=2.0, position=np.array([4.0, -1.0]), mode=mode, speed=1.4
    )
    whole = scene.placement(time, gappy, **kw).apply(time, gappy_joints)
    tracked = slice(20, 195)
    alone = scene.placement(time[tracked], base[tracked], **kw)
    assert np.max(np.abs(whole[tracked] - alone.apply(time[tracked], joints[tracked]))) < 1e-12
    assert np.all(np.isnan(whole[:20]))
    assert scene.travel_heading(gappy) == pytest.approx(scene.travel_heading(base[tracked]))
    with pytest.raises(ValueError, match="not tracked in any frame"):
        scene.placement(time, np.full_like(base, np.nan), **kw)


def test_a_body_never_tracked_is_refused_naming_its_file() -> None:
    """A body whose hip centre is tracked in no frame (other joints tracked) has nowhere to be
    placed: one error naming the motion's file (a SceneError without one)."""
    from mdframework import DataFileError
    from mdframework.errors import SceneError
    from mdframework.pipeline import body_placement
    from mdframework.settings import PersonConfig
    from mdframework.skeleton import CANONICAL_JOINTS, Skeleton

    n, j = 10, len(CANONICAL_JOINTS)
    pos = np.random.default_rng(2).normal(0.0, 0.3, (n, j, 3)) + np.array([2.0, 0.0, 1.0])
    valid = np.ones((n, j), dtype=bool)
    valid[:, CANONICAL_JOINTS.index("base")] = False
    pos[:, CANONICAL_JOINTS.index("base")] = np.nan
    body = Skeleton(np.arange(n) / 30.0, pos, CANONICAL_JOINTS, valid)
    radar = np.zeros(3)
    with pytest.raises(DataFileError, match=r"^cap\.nite\.txt: the hip centre .* in no frame"):
        body_placement(body, PersonConfig(), radar, "cap.nite.txt")
    with pytest.raises(SceneError, match="in no frame"):
        body_placement(body, PersonConfig(), radar)
