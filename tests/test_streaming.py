"""The streaming pipeline: block sizes do not change results, windows resample only their
window (against whole-recording resampling at a stated tolerance), long records keep a bounded
range-time map, and the float32 defaults stay within the accuracy ladder of float64."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from conftest import EXAMPLES

from mdframework import pipeline
from mdframework.config import validate_run_config
from mdframework.output import MAX_SAVED_RANGE_TIME_ROWS, result_arrays
from mdframework.physics import interpolation, scene
from mdframework.pipeline import (
    MAX_KEPT_RANGE_TIME_ROWS,
    build_stages,
    place_body,
    simulate,
    simulate_motion,
)

CMU_WALK = {"kind": "cmu", "file": "data/cmu/asf-amc/02_01.amc", "activity": "walk"}


def run(**sections: Any) -> Any:
    cfg = {"motion": CMU_WALK, **sections}
    return simulate(validate_run_config(cfg, base_dir=EXAMPLES))


@pytest.mark.parametrize("effects", [[], [{"kind": "antenna", "beamwidth_az_deg": 20.0}]])
def test_block_size_does_not_change_the_run(effects: list[dict[str, Any]]) -> None:
    """Blocks of 16 pulses and one block of the whole record give the same signal and dB map."""
    small = run(processing={"block_pulses": 16}, effects=effects)
    whole = run(processing={"block_pulses": 1_000_000}, effects=effects)
    scale = np.max(np.abs(whole.received.signal))
    assert np.max(np.abs(small.received.signal - whole.received.signal)) < 1e-12 * scale
    assert np.array_equal(small.gate_range, whole.gate_range)
    assert small.metadata["effects"] == whole.metadata["effects"]


def test_block_size_changes_the_raw_path_only_in_its_last_bits() -> None:
    """docs/concepts.md: the raw path's signal (sampled chirps, compressed per block) stays
    within 1e-12 of its peak whatever ``block_pulses``, as the analytic path's does."""
    motion = {**CMU_WALK, "duration": 0.5}
    radar = {"kind": "lfm", "path": "raw"}
    small = run(motion=motion, radar=radar, processing={"block_pulses": 48})
    whole = run(motion=motion, radar=radar, processing={"block_pulses": 1_000_000})
    scale = np.max(np.abs(whole.received.signal))
    assert scale > 0
    assert np.max(np.abs(small.received.signal - whole.received.signal)) < 1e-12 * scale


def test_window_resampling_matches_whole_recording_resampling() -> None:
    """A 0.4 s record cut 1.2 s into a 2.85 s CMU walk, resampled from its window plus the margin of
    frames, equals resampling the whole recording to within 1e-9 m (the spline's end effects
    decay by ~0.27 per frame: 16 frames leave ~1e-9 of them)."""
    cfg = validate_run_config({"motion": CMU_WALK}, base_dir=EXAMPLES)
    motion = build_stages(cfg).source.load()
    body = place_body(motion.canonical(), cfg.scene.person, np.array([10.0, 0.0, 2.0]))
    t = interpolation.pulse_times(body.time[0] + 1.2, body.time[0] + 1.6, 2400.0)
    whole = interpolation.resample_tracks(body.time, body.positions, body.valid, t)
    frames = interpolation.window_frames(body.time, float(t[0]), float(t[-1]))
    assert frames.stop - frames.start < 0.3 * body.n_frames  # the window and its margin only
    near = body.select_frames(frames)
    windowed = interpolation.TrackResampler(near.time, near.positions, near.valid)(t)
    assert np.max(np.abs(windowed - whole)) < 1e-9


def test_record_uses_only_its_window_of_a_long_recording() -> None:
    """The run's body holds the record's frames only, and its times start at the first pulse."""
    res = run(motion={**CMU_WALK, "start": 1.0, "duration": 1.0})
    assert res.body.time[0] >= 0.0 and res.body.time[-1] <= 1.0 + 1e-9
    assert 110 <= res.body.n_frames <= 122  # 120 Hz for 1 s


