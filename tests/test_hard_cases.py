"""Every numerically hard case of physics.md section 6, by name (``test_6_<n>_...``), plus
Hypothesis property tests over random valid scenes.

Some cases are also checked elsewhere (test_pipeline_hard_cases, test_processing, test_classify);
here each is re-checked under its section's name so the coverage of section 6 is visible in one
place.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
import pytest
import synthetic
from helpers import phase_increment_doppler, point_run
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mdf_knn import Knn
from scenes import load_project_modules

from mdframework import Skeleton
from mdframework.classify import Standardizer, confusion_matrix
from mdframework.conditioning import sort_timestamps
from mdframework.config import validate_run_config
from mdframework.constants import SPEED_OF_LIGHT
from mdframework.errors import ConfigError, SceneError
from mdframework.features import spectrogram_features
from mdframework.interfaces import receive_points
from mdframework.physics import interpolation, radar, rcs
from mdframework.physics.spectrogram import RecordTooShortError, power_to_db, spectrogram
from mdframework.pipeline import AliasingWarning, RunResult, simulate
from mdframework.plugins import Registry, build_registry
from mdframework.skeleton import SkeletonError

FC = 15e9
LAM = SPEED_OF_LIGHT / FC
# The property tests draw their examples deterministically (no database, no random seed): a
# random draw made every run try other examples (and replay the failures that the examples
# database in the working folder's .hypothesis/ kept), so a run could fail by chance and CI
# differ from a developer's run. Hypothesis also draws constants of the loaded modules: load
# them all, for the same examples whatever ran before.
load_project_modules()
PROPERTY = settings(
    max_examples=25,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)


@pytest.fixture(scope="module")
def registry() -> Registry:
    return build_registry([synthetic], autoload=True)


def walker(registry: Registry, **sections: Any) -> RunResult:
    cfg: dict[str, Any] = {
        "motion": {"kind": "synthetic_walker", "length": 2.0},
        "processing": {"keep_scatterers": True},
        **sections,
    }
    return simulate(validate_run_config(cfg, registry=registry), registry)


def all_finite(res: RunResult) -> bool:
    arrays = [
        res.received.signal,
        res.spectrogram.power,
        res.spectrogram_db,
        res.velocity,
        *((res.scatterers.positions, res.scatterers.rcs) if res.scatterers else ()),
        res.gate_range,
    ]
    return all(bool(np.all(np.isfinite(a))) for a in arrays)


# --------------------------------------------------------------------------- 6.1


@pytest.mark.parametrize("precision", ["float64", "float32"])
def test_6_1_large_range_doppler_at_10km_equals_10m(precision: str) -> None:
    near = point_run(
        [{"position": [10.0, 0, 0], "velocity": [1.0, 0, 0]}],
        duration=1.0,
        radar={"precision": precision},
    )
    far = point_run(
        [{"position": [10_000.0, 0, 0], "velocity": [1.0, 0, 0]}],
        duration=1.0,
        radar={"precision": precision},
    )
    f_near = phase_increment_doppler(near.received.signal, 2400.0)
    f_far = phase_increment_doppler(far.received.signal, 2400.0)
    assert f_far == pytest.approx(f_near, abs=1e-6)  # section 6.1, in either precision
    assert f_near == pytest.approx(-2.0 / LAM, abs=1e-3)


def test_6_1_large_range_float32_option_matches_float64() -> None:
    """The float32 option reduces the phase in float64 first: at 10 km its return differs
    from float64 by float32 rounding only (< 1e-6 relative), not by 0.6-rad phase steps."""
    tgt = [{"position": [10_000.0, 0, 0], "velocity": [-1.3, 0.2, 0]}]
    a = point_run(tgt, duration=0.5, radar={"precision": "float64"})
    b = point_run(tgt, duration=0.5, radar={"precision": "float32"})
    err = np.abs(b.received.signal - a.received.signal) / np.abs(a.received.signal)
    assert np.max(err) < 1e-6


def test_6_1_large_range_naive_float32_positions_fail_the_same_check() -> None:
    """The failure the formulation avoids: float32 ranges at 10 km quantise the phase in
    0.6-rad steps; the instantaneous Doppler then scatters by ~100 Hz."""
    t = np.arange(2400) / 2400.0
    r64 = 10_000.0 + 1.0 * t
    naive = np.exp(-1j * (4 * np.pi / np.float32(LAM)) * r64.astype(np.float32))
    stable = radar.carrier_phasor(r64, FC)
    inst_naive = np.angle(naive[1:] * np.conj(naive[:-1])) * 2400 / (2 * np.pi)
    inst_stable = np.angle(stable[1:] * np.conj(stable[:-1])) * 2400 / (2 * np.pi)
    assert np.std(inst_naive) > 50.0
    assert np.std(inst_stable) < 1e-6


# --------------------------------------------------------------------------- 6.2


def test_6_2_ellipsoid_denominator_never_below_min_axis() -> None:
    rng = np.random.default_rng(1)
    a, b, c = 0.05, 0.08, 0.2
    th = rng.uniform(0, np.pi, 100_000)
    ph = rng.uniform(-np.pi, np.pi, 100_000)
    sigma = rcs.ellipsoid_rcs_angles(a, b, c, th, ph)
    h2 = np.sqrt(np.pi * a * a * b * b * c * c / sigma)
    assert np.all(np.isfinite(sigma)) and h2.min() >= min(a, b, c) ** 2 * (1 - 1e-12)


def test_6_2_ellipsoid_end_on_and_broadside_values() -> None:
    end_on = rcs.ellipsoid_rcs_angles(0.06, 0.06, 0.2, 0.0, 0.0)
    broadside = rcs.ellipsoid_rcs_angles(0.06, 0.06, 0.2, np.pi / 2, 0.0)
    assert end_on == pytest.approx(1.017876e-3, rel=1e-6)
    assert broadside == pytest.approx(0.1256637, rel=1e-6)
    sphere = rcs.ellipsoid_rcs_angles(0.1, 0.1, 0.1, np.linspace(0, np.pi, 50), 0.3)
    assert np.ptp(sphere) < 1e-15 and sphere[0] == pytest.approx(np.pi * 0.01)


def test_6_2_ellipsoid_zero_length_segment_and_acos_domain_are_finite() -> None:
    a, c = np.array([0.06]), np.array([0.2])
    zero = rcs.spheroid_rcs(a, c, np.zeros((1, 3)), np.array([[1.0, 0.0, 0.0]]))
    assert np.all(np.isfinite(zero))
    # parallel vectors whose cosine rounds above 1: exactly end-on, no NaN
    axis = np.array([[0.1, 0.2, 0.3]])
    los = axis * (1 + 1e-16) * 7.0
    assert rcs.spheroid_rcs(a, c, axis, los)[0] == pytest.approx(np.pi * 0.06**4 / 0.2**2)


@pytest.mark.parametrize("surface_points", [0, 8])
def test_6_2_ellipsoid_zero_length_segments_in_pipeline(
    registry: Registry, surface_points: int
) -> None:
    res = walker(
        registry,
        motion={"kind": "synthetic_walker", "length": 2.0, "collapse": "all"},
        scatterers={"kind": "ellipsoid", "height": 1.8, "surface_points": surface_points},
    )
    assert all_finite(res)


def test_6_2_ellipsoid_dynamic_range_in_db() -> None:
    """A slim limb swings ~20 dB between broadside and end-on; the dB conversion is finite."""
    th = np.linspace(0, np.pi / 2, 1001)
    sigma = rcs.ellipsoid_rcs_angles(0.07, 0.07, 0.2205, th, 0.0)
    swing = 10 * np.log10(sigma.max() / sigma.min())
    assert swing == pytest.approx(20 * np.log10(0.2205**2 / 0.07**2) / 1, rel=1e-9)
    assert np.all(np.isfinite(power_to_db(sigma[:, None], -200.0)))


# --------------------------------------------------------------------------- 6.3


def test_6_3_log_of_zero_power_is_floored() -> None:
    p = np.zeros((64, 10))
    p[3, 4] = 1.0
    db = power_to_db(p, -60.0)
    assert np.all(np.isfinite(db)) and db.min() == -60.0 and db.max() == 0.0
    assert np.all(power_to_db(np.zeros((8, 3)), -60.0) == -60.0)
    assert np.all(power_to_db(np.zeros((0, 3)), -60.0).shape == (0, 3))


def test_6_3_log_of_zero_silent_scene_is_defined() -> None:
    res = point_run([{"position": [10.0, 0, 0], "rcs": 0.0}], duration=0.5)
    assert np.all(res.spectrogram_db == -60.0)
    with pytest.raises(ValueError, match="silent"):
        spectrogram_features(res.spectrogram.power, res.velocity)


# --------------------------------------------------------------------------- 6.4


def _track(t: np.ndarray) -> np.ndarray:
    """A 1 Hz, 0.2 m swing on a 1.1 m/s walk, (n, 1, 3) [m]."""
    x = 1.1 * t + 0.2 * np.sin(2 * np.pi * t)
    return np.stack([x, 0 * t, 0 * t], axis=1)[:, None, :]


def _resample_error(t_in: np.ndarray, valid: np.ndarray | None = None, method: str = "cubic"):
    pos = _track(t_in)
    ok = np.ones(pos.shape[:2], bool) if valid is None else valid[:, None]
    t_out = interpolation.pulse_times(t_in[0], t_in[-1], 2400.0)
    got = interpolation.resample_tracks(t_in, pos, ok, t_out, method)  # type: ignore[arg-type]
    true = _track(t_out)
    err = np.abs(got - true)[:, 0, 0]
    v_err = np.abs(np.gradient(got[:, 0, 0] - true[:, 0, 0], t_out))
    inner = (t_out > t_in[0] + 0.5) & (t_out < t_in[-1] - 0.5)
    return err[inner].max(), v_err[inner].max()


def test_6_4_interpolation_with_jitter() -> None:
    rng = np.random.default_rng(2)
    t = np.arange(0, 6, 1 / 18) + rng.uniform(-0.005, 0.005, 108)
    e, ve = _resample_error(np.sort(t))
    assert e < 1e-3 and ve < 0.03
    e_lin, ve_lin = _resample_error(np.sort(t), method="linear")
    assert e_lin > 3 * e and ve_lin > 5 * ve  # the C2 spline is the accurate choice


def test_6_4_interpolation_with_dropped_frames_uses_real_time_stamps() -> None:
    rng = np.random.default_rng(3)
    t = np.arange(0, 6, 1 / 18)
    keep = np.ones(t.size, bool)
    keep[rng.choice(np.arange(5, t.size - 5), 10, replace=False)] = False
    e, ve = _resample_error(t[keep])
    assert e < 3e-3 and ve < 0.1
    # assuming a uniform grid instead time-warps the motion: a much larger error
    t_wrong = t[0] + np.arange(keep.sum()) / 18
    pos = _track(t[keep])
    t_out = interpolation.pulse_times(t_wrong[0], t_wrong[-1], 2400.0)
    got = interpolation.resample_tracks(t_wrong, pos, np.ones((keep.sum(), 1), bool), t_out)
    assert np.max(np.abs(got - _track(t_out))) > 10 * e


def test_6_4_interpolation_with_nan_gaps() -> None:
    t = np.arange(0, 6, 1 / 18)
    valid = np.ones(t.size, bool)
    valid[50:54] = False  # a 4-frame (0.22 s) gap
    pos = _track(t)
    pos[~valid] = np.nan
    skel = Skeleton(t, pos, ("j",))
    assert not skel.valid[50:54].any()
    t_out = interpolation.pulse_times(t[0], t[-1], 2400.0)
    got = interpolation.resample_tracks(t, np.nan_to_num(pos), skel.valid, t_out)
    assert np.all(np.isfinite(got))
    assert np.max(np.abs(got - _track(t_out))) < 0.02  # ~13 mm at worst for this gap


def test_6_4_interpolation_non_increasing_time_stamps() -> None:
    t = np.array([0.0, 0.05, 0.05, 0.1, 0.08, 0.2])
    pos = np.arange(18, dtype=float).reshape(6, 1, 3)
    with pytest.raises(SkeletonError) as caught:
        Skeleton(t, pos, ("j",))
    assert "strictly increasing (frame 2: 0.05 s after 0.05 s)" in str(caught.value)
    ts, ps, _, _ = sort_timestamps(t, pos)
    assert np.all(np.diff(ts) > 0) and np.array_equal(ps, pos[[0, 1, 4, 3, 5]])
    # and no extrapolation beyond the last frame
    with pytest.raises(ValueError, match="never extrapolates"):
        interpolation.resample_tracks(ts, ps, np.ones((5, 1), bool), np.array([0.0, 0.3]))


# --------------------------------------------------------------------------- 6.5


def test_6_5_doppler_aliasing_detected_and_observed_where_predicted() -> None:
    tgt = [{"position": [100.0, 0, 0], "velocity": [-15.0, 0, 0]}]
    # the warning says which PRF would do: 4 v / lambda = 4 * 15 / 0.019986 = 3002.1 Hz
    assert radar.min_prf_for_velocity(15.0, FC) == pytest.approx(3002.08, abs=0.01)
    with pytest.warns(AliasingWarning, match="aliases; raise radar.prf to at least 3003 Hz"):
        res = point_run(tgt, duration=1.0)
    f = phase_increment_doppler(res.received.signal, 2400.0)
    assert f == pytest.approx(radar.alias_frequency(2 * 15.0 / LAM, 2400.0), abs=1e-3)
    assert f == pytest.approx(-898.9616, abs=1e-3)
    with pytest.raises(SceneError, match="aliases"):
        point_run(tgt, duration=1.0, processing={"aliasing": "error"})


def test_6_5_doppler_aliasing_limit_at_low_prf() -> None:
    assert radar.max_unambiguous_velocity(FC, 1200.0) == pytest.approx(5.995849, rel=1e-6)
    fast = [{"position": [50.0, 0, 0], "velocity": [-9.0, 0, 0]}]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        point_run(fast, duration=0.5)  # 9 m/s is inside 12 m/s at 2400 Hz
    with pytest.warns(AliasingWarning):
        point_run(fast, duration=0.5, radar={"prf": 1200.0})


# --------------------------------------------------------------------------- 6.6


def test_6_6_range_migration_tracking_gate_constant_fixed_gate_follows_response() -> None:
    tgt = [{"position": [20.0, 0, 0], "velocity": [1.1, 0, 0]}]
    tracked = point_run(tgt, duration=3.0)
    fixed = point_run(tgt, duration=3.0, scene={"gate": 20.0})
    a = radar.range_equation_amplitude(1.0, tracked.gate_range, wavelength=LAM)
    assert np.allclose(np.abs(tracked.received.signal), a, rtol=1e-12)
    r = 20.0 + 1.1 * fixed.pulse_times
    w = radar.gate_weights(r[:, None], np.full(r.size, 20.0), pulse_width=1e-6, bandwidth=150e6)
    assert np.allclose(np.abs(fixed.received.signal), a * np.abs(w[:, 0]), atol=1e-3 * a.max())
    # past the first null (~1 m) only the range sidelobes remain: at most the sinc's first
    # sidelobe, 0.217 (-13.3 dB), of the tracked amplitude
    late = fixed.pulse_times > 1.0 / 1.1 + 0.05
    assert np.max(np.abs(fixed.received.signal[late]) / a[late]) < 0.22
    cells = 1.1 * 6.0 / (SPEED_OF_LIGHT / 2 / 150e6)
    assert cells == pytest.approx(6.6, abs=0.05)


# --------------------------------------------------------------------------- 6.7


def test_6_7_knn_zero_variance_feature() -> None:
    x = np.array([[1.0, 0.3], [2.0, 0.3], [3.0, 0.3], [10.0, 0.3]])
    z = Standardizer.fit(x).transform(x)
    assert np.all(np.isfinite(z))
    pred = Knn(Knn.Config(k=1)).fit(x, np.array(list("aabb"))).predict(np.array([[9.0, 0.3]]))
    assert pred[0] == "b"


def test_6_7_knn_vote_ties_and_distance_ties() -> None:
    x = np.array([[1.0], [-1.2], [2.0], [-2.2], [3.0]])
    y = np.array(["walk", "run", "walk", "run", "box"])
    assert Knn(Knn.Config(k=5)).fit(x, y).predict(np.array([[0.0]]))[0] == "walk"
    eq = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    for labels in (list("abcd"), list("dcba")):
        model = Knn(Knn.Config(k=1)).fit(eq, np.array(labels))
        assert model.predict(np.zeros((1, 2)))[0] == labels[0]


def test_6_7_knn_unequal_class_sizes_per_class_rates() -> None:
    y_true = np.array(["walk"] * 93 + ["run"] * 32)
    y_pred = np.array(["walk"] * 93 + ["run"] * 30 + ["walk"] * 2)
    cm = confusion_matrix(y_true, y_pred, ["walk", "run"])
    assert cm[1, 1] == pytest.approx(30 / 32) and cm[0, 0] == 1.0
    assert np.allclose(cm.sum(axis=1), 1.0)


# --------------------------------------------------------------------------- 6.8


def test_6_8_record_shorter_than_stft_window() -> None:
    with pytest.raises(RecordTooShortError, match="256"):
        spectrogram(np.ones(100, complex), 2400.0, window_length=256)
    one = spectrogram(np.ones(256, complex), 2400.0, window_length=256)
    assert one.power.shape[1] == 1
    with pytest.raises(SceneError, match="window_length"):
        point_run([{"position": [10.0, 0, 0]}], duration=0.05)


# --------------------------------------------------------------------------- 6.9


def test_6_9_target_at_the_radar_is_a_clear_error() -> None:
    with pytest.raises(SceneError, match="of the radar"):
        point_run([{"position": [1.0, 0, 0], "velocity": [-1.0, 0, 0]}], duration=1.0)
    with pytest.raises(ValueError, match="positive"):
        radar.range_equation_amplitude(1.0, 0.0, wavelength=LAM)


def test_6_9_radar_straight_overhead(registry: Registry) -> None:
    res = walker(
        registry,
        motion={"kind": "synthetic_walker", "length": 2.0, "speed": 0.0},
        scene={"radar_position": [0.0, 0.0, 8.0], "person": {"heading_deg": 0.0}},
        effects=[{"kind": "multipath"}, {"kind": "antenna", "beamwidth_az_deg": 40.0}],
    )
    assert all_finite(res) and np.all(res.scatterers.rcs >= 0)
    with pytest.raises(SceneError, match="straight above"):
        walker(registry, scene={"radar_position": [0.0, 0.0, 8.0]})
    # a vertical segment seen from overhead: the finite end-on value pi a^4 / c^2
    end_on = rcs.spheroid_rcs(0.07, 0.22, np.array([0.0, 0, 1]), np.array([0.0, 0, 5]))
    assert end_on == pytest.approx(np.pi * 0.07**4 / 0.22**2)


# --------------------------------------------------------------------------- 6.10


def test_6_10_boulic_gait_boundaries() -> None:
    for rv in (0.0, -1.0, 3.5):
        with pytest.raises(ConfigError):
            validate_run_config({"motion": {"kind": "boulic", "rv": rv}})
    for rv in (0.5, 1.3, 3.0):
        cfg = validate_run_config({"motion": {"kind": "boulic", "rv": rv, "duration": 1.0}})
        assert all_finite(simulate(cfg))


def test_6_10_rigid_bone_lengths_constant() -> None:
    cfg = validate_run_config(
        {
            "motion": {"kind": "boulic", "duration": 2.0},
            "scatterers": {"kind": "ellipsoid"},
            "processing": {"keep_scatterers": True},
        }
    )
    res = simulate(cfg)
    n = res.scatterers.names
    p = res.scatterers.positions
    for a, b in (("l_hip", "l_knee"), ("l_knee", "l_ankle"), ("r_shoulder", "r_elbow")):
        length = np.linalg.norm(p[:, n.index(a)] - p[:, n.index(b)], axis=1)
        assert np.ptp(length) < 1e-3 * length.mean()


def test_6_10_sign_convention_and_axes_end_to_end() -> None:
    res = point_run(
        [{"position": [10.0, 0, 0], "velocity": [-0.936851431, 0, 0]}],
        duration=2.0,
        processing={"window_length": 256, "hop": 64, "nfft": 256},
    )
    peak = res.spectrogram.doppler[np.argmax(res.spectrogram.power, axis=0)]
    assert np.all(peak == pytest.approx(93.75, abs=1e-9))  # approaching -> positive
    assert np.allclose(res.velocity, res.spectrogram.doppler * SPEED_OF_LIGHT / (2 * FC))
    centres = (np.arange(res.spectrogram.time.size) * 64 + 128) / 2400.0  # Hann: L/2
    assert np.allclose(res.spectrogram.time, centres)


# --------------------------------------------------------------------------- properties

target_st = st.fixed_dictionaries(
    {
        "position": st.tuples(
            st.floats(5.0, 60.0), st.floats(-10.0, 10.0), st.floats(0.2, 3.0)
        ).map(list),
        "velocity": st.tuples(st.floats(-4.0, 4.0), st.floats(-4.0, 4.0), st.floats(-0.5, 0.5)).map(
            list
        ),
        "rcs": st.floats(0.001, 10.0),
    }
)
effect_st = st.lists(
    st.sampled_from(
        [
            {"kind": "noise", "snr_db": 10.0},
            {"kind": "clutter", "csr_db": 5.0},
            {"kind": "multipath", "ground_height": 0.0},
            {"kind": "antenna", "beamwidth_az_deg": 30.0},
            {"kind": "attenuation", "gas_db_per_km": 0.5},
        ]
    ),
    max_size=3,
    unique_by=lambda e: e["kind"],
).map(  # multipath first, the antenna last (the order the effects require)
    lambda effects: sorted(
        effects, key=lambda e: (e["kind"] != "multipath", e["kind"] == "antenna")
    )
)


@PROPERTY
@given(
    targets=st.lists(target_st, min_size=1, max_size=5),
    effects=effect_st,
    radar_z=st.floats(0.5, 10.0),
    gate=st.sampled_from(["track", 30.0]),
)
def test_property_random_point_scenes_have_no_nan_or_inf(
    targets: list[dict[str, Any]], effects: list[dict[str, Any]], radar_z: float, gate: Any
) -> None:
    cfg = {
        "motion": {"kind": "point_targets", "length": 0.3, "targets": targets},
        "scatterers": {"kind": "points"},
        "scene": {"radar_position": [0.0, 0.0, radar_z], "gate": gate},
        "processing": {"window_length": 128, "hop": 32, "nfft": 256},
        "effects": effects,
    }
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AliasingWarning)
        res = simulate(validate_run_config(cfg))
    assert all_finite(res)
    assert [e["kind"] for e in res.metadata["effects"]] == sorted(
        (e["kind"] for e in effects),
        key=lambda k: (k in ("noise", "clutter"), [e["kind"] for e in effects].index(k)),
    )


@settings(PROPERTY, max_examples=10)
@given(
    speed=st.floats(0.0, 2.0),
    swing=st.floats(0.0, 40.0),
    cadence=st.floats(0.3, 1.5),
    placement=st.sampled_from(["joints17", "chen16"]),
)
def test_property_random_synthetic_walkers_have_no_nan_or_inf(
    registry: Registry, speed: float, swing: float, cadence: float, placement: str
) -> None:
    res = walker(
        registry,
        motion={
            "kind": "synthetic_walker",
            "length": 1.0,
            "speed": speed,
            "swing_deg": swing,
            "cadence_hz": cadence,
        },
        scatterers={"kind": "ellipsoid", "placement": placement, "height": 1.8},
    )
    assert all_finite(res)


range_history_st = st.integers(1, 12).flatmap(
    lambda k: st.tuples(
        st.lists(st.floats(-0.6, 0.6), min_size=k, max_size=k),
        st.lists(st.floats(-5.0, 5.0), min_size=k, max_size=k),
        st.lists(st.floats(0.05, 2.0), min_size=k, max_size=k),
    )
)


def _history(offsets: list[float], speeds: list[float]) -> np.ndarray:
    t = np.arange(1200) / 2400.0
    return 10.0 + np.array(offsets)[None, :] + np.outer(t, speeds)


@PROPERTY
@given(
    hist=range_history_st,
    shift=st.floats(1.0, 1e5),
    response=st.sampled_from(["exact", "sinc", "phase_only"]),
)
def test_property_doppler_content_unchanged_by_constant_range_shift(
    hist: tuple[list[float], list[float], list[float]], shift: float, response: str
) -> None:
    offsets, speeds, amps = hist
    r = _history(offsets, speeds)
    a = np.array(amps)[None, :] * np.ones_like(r)
    kw: dict[str, Any] = {
        "carrier_frequency": FC,
        "pulse_width": 1e-6,
        "bandwidth": 150e6,
        "response": response,
    }
    y0 = radar.compressed_return_at_gate(r, a, r[:, 0], **kw)
    y1 = radar.compressed_return_at_gate(r + shift, a, r[:, 0] + shift, **kw)
    s0 = spectrogram(y0, 2400.0, window_length=256, hop=64, precision="float64").power
    s1 = spectrogram(y1, 2400.0, window_length=256, hop=64, precision="float64").power
    assert np.allclose(s1, s0, rtol=1e-6, atol=1e-9 * s0.max())


@PROPERTY
@given(
    k=st.integers(1, 200), r=st.floats(1.0, 1e5), precision=st.sampled_from(["float64", "float32"])
)
def test_property_coherent_sum_of_k_unit_scatterers_at_one_range_is_k(
    k: int, r: float, precision: str
) -> None:
    ranges = np.full((4, k), r)
    y = radar.compressed_return_at_gate(
        ranges,
        np.ones_like(ranges),
        ranges[:, 0],
        carrier_frequency=FC,
        pulse_width=1e-6,
        bandwidth=150e6,
    )
    assert np.allclose(np.abs(y), k, rtol=1e-12)
    from mdf_lfm import LfmPulseDoppler

    wf = LfmPulseDoppler(LfmPulseDoppler.Config(precision=precision))
    rx = receive_points(wf, ranges, np.ones_like(ranges), ranges[:, 0]).signal
    a = radar.range_equation_amplitude(1.0, r, wavelength=LAM)
    assert np.allclose(np.abs(rx), k * a, rtol=1e-6 if precision == "float32" else 1e-12, atol=0)


@PROPERTY
@given(targets=st.lists(target_st, min_size=2, max_size=6), seed=st.integers(0, 1000))
def test_property_results_independent_of_scatterer_order(
    targets: list[dict[str, Any]], seed: int
) -> None:
    perm = np.random.default_rng(seed).permutation(len(targets))
    kw: dict[str, Any] = {"duration": 0.2, "processing": {"window_length": 128}}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AliasingWarning)
        a = point_run(targets, scene={"gate": 30.0}, **kw)
        b = point_run([targets[i] for i in perm], scene={"gate": 30.0}, **kw)
    scale = np.max(np.abs(a.received.signal)) + 1e-300
    assert np.allclose(a.received.signal, b.received.signal, rtol=1e-10, atol=1e-12 * scale)
    assert np.allclose(
        a.spectrogram.power, b.spectrogram.power, rtol=1e-8, atol=1e-12 * a.spectrogram.power.max()
    )