def test_a_record_cut_at_start_counts_its_times_from_its_first_pulse() -> None:
    """docs/getting-started.md: a record cut at ``motion.start`` = 0.7 s of a point receding
    from 10 m at 1 m/s counts every time from its own first pulse: pulse 0 is at 0 s and sees
    the point at 10.7 m, pulse ``k`` at ``10.7 + pulse_time_s[k]`` (to 1e-9 m), and the
    spectrogram's first frame is stamped at its Hann window's centre, 128 pulses in."""
    res = pipeline.simulate(
        validate_run_config(
            {
                "motion": {
                    "kind": "point_targets",
                    "length": 3.0,
                    "start": 0.7,
                    "duration": 1.0,
                    "targets": [{"position": [10.0, 0.0, 0.0], "velocity": [1.0, 0.0, 0.0]}],
                },
                "scatterers": {"kind": "points"},
                "scene": {"radar_position": [0.0, 0.0, 0.0]},
                "processing": {"keep_scatterers": True, "window_length": 256},
            }
        )
    )
    arrays = result_arrays(res)
    t = arrays["pulse_time_s"]
    assert t[0] == 0.0 and t[-1] == pytest.approx(1.0)
    np.testing.assert_allclose(arrays["scatterer_range_m"][:, 0], 10.7 + t, rtol=0, atol=1e-9)
    assert arrays["time_s"][0] == pytest.approx(128 / 2400.0, rel=1e-12)
    assert arrays["body_time_s"][0] == pytest.approx(0.0, abs=1e-12)


def test_the_records_start_in_the_metadata_counts_from_the_recordings_first_frame() -> None:
    """``metadata.json``'s ``record_start_s`` is where the record starts as ``motion.start``
    counts it (and ``mdf check`` prints it), from the recording's first frame, also for a
    motion whose clock starts at 100 s: 0.5, not the clock's 100.5."""
    from mdframework import Motion, Skeleton

    t = 100.0 + np.arange(201) / 100.0
    pos = np.zeros((t.size, 1, 3))
    pos[:, 0, 0] = 10.0 + (t - 100.0)
    motion = Motion(Skeleton(t, pos, ("p",)), {"source": "clock"}, None, np.ones(1), True)
    cfg = validate_run_config(
        {
            "motion": {
                "kind": "point_targets",
                "length": 2.0,
                "start": 0.5,
                "duration": 1.0,
                "targets": [{"position": [10.0, 0.0, 0.0]}],
            },
            "scatterers": {"kind": "points"},
            "scene": {"radar_position": [0.0, 0.0, 0.0]},
            "processing": {"keep_scatterers": True},
        }
    )
    res = simulate_motion(cfg, build_stages(cfg), motion)
    assert res.metadata["record_start_s"] == pytest.approx(0.5, abs=1e-12)
    assert res.pulse_times[0] == 0.0
    assert res.scatterers is not None
    assert res.scatterers.ranges(np.zeros(3))[0, 0] == pytest.approx(10.5, abs=1e-9)


def test_long_raw_records_keep_a_bounded_range_time_map() -> None:
    """Beyond MAX_KEPT_RANGE_TIME_ROWS pulses the map keeps evenly spaced rows with their
    indices, and the saved map at most MAX_SAVED_RANGE_TIME_ROWS of them with their times: every
    row, kept or saved, peaks at the target's range at its time."""
    radar = {"kind": "lfm", "path": "raw", "prf": 4000.0, "bandwidth": 50e6}
    targets = [{"position": [0.0, 20.0, 0.0], "velocity": [0.0, 1.0, 0.0]}]
    seconds = 1.2 * MAX_KEPT_RANGE_TIME_ROWS / 4000.0
    res = simulate(
        validate_run_config(
            {
                "motion": {"kind": "point_targets", "length": seconds, "targets": targets},
                "scatterers": {"kind": "points"},
                "radar": radar,
                "scene": {"radar_position": [0.0, 0.0, 0.0]},
            }
        )
    )
    rec = res.received
    assert rec.range_time is not None and rec.range_time_pulses is not None
    assert rec.range_time.shape[0] <= MAX_KEPT_RANGE_TIME_ROWS
    assert rec.range_time.shape[0] == rec.range_time_pulses.shape[0]
    # each kept row peaks at the target's range at that pulse
    rows = rec.range_time_pulses[:: max(1, rec.range_time_pulses.size // 20)]
    keep = np.searchsorted(rec.range_time_pulses, rows)
    peak = rec.range_axis[np.argmax(np.abs(rec.range_time[keep]), axis=1)]
    truth = 20.0 + res.pulse_times[rows]
    assert np.max(np.abs(peak - truth)) < 0.5 * 3e8 / (2 * 100e6) + 1e-9  # half a sample
    # result.npz keeps at most MAX_SAVED_RANGE_TIME_ROWS of the kept rows, each with its time
    saved = result_arrays(res)
    db, when = saved["range_time_db"], saved["range_time_time_s"]
    assert MAX_SAVED_RANGE_TIME_ROWS // 2 < db.shape[0] <= MAX_SAVED_RANGE_TIME_ROWS
    assert when.shape == (db.shape[0],) and np.all(np.diff(when) > 0)
    peak = saved["range_m"][np.argmax(db, axis=1)]
    assert np.max(np.abs(peak - (20.0 + when))) < 0.5 * 3e8 / (2 * 100e6) + 1e-9


def test_float32_defaults_match_float64_within_the_ladder() -> None:
    """The float32 receive and STFT (defaults) differ from float64 by < 0.01 dB above -40 dB."""
    f32 = run()
    f64 = run(radar={"kind": "lfm", "precision": "float64"}, processing={"precision": "float64"})
    support = f64.spectrogram_db > -40.0
    assert np.max(np.abs(f32.spectrogram_db - f64.spectrogram_db)[support]) < 0.01


def test_fastest_radial_speed_against_a_per_pulse_reference() -> None:
    """The aliasing check's radial speed: for evenly spaced pulses, the largest range step
    over the shortest interval is the per-pulse maximum of |step| / interval to 1e-9; for
    uneven pulse times it is that maximum exactly."""
    from mdframework.physics.radar import max_range_rate

    rng = np.random.default_rng(7)
    ranges = 10.0 + np.cumsum(rng.normal(0.0, 1e-3, (500, 5)), axis=0)

    def reference(t: np.ndarray) -> float:
        return max(
            abs(ranges[i + 1, j] - ranges[i, j]) / (t[i + 1] - t[i])
            for i in range(len(t) - 1)
            for j in range(ranges.shape[1])
        )

    even = interpolation.pulse_times(0.3, 0.3 + 499 / 2400.0, 2400.0)
    assert even.size == 500
    assert max_range_rate(ranges, even) == pytest.approx(reference(even), rel=1e-9)
    uneven = np.cumsum(rng.uniform(1e-4, 1e-3, 500))
    assert max_range_rate(ranges, uneven) == reference(uneven)


@pytest.mark.parametrize("mode", ["recorded", "treadmill", "straight"])
@pytest.mark.parametrize("method", ["cubic", "linear"])
def test_a_placed_interpolant_equals_interpolating_the_placed_frames(
    mode: str, method: interpolation.Method
) -> None:
    """Placing a window's interpolant (its B-spline coefficients at the Greville abscissae, or
    the frames of linear interpolation) gives the interpolant of the placed frames, to 1e-12 m:
    on a real CMU walk, and with a joint untracked for a stretch (per-joint interpolants) and a
    3-frame window (natural spline ends)."""
    cfg = validate_run_config({"motion": CMU_WALK}, base_dir=EXAMPLES)
    body = build_stages(cfg).source.load().canonical()
    where = scene.placement(
        body.time,
        body.positions[:, 0, :],
        heading_now=0.3,
        heading=2.1,
        position=np.array([12.0, -3.0, 0.0]),
        mode=mode,
        speed=1.4,
    )
    valid = body.valid.copy()
    valid[40:70, 5] = False
    for frames in (slice(20, 200), slice(100, 103)):
        time, pos, ok = body.time[frames], body.positions[frames], valid[frames]
        t = np.linspace(time[0], time[-1], 997)
        placed = interpolation.TrackResampler(time, where.apply(time, pos), ok, method)(t)
        mapped = interpolation.TrackResampler(time, pos, ok, method).mapped(where.apply)(t)
        assert np.max(np.abs(mapped - placed)) < 1e-12
    for other in ("pchip", "akima"):
        with pytest.raises(ValueError, match="not linear"):
            interpolation.TrackResampler(time, pos, ok, other).mapped(where.apply)


def test_records_of_one_window_are_the_same_whether_its_interpolant_is_reused() -> None:
    """Records of the same window of one loaded motion at several aspects, one after another
    (a dataset's variations), reuse the window's interpolant; each is bit for bit the record
    built afresh (so records do not depend on which worker built what before them)."""
    base = {"motion": {**CMU_WALK, "start": 0.5, "duration": 1.0}}
    configs = [
        validate_run_config({**base, "scene": {"person": {"aspect_deg": a}}}, base_dir=EXAMPLES)
        for a in (0.0, 30.0, 60.0)
    ]
    motion = build_stages(configs[0]).source.load()
    pipeline._LAST_WINDOW.clear()
    in_a_row, reused = [], []
    for cfg in configs:
        in_a_row.append(simulate_motion(cfg, build_stages(cfg), motion))
        reused.append(pipeline._LAST_WINDOW[0][-1])
    assert reused[0] is reused[1] is reused[2]  # built once for the three records
    for cfg, seen in zip(configs, in_a_row, strict=True):
        pipeline._LAST_WINDOW.clear()
        fresh = simulate_motion(cfg, build_stages(cfg), motion)
        assert pipeline._LAST_WINDOW[0][-1] is not reused[0]  # built afresh
        assert np.array_equal(fresh.received.signal, seen.received.signal)
        assert np.array_equal(fresh.spectrogram_db, seen.spectrogram_db)
    assert not np.array_equal(in_a_row[0].received.signal, in_a_row[2].received.signal)


def test_a_runs_interpolant_is_not_kept_once_its_motion_is_gone() -> None:
    """`simulate` loads its own motion: once it returns, no record can share its window's
    interpolant, which is let go (a 10-minute walk of the 380 Hz Boulic walker held 93 MB of
    it while `mdf run` wrote its files and drew its figures, and a library user held it until
    the next run); the result does not need it."""
    import gc

    cfg = validate_run_config({"motion": {**CMU_WALK, "duration": 0.5}}, base_dir=EXAMPLES)
    pipeline._LAST_WINDOW.clear()
    result = simulate(cfg)
    gc.collect()
    assert pipeline._LAST_WINDOW == []
    assert np.max(np.abs(result.received.signal)) > 0


def test_another_body_with_the_same_window_does_not_reuse_the_interpolant() -> None:
    """Two recordings cut at the same frames (a CMU walk and a CMU boxing trial, both 120 Hz),
    one after the other: the second record is the one built afresh, not one made from the
    first recording's interpolant."""
    window = {"start": 0.5, "duration": 1.0}
    configs = [
        validate_run_config({"motion": {**m, **window}}, base_dir=EXAMPLES)
        for m in (CMU_WALK, {"kind": "cmu", "file": "data/cmu/asf-amc/13_18.amc"})
    ]
    motions = [build_stages(c).source.load() for c in configs]
    pipeline._LAST_WINDOW.clear()
    first = simulate_motion(configs[0], build_stages(configs[0]), motions[0])
    frames_first = pipeline._LAST_WINDOW[0][1:3]
    after = simulate_motion(configs[1], build_stages(configs[1]), motions[1])
    assert pipeline._LAST_WINDOW[0][1:3] == frames_first  # the same frames: only the body differs
    pipeline._LAST_WINDOW.clear()
    fresh = simulate_motion(configs[1], build_stages(configs[1]), motions[1])
    assert np.array_equal(after.received.signal, fresh.received.signal)
    assert not np.array_equal(after.received.signal, first.received.signal)
