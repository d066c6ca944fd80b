"""The fmcw and cw radars end to end (plugins mdf-fmcw and mdf-cw)."""

from __future__ import annotations

import warnings
from dataclasses import replace
from typing import Any

import numpy as np
import pytest
from conftest import EXAMPLES
from mdf_cw.waveform import CwConfig, CwDoppler
from mdf_fmcw.waveform import FmcwConfig, FmcwRadar
from mdf_lfm.waveform import LfmConfig, LfmPulseDoppler

from mdframework.config import load_run_config, validate_run_config
from mdframework.constants import SPEED_OF_LIGHT as C
from mdframework.errors import ConfigError, SceneError
from mdframework.interfaces import PulseBlock, Scatterers, receive_points
from mdframework.physics import radar
from mdframework.pipeline import simulate

QUIET = {"receiver_noise": False}
#: the IWR1443 short-range 3-D preset
IWR1443 = FmcwConfig(preset="iwr1443_short_range_3d")


def point_run(
    targets: list[dict[str, Any]],
    *,
    duration: float,
    radar: dict[str, Any],
    processing: dict[str, Any] | None = None,
) -> Any:
    """Point targets seen by ``radar`` at the origin (``processing``: that config section)."""
    cfg = {
        "motion": {"kind": "point_targets", "length": duration, "targets": targets},
        "scatterers": {"kind": "points"},
        "radar": radar,
        "scene": {"radar_position": [0.0, 0.0, 0.0]},
        "processing": processing or {},
    }
    return simulate(validate_run_config(cfg))


def fmcw_run(targets: list[dict[str, Any]], duration: float = 0.5, **radar_fields: Any) -> Any:
    """Point targets seen by the IWR1443 preset at the origin, looking along +x."""
    fields = {"kind": "fmcw", "preset": "iwr1443_short_range_3d", "boresight_azimuth_deg": 0.0}
    return point_run(targets, duration=duration, radar={**fields, **radar_fields})


@pytest.mark.parametrize(
    ("preset", "expected"),
    [
        (
            "iwr1443_short_range_3d",
            # range resolution, max range, centre GHz, chirp us, v_max, v_res, busy ms, sweep GHz
            (0.0436, 10.46, 79.20, 64.14, 4.92, 0.615, 3.08, 4.00),
        ),
        ("iwr6843isk_people_counting_6m", (0.0842, 8.08, 63.00, 89.1, 4.45, 0.0927, 25.66, 3.23)),
        (None, (0.0976, 24.98, 77.94, 70.0, 4.58, 0.286, 6.72, 1.80)),
    ],
)
def test_preset_derived_values_as_documented(
    preset: str | None, expected: tuple[float, ...]
) -> None:
    seq = FmcwConfig(preset=preset).sequence()  # type: ignore[arg-type]
    got = (
        seq.range_resolution,
        seq.max_range,
        seq.centre_frequency / 1e9,
        seq.chirp_period * 1e6,
        seq.max_velocity,
        seq.velocity_resolution,
        seq.chirps_per_frame * seq.chirp_period * 1e3,
        seq.slope * seq.ramp_end_time / 1e9,
    )
    for g, e in zip(got, expected, strict=True):
        digits = len(f"{e}".split(".")[1])
        assert round(g, digits) == pytest.approx(e, abs=10**-digits / 2 + 1e-12)


def test_explicit_fields_override_the_preset() -> None:
    c = FmcwConfig(preset="iwr6843isk_people_counting_6m", n_loops=32)
    assert c.n_loops == 32 and c.slope == 54.71e12 and c.tdm_order == [1, 2, 3]


@pytest.mark.parametrize(
    ("change", "field", "limit"),
    [
        ({"frame_period": 2e-3}, "frame_period:", "6.7200 ms"),
        ({"slope": 80e12}, "slope:", "4.0000 GHz"),
        ({"n_samples": 300}, "ramp_end_time:", "60.000 us"),
        ({"tdm_order": [1, 4]}, "tdm_order:", "TX 4"),
    ],
)
def test_impossible_settings_are_config_errors_naming_field_and_limit(
    change: dict[str, Any], field: str, limit: str
) -> None:
    cfg = {
        "motion": {"kind": "point_targets", "length": 1.0, "targets": [{"position": [3, 0, 0]}]},
        "scatterers": {"kind": "points"},
        "radar": {"kind": "fmcw", **change},
    }
    with pytest.raises(ConfigError) as err:
        validate_run_config(cfg, source="run.toml")
    msg = str(err.value)
    assert msg.startswith(f"run.toml: radar.{field}") and limit in msg
    assert "\n" not in msg


@pytest.mark.parametrize(
    ("change", "start", "limit"),
    [
        ({"slope": 2e15}, "radar.slope: must be at most", "1e+15"),
        ({"idle_time": 0.02}, "radar.idle_time: must be at most", "0.01"),
        ({"sample_rate": 2e9}, "radar.sample_rate: must be at most", "1e+09"),
        ({"n_loops": 5000}, "radar.n_loops: must be at most", "4096"),
        ({"tdm_order": [0]}, "radar.tdm_order.0: must be at least", "1"),
        ({"rx_positions": [[1e4, 0.0]]}, "radar.rx_positions.0.0: must be at most", "1000"),
        (
            {
                "n_loops": 1000,
                "tdm_order": [1],
                "tx_positions": [[0.0, 0.0]],
                "rx_positions": [[float(i), 0.0] for i in range(8)],
                "n_samples": 4096,
                "ramp_end_time": 9e-4,
                "slope": 4e12,
                "frame_period": 1.0,
            },
            "radar.n_samples: one frame's chirps x RX x range bins (1000 x 8 x 4096)",
            "the limit is 16,777,216",
        ),
        (
            {"doppler_fft_size": 65536, "range_fft_size": 4096},
            "radar.doppler_fft_size: one frame's virtual antennas x Doppler bins",
            "(12 x 65536 x 4096) is 3,221,225,472 complex values (about 48 GiB)",
        ),
    ],
)
def test_absurd_settings_are_refused_before_any_frame(
    change: dict[str, Any], start: str, limit: str
) -> None:
    """Each chirp, frame and antenna setting has a physical bound (docs/input-rules.md), and a
    frame whose largest array would exceed limits.MAX_FRAME_CELLS is refused with its memory."""
    cfg = {
        "motion": {"kind": "point_targets", "length": 1.0, "targets": [{"position": [3, 0, 0]}]},
        "scatterers": {"kind": "points"},
        "radar": {"kind": "fmcw", **change},
    }
    with pytest.raises(ConfigError) as err:
        validate_run_config(cfg, source="run.toml")
    msg = str(err.value)
    assert msg.startswith(f"run.toml: {start}") and limit in msg, msg


def test_scatterer_beyond_max_range_is_an_error_or_aliases() -> None:
    """Hard case: at 12 m the IWR1443's beat frequency (5.60 MHz) exceeds its 4.884 Msps ADC.
    Default: an error naming the field and the limit; ``beyond_max_range = "alias"``: the point
    appears at 12 - 10.46 = 1.54 m, as on the sensor (10 m^2: a 1 m^2 point at 12 m is 11 dB
    over the noise with the preset's 12 dBm and isotropic antennas, under the 15 dB CFAR)."""
    target = [{"position": [12.0, 0.0, 0.0], "rcs": 10.0}]
    with pytest.raises(SceneError, match=r"radar\.sample_rate.*12\.00 m.*4\.884 MHz.*10\.46 m"):
        fmcw_run(target, duration=0.2, **QUIET)
    res = fmcw_run(target, duration=0.2, beyond_max_range="alias")
    rd = res.received.products["range_doppler"]
    axis = FmcwRadar(IWR1443).axes()["range_m"]
    peaks = axis[np.argmax(rd.max(axis=1), axis=1)]
    np.testing.assert_allclose(peaks, 12.0 - 10.4585, atol=0.0436)
    pts = res.received.products["points"]
    best = pts[np.argmax(pts[:, 6])]
    assert np.linalg.norm(best[2:5]) == pytest.approx(12.0 - 10.4585, abs=0.0436)


def test_point_target_points_have_position_and_positive_approach_velocity() -> None:
    """A point approaching at 1.23 m/s (two velocity bins) 3 m away, 20 deg to the sensor's
    right and 0.5 m up: every frame's strongest point is there, at +1.23 m/s."""
    az = np.deg2rad(20.0)
    pos = np.array([3 * np.cos(az), -3 * np.sin(az), 0.5])  # sensor right = scene -y
    v = 2 * 0.61472423
    los = pos / np.linalg.norm(pos)
    res = fmcw_run([{"position": pos.tolist(), "velocity": (-v * los).tolist(), "rcs": 1.0}])
    pts = res.received.products["points"]
    frames = np.unique(pts[:, 0]).astype(int)
    assert frames.size == 15  # 0.5 s of 33.3 ms frames
    for f in frames:
        p = pts[pts[:, 0] == f]
        best = p[np.argmax(p[:, 6])]
        t = best[1]
        true = pos - v * los * t
        r = np.linalg.norm(true)
        assert np.linalg.norm(best[2:5]) == pytest.approx(r, abs=0.0436)
        assert best[2] / r == pytest.approx(np.sin(az) * np.cos(np.arcsin(true[2] / r)), abs=0.05)
        assert best[5] == pytest.approx(v, abs=1e-6)
        assert best[1] == pytest.approx(f * 33.333e-3)


@pytest.mark.parametrize("preset", ["iwr1443_short_range_3d", "iwr6843isk_people_counting_6m"])
def test_snr_of_a_point_target_follows_the_range_equation(preset: str) -> None:
    """The presets' data-sheet transmit power and noise figure make the SNR a prediction: a
    1 m^2 point on a range bin at boresight, static, peaks in the range-Doppler map (summed over
    the virtual antennas) at ``1 + SNR`` times the map's mean noise, with
    ``SNR = P_r / (k T0 F fs) x (sum w_r)^2 / sum w_r^2 x (sum w_d)^2 / sum w_d^2`` (the received
    power of the range equation over the noise of one complex ADC sample, times the coherent
    gain of the Hann-windowed range and Doppler FFTs), to 0.1 dB over 6 frames (0.03 dB
    measured)."""
    from mdframework.physics import fmcw

    cfg = FmcwConfig(preset=preset)  # type: ignore[arg-type]
    # the data sheets' values (docs/fmcw.md): 12 dBm; 16 dB (77-81 GHz) and 12 dB
    assert 10 * np.log10(cfg.transmit_power / 1e-3) == pytest.approx(12.0, abs=1e-12)
    assert cfg.noise_figure_db == {"iwr1443_short_range_3d": 16.0}.get(preset, 12.0)
    assert cfg.gain_dbi == 0.0
    wf = FmcwRadar(cfg)
    seq = wf.sequence
    r = 40 * seq.range_resolution  # on bin 40 (1.74 m and 3.37 m)
    res = fmcw_run(
        [{"position": [r, 0.0, 0.0], "rcs": 1.0}],
        duration=6 * seq.frame_period,
        preset=preset,
        clutter_removal=False,
    )
    maps = res.received.products["range_doppler"].astype(np.float64)
    assert maps.shape[0] == 6
    amp = cfg.amplitudes(np.ones(1), np.array([r]), seq.wavelength)[0]
    noise = wf.noise_power()
    assert noise == pytest.approx(
        1.380649e-23 * 290 * 10 ** (cfg.noise_figure_db / 10) * seq.sample_rate, abs=0
    )
    w_r, w_d = fmcw.window("hann", seq.n_samples), fmcw.window("hann", seq.n_loops)
    gain = np.sum(w_r) ** 2 / np.sum(w_r**2) * np.sum(w_d) ** 2 / np.sum(w_d**2)
    snr = amp**2 / noise * gain
    zero = (seq.n_loops - 1) // 2  # the zero-Doppler row
    peak = maps[:, zero, 40]
    assert np.all(np.argmax(maps.reshape(6, -1), axis=1) == zero * maps.shape[2] + 40)
    floor = np.mean(maps[:, :, 80:])  # every Doppler row, 40 bins and more beyond the target
    measured = 10 * np.log10(np.mean(peak) / floor)
    assert measured == pytest.approx(10 * np.log10(1 + snr), abs=0.1)
    # the figures of docs/fmcw.md: 44.3 and 44.9 dB here
    documented = {"iwr1443_short_range_3d": 44.3, "iwr6843isk_people_counting_6m": 44.9}
    assert round(10 * np.log10(1 + snr), 1) == documented[preset]


def test_a_point_under_the_threshold_near_the_maximum_range_as_documented() -> None:
    """docs/fmcw.md: a static 1 m^2 point on range bin 235 (10.24 m, inside the IWR1443
    preset's 10.46 m maximum range) stands 13.8 dB over the noise by the range equation and,
    measured over 30 frames, to 0.2 dB; under the 15 dB threshold it gives a point in at most
    3 of the 30 frames (a point 12 m away, the example before, is beyond the maximum range:
    the run stops)."""
    from mdframework.physics import fmcw

    wf = FmcwRadar(IWR1443)
    seq = wf.sequence
    k = 235
    r = k * seq.range_resolution
    assert round(r, 2) == 10.24 and round(seq.max_range, 2) == 10.46
    res = fmcw_run(
        [{"position": [r, 0.0, 0.0], "rcs": 1.0}],
        duration=30 * seq.frame_period,
        clutter_removal=False,
    )
    maps = res.received.products["range_doppler"].astype(np.float64)
    assert maps.shape[0] == 30
    amp = IWR1443.amplitudes(np.ones(1), np.array([r]), seq.wavelength)[0]
    w_r, w_d = fmcw.window("hann", seq.n_samples), fmcw.window("hann", seq.n_loops)
    gain = np.sum(w_r) ** 2 / np.sum(w_r**2) * np.sum(w_d) ** 2 / np.sum(w_d**2)
    predicted = 10 * np.log10(1 + amp**2 / wf.noise_power() * gain)
    assert round(predicted, 1) == 13.8
    floor = np.mean(maps[:, :, :150])  # 85 bins and more short of the target
    measured = 10 * np.log10(np.mean(maps[:, (seq.n_loops - 1) // 2, k]) / floor)
    assert measured == pytest.approx(predicted, abs=0.2)
    pts = res.received.products["points"]
    near = np.abs(np.linalg.norm(pts[:, 2:5], axis=1) - r) < 0.2
    assert np.unique(pts[near, 0]).size <= 3
    with pytest.raises(SceneError, match=r"radar\.sample_rate: the farthest scatterer at 12\.00"):
        fmcw_run([{"position": [12.0, 0.0, 0.0], "rcs": 1.0}], duration=seq.frame_period)


@pytest.mark.parametrize("range_window", ["hann", "rect"])
@pytest.mark.parametrize("doppler_window", ["hann", "rect"])
def test_range_doppler_map_is_the_received_power_in_watts(
    range_window: str, doppler_window: str
) -> None:
    """Absolute level of the ``range_doppler`` product (docs/fmcw.md: [W], summed over the
    virtual antennas): a static 0.5 m^2 point on boresight on range bin 40 (zero Doppler: on a
    Doppler bin too), without receiver noise, peaks at 12 P_r, the 3 x 4 virtual antennas times
    the received power of the radar range equation
    ``P_r = P_t G^2 lambda_c^2 sigma / ((4 pi)^3 R^4 L_s L_a)``, computed here from the config's
    fields, to 1e-5 (the map is stored in float32), with Hann and rectangular windows."""
    fields = {"transmit_power": 2.0, "gain_dbi": 6.0, "system_loss_db": 3.0}
    fields |= {"atmospheric_loss_db": 1.0, "clutter_removal": False, **QUIET}
    seq = FmcwConfig(preset="iwr1443_short_range_3d", **fields).sequence()  # type: ignore[arg-type]
    r, sigma = 40 * seq.range_resolution, 0.5
    res = fmcw_run(
        [{"position": [r, 0.0, 0.0], "rcs": sigma}],
        duration=2 * seq.frame_period,
        range_window=range_window,
        doppler_window=doppler_window,
        **fields,
    )
    maps = res.received.products["range_doppler"]
    assert maps.shape == (2, 16, 240)
    lam = C / seq.centre_frequency
    gain, loss = 10 ** (6.0 / 10), 10 ** ((3.0 + 1.0) / 10)
    p_r = 2.0 * gain**2 * lam**2 * sigma / ((4 * np.pi) ** 3 * r**4 * loss)
    for frame in maps:  # zero Doppler is row 7 of 16 (the ambiguous bin is the last row)
        assert np.unravel_index(np.argmax(frame), frame.shape) == (7, 40)
        assert float(frame[7, 40]) == pytest.approx(12 * p_r, rel=1e-5, abs=0)


def test_receive_is_block_invariant() -> None:
    """Four frames in one block or in two give the same signal, maps and points (the receiver
    noise is seeded per frame); ``receive_signal`` gives the same signal without them."""
    wf = FmcwRadar(IWR1443)
    t = wf.pulse_times(0.0, 4 * 33.333e-3)
    assert t.size == 4 * 48
    radar_pos = np.array([0.0, 0.0, 1.0])
    rng = np.random.default_rng(3)
    start = rng.uniform([2, -1, 0.5], [4, 1, 1.5], (5, 3))
    pos = start[None] + (t - t[0])[:, None, None] * np.array([-1.0, 0.2, 0.0])
    rcs = np.full(pos.shape[:2], 0.2)

    def block(lo: int, hi: int) -> PulseBlock:
        scat = Scatterers(pos[lo:hi], rcs[lo:hi], tuple("abcde"))
        ranges = scat.ranges(radar_pos)
        return PulseBlock(lo, t[lo:hi], scat, ranges, ranges[:, 0], radar_pos)

    wf = FmcwRadar(IWR1443.model_copy(update={"boresight_azimuth_deg": 0.0}))
    whole = wf.receive(block(0, 192))
    halves = [wf.receive(block(0, 96)), wf.receive(block(96, 192))]
    np.testing.assert_array_equal(whole.signal, np.concatenate([h.signal for h in halves]))
    for key in ("range_doppler", "points"):
        np.testing.assert_array_equal(
            whole.products[key], np.concatenate([h.products[key] for h in halves])
        )
    assert whole.products["points"].shape[0] > 4
    # the signal alone (clutter patches: no maps, no angle scans) is the same signal
    alone = [wf.receive_signal(block(0, 96)), wf.receive_signal(block(96, 192))]
    np.testing.assert_array_equal(whole.signal, np.concatenate(alone))


def test_spectrogram_follows_the_frame_timing() -> None:
    """With frame gaps, one Doppler spectrum per frame at its window's centre, over +-v_max;
    without gaps, the STFT at the loop rate."""
    v = 1.0
    res = fmcw_run([{"position": [3.0, 0.0, 0.0], "velocity": [-v, 0.0, 0.0]}], **QUIET)
    wf = FmcwRadar(IWR1443)
    seq = wf.sequence
    spec = res.spectrogram
    assert spec.time.shape == (15,)
    np.testing.assert_allclose(np.diff(spec.time), seq.frame_period, rtol=1e-9)
    assert spec.time[0] == pytest.approx(8 * seq.loop_period, rel=1e-9)  # Hann centre, 16 / 2
    vel = radar.doppler_to_velocity(spec.doppler, wf.carrier_frequency)
    assert vel[0] == pytest.approx(-seq.max_velocity, rel=1e-9)
    peaks = vel[np.argmax(spec.power, axis=0)]
    assert np.all(np.abs(peaks - v) < seq.velocity_resolution / 2)


@pytest.mark.parametrize(
    ("tdm_order", "v"),
    [([1, 3, 2], 1.0), ([1, 3, 2], -1.5), ([1], 1.0), ([1], -1.5)],
    ids=["3tx-approaching", "3tx-receding", "1tx-approaching", "1tx-receding"],
)
def test_gapless_frames_give_the_stft_at_the_loop_rate(tdm_order: list[int], v: float) -> None:
    """Frames without gaps (``frame_period = n_loops n_tx T_c``): the STFT of the first TDM
    slot's chirps, one sample per loop, so at the loop rate ``1 / (n_tx T_c)`` (5197 Hz with 3
    TX, 15590 Hz with 1). A point 3 m out on boresight approaching at ``v`` (receding when
    negative) peaks in every column at ``v`` within one velocity bin, with ``v = f_D lambda_c /
    2`` and ``f_c = f0 + S (adc_start_time + (n_samples - 1) / (2 fs))`` (docs/fmcw.md) from the
    preset's data; the columns are ``hop`` loops apart. (At the chirp rate instead, 1 m/s would
    show at 3 m/s with 3 TX.)"""
    base = FmcwConfig(preset="iwr1443_short_range_3d", tdm_order=tdm_order)
    seq = base.sequence()
    n_tx = len(tdm_order)
    loop = n_tx * 64.14e-6  # the preset's chirp period, 7 us idle + 57.14 us ramp
    res = point_run(
        [{"position": [3.0, 0.0, 0.0], "velocity": [-v, 0.0, 0.0]}],
        duration=0.3,
        radar={
            "kind": "fmcw",
            "preset": "iwr1443_short_range_3d",
            "tdm_order": tdm_order,
            "frame_period": seq.n_loops * loop,
            "boresight_azimuth_deg": 0.0,
            **QUIET,
        },
        processing={"window_length": 64, "hop": 16, "nfft": 256},
    )
    spec = res.spectrogram
    np.testing.assert_allclose(np.diff(spec.doppler), 1 / (loop * 256), rtol=1e-9)
    assert spec.doppler[0] == pytest.approx(-1 / (2 * loop), rel=1e-9)
    np.testing.assert_allclose(np.diff(spec.time), 16 * loop, rtol=1e-9)
    f_c = 77e9 + 70e12 * (7e-6 + 239 / (2 * 4.884e6))  # 79.20 GHz
    vel = spec.doppler * (C / f_c) / 2
    peaks = vel[np.argmax(spec.power, axis=0)]
    assert spec.time.size > 50
    assert np.max(np.abs(peaks - v)) <= vel[1] - vel[0]


@pytest.mark.parametrize("gapless", [True, False], ids=["stft", "per-frame"])
def test_spectrogram_follows_processing_precision(gapless: bool) -> None:
    """``processing.precision`` holds for both FMCW spectrogram paths (the STFT of frames
    without gaps, one spectrum per frame otherwise): float32 power by default, float64 on
    request, and the two agree as docs/accuracy.md states, to 0.005 dB at every cell within
    40 dB of the peak (3.4e-5 dB STFT, 1.1e-5 dB per frame measured), for two points and the
    preset's receiver noise."""
    from mdframework.physics.spectrogram import power_to_db

    seq = IWR1443.sequence()
    radar = {"kind": "fmcw", "preset": "iwr1443_short_range_3d", "boresight_azimuth_deg": 0.0}
    if gapless:
        radar["frame_period"] = seq.chirps_per_frame * seq.chirp_period
    targets = [
        {"position": [3.0, 0.0, 0.0], "velocity": [-1.0, 0.0, 0.0]},
        {"position": [2.0, 0.3, 0.0], "velocity": [0.7, 0.0, 0.0], "rcs": 0.1},
    ]
    stft = {"window_length": 64, "hop": 16, "nfft": 256}
    power = {}
    for precision in (None, "float32", "float64"):
        processing = stft if precision is None else {**stft, "precision": precision}
        res = point_run(targets, duration=0.5, radar=radar, processing=processing)
        power[precision] = res.spectrogram.power
        assert res.spectrogram.time.size == (159 if gapless else 15)
    assert power[None].dtype == np.float32
    assert power["float32"].dtype == np.float32
    assert power["float64"].dtype == np.float64
    np.testing.assert_array_equal(power[None], power["float32"])
    ref = power_to_db(power["float64"])
    support = ref > -40.0
    diff = np.abs(power_to_db(power["float32"].astype(np.float64)) - ref)[support]
    assert np.max(diff) < 0.005


def test_fmcw_and_lfm_spectrograms_of_the_same_walk_agree() -> None:
    """The side-by-side examples (matched carrier, bandwidth, slow-time rate, amplitudes and
    STFT, the FMCW gate four range resolutions wide): the dB spectrograms over the common time
    span correlate above 0.995 (0.9997 measured; 0.991 with a gate of two resolutions) and the
    strongest velocity of each column agrees within 0.1 m/s in 95 % of the columns."""
    lfm = simulate(load_run_config(EXAMPLES / "walk_side_by_side_lfm.toml"))
    fm = simulate(load_run_config(EXAMPLES / "walk_side_by_side_fmcw.toml"))
    n = min(lfm.spectrogram_db.shape[1], fm.spectrogram_db.shape[1])
    np.testing.assert_allclose(fm.spectrogram.time[:n], lfm.spectrogram.time[:n], atol=1e-9)
    a, b = lfm.spectrogram_db[:, :n], fm.spectrogram_db[:, :n]
    corr = float(np.corrcoef(a.ravel(), b.ravel())[0, 1])
    assert corr > 0.995
    va = lfm.velocity[np.argmax(a, axis=0)]
    vb = fm.velocity[np.argmax(b, axis=0)]
    assert np.mean(np.abs(va - vb) <= 0.1) >= 0.95


def test_cw_equals_the_lfm_phase_only_return() -> None:
    """Independent implementation: the CW baseband equals the LFM analytic return with a flat
    range response at the same carrier and rate, to 1e-12."""
    rng = np.random.default_rng(5)
    ranges = rng.uniform(3.0, 9.0, (400, 6))
    rcs = rng.uniform(0.01, 0.5, (400, 6))
    gate = ranges[:, 0]
    cw = receive_points(CwDoppler(CwConfig(carrier_frequency=24e9)), ranges, rcs, gate)
    lfm = LfmPulseDoppler(
        LfmConfig(
            carrier_frequency=24e9, prf=2000.0, gate_response="phase_only", precision="float64"
        )
    )
    ref = receive_points(lfm, ranges, rcs, gate)
    np.testing.assert_allclose(cw.signal, ref.signal, rtol=1e-12, atol=0)


def test_cw_doppler_at_24_ghz() -> None:
    """A point receding at 1 m/s: Doppler -2 v / lambda = -160.94 Hz at 24.125 GHz."""
    res = point_run(
        [{"position": [10.0, 0.0, 0.0], "velocity": [1.0, 0.0, 0.0]}],
        duration=1.0,
        radar={"kind": "cw", "carrier_frequency": 24.125e9, "sample_rate": 2000.0},
    )
    y = res.received.signal
    est = np.angle(np.sum(y[1:] * np.conj(y[:-1]))) * 2000.0 / (2 * np.pi)
    assert est == pytest.approx(-2 * 1.0 / radar.wavelength(24.125e9), rel=1e-9)
    assert est == pytest.approx(-160.94, abs=0.01)
    assert radar.max_unambiguous_velocity(24.125e9, 2000.0) == pytest.approx(6.21, abs=0.005)


def test_outputs_hold_maps_points_and_their_figures(tmp_path: Any) -> None:
    """A run writes the range-Doppler maps with their axes and the points into result.npz,
    the points as CSV (the same numbers), and a range-Doppler and a point-cloud figure."""
    from mdframework.output import POINTS_HEADER, write_run

    res = fmcw_run([{"position": [3.0, 0.5, 0.2], "velocity": [-1.0, 0.0, 0.0]}], duration=0.2)
    files = {p.name for p in write_run(res, {}, tmp_path / "run")}
    assert {"points.csv", "range_doppler.png", "point_cloud.png", "result.npz"} <= files
    with np.load(tmp_path / "run" / "result.npz") as r:
        maps, pts = r["range_doppler"], r["points"]
        assert maps.shape == (6, 16, 240) and maps.dtype == np.float32
        np.testing.assert_allclose(r["range_doppler_range_m"][1], 0.043577, atol=1e-6)
        np.testing.assert_allclose(
            r["range_doppler_velocity_mps"][[0, -1]], [-4.303, 4.918], atol=1e-3
        )
    lines = (tmp_path / "run" / "points.csv").read_text().splitlines()
    assert lines[0] == POINTS_HEADER
    table = np.loadtxt(tmp_path / "run" / "points.csv", delimiter=",", skiprows=1, ndmin=2)
    np.testing.assert_allclose(table, pts, rtol=1e-5, atol=1e-6)
    assert len(lines) - 1 == len(pts) > 0


def test_points_csv_keeps_the_frame_times_of_a_long_record(tmp_path: Any) -> None:
    """``points.csv`` keeps each point's time to a microsecond however far into the record:
    frames 33.333 ms apart, 1234.6 s and 3470.0 s in (a record of at most ``MAX_PULSES``
    chirps reaches an hour), read back at their times and in their order. Six significant
    digits rounded every time past 1000 s to 10 ms (1234.59 for 1234.5877 s), up to 15 % of a
    frame."""
    from mdframework.output import write_points_csv

    period = 33.333e-3
    frames = np.array([37038, 37039, 104101])
    pts = np.zeros((frames.size, 7))
    pts[:, 0], pts[:, 1], pts[:, 3] = frames, frames * period, 3.0
    write_points_csv(tmp_path / "points.csv", pts)
    table = np.loadtxt(tmp_path / "points.csv", delimiter=",", skiprows=1, ndmin=2)
    np.testing.assert_allclose(table[:, 1], pts[:, 1], rtol=0, atol=1e-6)
    np.testing.assert_array_equal(table[:, 0], frames)


def test_a_radar_section_without_kind_is_still_the_lfm_radar() -> None:
    """With several radars installed, a ``[radar]`` section that names no kind keeps meaning
    the default radar (as it did when ``lfm`` was the only one)."""
    cfg = validate_run_config(
        {
            "motion": {
                "kind": "point_targets",
                "length": 1.0,
                "targets": [{"position": [5, 0, 0]}],
            },
            "radar": {"carrier_frequency": 10e9},
        }
    )
    assert cfg.radar.kind == "lfm" and cfg.radar.carrier_frequency == 10e9  # type: ignore[attr-defined]


def test_the_pulse_budget_counts_chirps_and_iq_samples() -> None:
    """MAX_PULSES counts what the radar computes: the IWR1443 preset sends 48 chirps per
    33.333 ms frame (1440 per second; its slow-time rate within a frame, 1 / (3 x 64.14 us),
    says nothing of the gaps), a CW radar one I/Q sample per 1/sample_rate; a record over the
    limit is refused when the config is read."""
    from mdframework import limits

    assert FmcwConfig(preset="iwr1443_short_range_3d").pulse_rate() == pytest.approx(1440.0, 1e-4)
    sensor = FmcwRadar(IWR1443)
    assert sensor.pulse_rate == pytest.approx(1440.0, 1e-4)
    assert sensor.pulse_times(0.0, 10.0).size == 300 * 48  # what the budget bounds
    assert CwConfig(sample_rate=2000.0).pulse_rate() == 2000.0
    seconds = limits.MAX_PULSES / 1440.0 * 1.01  # just over the budget in chirps
    for radar_cfg in ({"kind": "fmcw", "preset": "iwr1443_short_range_3d"}, {"kind": "cw"}):
        cfg = {
            "motion": {
                "kind": "point_targets",
                "length": seconds,
                "targets": [{"position": [3, 0, 0]}],
            },
            "scatterers": {"kind": "points"},
            "radar": radar_cfg,
        }
        if radar_cfg["kind"] == "cw":
            cfg["radar"] = {"kind": "cw", "sample_rate": 1440.0}
        with pytest.raises(ConfigError, match=r"run\.toml: motion\.duration: .* pulses"):
            validate_run_config(cfg, source="run.toml")


def test_range_doppler_maps_beyond_the_product_limit_are_refused_before_the_first_frame() -> None:
    """One TX, one RX, 4096 x 4096 maps (64 MiB of float32 each) over 20 frames are 1.25 GiB,
    more than limits.MAX_PRODUCT_BYTES: refused naming save_range_doppler; without the maps
    the same radar is within every limit."""
    big = {
        "tdm_order": [1],
        "tx_positions": [[0.0, 0.0]],
        "rx_positions": [[0.0, 0.0]],
        "range_fft_size": 4096,
        "doppler_fft_size": 4096,
        "n_loops": 16,
        "frame_period": 0.05,
        "points": False,
        **QUIET,
    }
    target = [{"position": [3.0, 0.0, 0.0], "rcs": 1.0}]
    with pytest.raises(SceneError, match=r"radar\.save_range_doppler: .*20 frames.*1\.25 GiB"):
        fmcw_run(target, duration=1.0, **big)
    assert FmcwConfig(**{**big, "save_range_doppler": False}).n_loops == 16


def test_a_noise_free_detection_has_a_finite_intensity() -> None:
    """Hard case (found by benchmarks/fuzz_scenes.py): without receiver noise the analytic
    path leaves the CFAR training cells at exactly 0; the intensity of a detection over a
    noise estimate of 0 used to be +inf. Now it is finite (over the smallest positive float),
    and cells without power are never detections."""
    from mdframework.physics import fmcw

    radar_ = FmcwRadar(IWR1443)
    rd = np.zeros((12, 16, 240), dtype=np.complex128)
    rd[:, 8, 50] = 1e-3  # one target, nothing in its training cells
    axes = radar_.axes()
    grid = fmcw.angle_grid(radar_.antennas.virtual, radar_.sequence.wavelength)
    slots = radar_.antennas.slot_of_virtual(radar_.sequence)
    args = (radar_.sequence.chirp_period, radar_.sequence.wavelength)
    pts = fmcw.detect_points(
        rd, axes["range_m"], axes["doppler_hz"], grid, slots, *args, radar_.detection()
    )
    assert pts.shape[0] >= 1 and np.all(np.isfinite(pts))
    expected = 10 * np.log10(12 * 1e-6) - 10 * np.log10(np.finfo(np.float64).tiny)
    assert pts[0, 4] == pytest.approx(expected)
    # with the receiver's mean noise P as the floor (a run without receiver noise) the lone
    # target stands at 1 + SNR over it: (12 a^2 + P) / P
    floor = FmcwRadar(IWR1443).map_noise_power()
    detection = replace(radar_.detection(), noise_floor=floor)
    [pt] = fmcw.detect_points(
        rd, axes["range_m"], axes["doppler_hz"], grid, slots, *args, detection
    )
    assert pt[4] == pytest.approx(10 * np.log10(1 + 12 * 1e-6 / floor), abs=1e-5)  # cumsums


def test_a_gate_narrower_than_a_range_bin_reads_the_nearest_bin() -> None:
    """Hard case (fuzz): a 4 cm gate between two 4.4 cm bins selected no bin, so the slow-time
    signal was 0; now it reads the bin nearest to the gate, like a gate one bin wide."""
    from mdframework.physics import fmcw

    ranges = np.arange(8) * 0.0436
    profiles = np.zeros((1, 1, 8), dtype=np.complex128)
    profiles[0, 0, 3] = 1.0
    narrow = fmcw.gate_signal(profiles, ranges, np.array([3.2 * 0.0436]), 0.04, "hann", 8)
    wide = fmcw.gate_signal(profiles, ranges, np.array([3 * 0.0436]), 0.05, "hann", 8)
    assert abs(narrow[0]) > 0 and narrow[0] == pytest.approx(wide[0], abs=0)


def test_the_input_rules_page_states_the_radar_bounds_and_messages_of_the_code() -> None:
    """docs/input-rules.md: the FMCW table's bounds are the plugin's, and the messages it quotes
    are the ones the code gives."""
    import mdf_fmcw.waveform as w
    from conftest import ROOT

    page = " ".join((ROOT / "docs" / "input-rules.md").read_text().split())
    rows = {
        "at least 1e6 Hz/s (1 MHz/s), at most 1e15 Hz/s (1000 MHz/us)": w.MAX_SLOPE_HZ_PER_S == 1e15
        and w.MIN_SLOPE_HZ_PER_S == 1e6,
        "| 0 .. 10 ms (the ramp > 0) |": w.MAX_CHIRP_TIME_S == 10e-3,
        "| > 0, at most 1 GHz |": w.MAX_ADC_RATE_HZ == 1e9,
        "| 2 .. 16384 |": w.MAX_SAMPLES == 16384,
        "| 1 .. 4096 |": w.MAX_LOOPS == 4096,
        "1 .. 64 entries; TX numbers 1 .. 64": w.MAX_ANTENNAS == 64,
        "within +-1000 units of `antenna_spacing`": w.MAX_ANTENNA_UNITS == 1000,
        "| at most 65536 (and at least `n_samples`, `n_loops`) |": w.MAX_FFT == 65536,
        "| 1 Hz .. 10 MHz;": CwConfig.model_json_schema()["properties"]["sample_rate"]["maximum"]
        == 1e7,
    }
    for text, matches in rows.items():
        assert text in page and matches, text
    schema = FmcwConfig.model_json_schema()["properties"]
    assert schema["slope"]["maximum"] == w.MAX_SLOPE_HZ_PER_S
    assert schema["slope"]["minimum"] == w.MIN_SLOPE_HZ_PER_S
    assert schema["n_loops"]["maximum"] == w.MAX_LOOPS
    quoted = {
        "sample_rate": (1e6, "radar.ramp_end_time: the ADC samples until 247.000 us"),
        "n_loops": (2000, "radar.frame_period: 6000 chirps of 64.140 us need 384.8400 ms"),
        "slope": (100e12, "radar.slope: slope x ramp_end_time sweeps 5.7140 GHz"),
    }
    for field, (value, text) in quoted.items():
        cfg = {
            "motion": {
                "kind": "point_targets",
                "length": 1.0,
                "targets": [{"position": [3, 0, 0]}],
            },
            "radar": {"kind": "fmcw", "preset": "iwr1443_short_range_3d", field: value},
        }
        with pytest.raises(ConfigError) as err:
            validate_run_config(cfg, source="run.toml")
        assert f"run.toml: {text}" in str(err.value) and text in page, text
    with pytest.raises(SceneError) as scene_err:
        fmcw_run([{"position": [12.0, 0.0, 0.0], "rcs": 1.0}], duration=0.2, **QUIET)
    text = str(scene_err.value).split(": raise")[0]
    assert text in page, text


def test_a_record_shorter_than_one_frame_is_refused_naming_duration_and_minimum(
    tmp_path: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    """The IWR1443 preset's frame is 48 chirps of 64.14 us, 3.079 ms: a 3 ms record holds no
    frame. `mdf run` and `mdf check` both stop with one line naming motion.duration and the
    minimum (exit 2, not an IndexError); a record of one frame's chirps runs."""
    from mdframework import cli

    need = IWR1443.sequence().frame_active_time
    assert need == pytest.approx(48 * 64.14e-6, rel=1e-4)
    target = "{ position = [2.0, 0.0, 0.0], velocity = [0.0, 0.0, 0.0], rcs = 1.0 }"
    text = (
        '[motion]\nkind = "point_targets"\nlength = 0.1\nduration = DURATION\n'
        f"targets = [{target}]\n"
        '[scatterers]\nkind = "points"\n'
        '[radar]\nkind = "fmcw"\npreset = "iwr1443_short_range_3d"\n'
        "[scene]\nradar_position = [0.0, 0.0, 0.0]\n"
    )
    short = tmp_path / "short.toml"
    short.write_text(text.replace("DURATION", "0.003"))
    line = (
        "motion.duration: the 3.000 ms record holds no pulse of the fmcw radar, whose pulses "
        "need a record of at least 3.079 ms: lengthen motion.duration"
    )
    for command in (["run", str(short), "--out", str(tmp_path / "out")], ["check", str(short)]):
        assert cli.main(command) == 2
        err = capsys.readouterr().err
        assert err.strip() == f"mdf: error: {short}: {line}"
    assert not (tmp_path / "out").exists()
    one = tmp_path / "one.toml"
    one.write_text(text.replace("DURATION", f"{need + 1e-6:.7f}"))
    assert cli.main(["run", str(one), "--out", str(tmp_path / "one"), "--no-figures"]) == 0
    with np.load(tmp_path / "one" / "result.npz") as d:
        assert d["signal"].shape == (48,)


def test_one_loop_per_frame_gives_finite_points_at_zero_velocity() -> None:
    """n_loops = 1 with the preset's Hann Doppler window (was 0/0: a one-sample periodic Hann
    is [0]): a static 1 m^2 point 3 m ahead, 20 deg to the right, gives in every frame a
    strongest point there with v = 0 (the only Doppler bin) and a finite intensity."""
    az = np.deg2rad(20.0)
    pos = [3 * np.cos(az), -3 * np.sin(az), 0.0]  # sensor right = scene -y
    res = fmcw_run([{"position": pos, "velocity": [0.0, 0.0, 0.0], "rcs": 1.0}], 0.2, n_loops=1)
    pts = res.received.products["points"]
    assert np.all(np.isfinite(pts))
    assert res.received.products["range_doppler"].shape[1] == 1
    for f in range(6):  # 0.2 s of 33.3 ms frames
        p = pts[pts[:, 0] == f]
        best = p[np.argmax(p[:, 6])]
        assert np.linalg.norm(best[2:5]) == pytest.approx(3.0, abs=0.0436)
        assert best[2] / 3.0 == pytest.approx(np.sin(az), abs=0.05)
        assert best[5] == 0.0 and best[6] > 15.0


@pytest.mark.parametrize("tdm_order", [[1, 3, 2], [1, 3]])
def test_angles_come_from_the_virtual_antennas_of_the_used_transmitters(
    tdm_order: list[int],
) -> None:
    """Two points 3 m away, one on boresight at z = 0 approaching at 1.23 m/s, one 20 deg to the
    right and 0.5 m up receding at 1.23 m/s. With TX1, TX3, TX2 the strongest point of each is
    at its x and z; leaving TX2 (the one above the others) out of the TDM order leaves an
    azimuth-only array of 8 virtual antennas: x still right and z exactly 0, not the garbage
    elevations (z from -3 to +1 m) that the 4 zero channels of the unused TX gave."""
    az = np.deg2rad(20.0)
    b = np.array([np.sqrt(9 - 0.25) * np.cos(az), -np.sqrt(9 - 0.25) * np.sin(az), 0.5])
    v = 2 * 0.61472423
    targets = [
        {"position": [3.0, 0.0, 0.0], "velocity": [-v, 0.0, 0.0], "rcs": 1.0},
        {"position": b.tolist(), "velocity": (v * b / 3.0).tolist(), "rcs": 1.0},
    ]
    res = fmcw_run(targets, 0.2, tdm_order=tdm_order)
    pts = res.received.products["points"]
    for f in range(6):
        p = pts[pts[:, 0] == f]
        t = f * 33.333e-3
        for target, sign in zip(targets, (1.0, -1.0), strict=True):
            at = np.add(target["position"], t * np.asarray(target["velocity"]))
            near = p[p[:, 5] * sign > 0]  # approaching or receding
            best = near[np.argmax(near[:, 6])]
            assert np.linalg.norm(best[2:5]) == pytest.approx(np.linalg.norm(at), abs=0.05)
            assert best[2] == pytest.approx(-at[1], abs=0.1)  # sensor right = scene -y
            if len(tdm_order) == 3:
                assert best[4] == pytest.approx(at[2], abs=0.1)
            else:
                assert np.all(p[:, 4] == 0.0)


def test_without_receiver_noise_points_stand_over_the_receivers_mean_noise() -> None:
    """The defaults (no preset) add no receiver noise but extract points. A 1 m^2 point 3 m
    ahead approaching at 0.86 m/s used to give 36 points a frame over 0.98-4.78 m, the window
    sidelobes over training cells of 0 W, at up to 2905 dB. CFAR now works on the map plus the
    receiver's mean noise, so the noise-free cloud is the noisy run's: the same cells (range
    and Doppler bin) in every frame but two at the threshold's edge (of the seeded noise's
    draws), all within 0.4 m of the
    target, the intensities alike (to 2 dB over 30 dB: the noisy smallest-of estimate
    fluctuates), the strongest at most the on-bin 1 + SNR of the range equation (k T0 F fs
    through both FFTs, docs/fmcw.md)."""
    target = [{"position": [3.0, 0.0, 0.0], "velocity": [-0.86, 0.0, 0.0], "rcs": 1.0}]
    fields = {"kind": "fmcw", "boresight_azimuth_deg": 0.0}
    runs = {
        noise: point_run(target, duration=0.2, radar={**fields, "receiver_noise": noise})
        for noise in (False, True)
    }
    quiet, noisy = (runs[n].received.products["points"] for n in (False, True))
    radar_ = FmcwRadar(FmcwConfig())
    seq = radar_.sequence
    cells = []  # (frame, range bin, velocity) -> the strongest intensity there [dB]
    for pts in (quiet, noisy):
        rbin = np.round(np.linalg.norm(pts[:, 2:5], axis=1) / seq.range_resolution)
        best: dict[tuple[int, int, float], float] = {}
        for f, k, v, db in zip(pts[:, 0], rbin, np.round(pts[:, 5], 3), pts[:, 6], strict=True):
            key = (int(f), int(k), float(v))
            best[key] = max(best.get(key, -np.inf), float(db))
        cells.append(best)
    assert len(cells[0]) >= 20 and len(cells[0].keys() ^ cells[1].keys()) <= 2
    both = cells[0].keys() & cells[1].keys()
    for k in both:
        assert abs(cells[0][k] - cells[1][k]) < (2.0 if cells[1][k] > 30.0 else 3.0)
    r = np.linalg.norm(quiet[:, 2:5], axis=1)
    assert np.all(np.abs(r - (3.0 - 0.86 * quiet[:, 1])) < 0.4)  # 4 range bins
    a2 = float(radar_.config.amplitudes(np.ones(1), np.full(1, 3.0), seq.wavelength)[0] ** 2)
    snr = a2 * 12 / radar_.map_noise_power()  # the map sums 12 antennas' signal and noise
    assert 15.0 < quiet[:, 6].max() <= 10 * np.log10(1 + snr)


def test_the_ambiguous_doppler_bin_as_documented() -> None:
    """docs/fmcw.md: with the IWR1443 preset's 16 Doppler bins the simulated axis runs from
    -4.30 to +4.92 m/s (the ambiguous bin last, read as approaching), the same bins as the real
    RadHAR points, their range rate negated by the reader (the shipped boxing subset holds points
    in both end bins). Points approaching or receding at 0.97 v_max fall in the ambiguous bin
    and are both reported at +v_max, as the sensor would; one receding at 0.85 v_max at
    -7/8 v_max, its nearest bin."""
    from mdf_radhar.source import npz_recordings

    radar_ = FmcwRadar(IWR1443)
    v = radar_.axes()["velocity_mps"]
    v_max = radar_.max_unambiguous_velocity
    assert v[-1] == pytest.approx(v_max, rel=1e-12) and v[-1] == pytest.approx(4.92, abs=5e-3)
    assert v[0] == pytest.approx(-7 / 8 * v_max, rel=1e-12) and round(v[0], 2) == -4.30
    step = 2 * v_max / 16
    real = np.concatenate(
        [
            c.velocity
            for _, c in npz_recordings(EXAMPLES / "data" / "radhar" / "radhar_boxing_subset.npz")
        ]
    )
    bins = np.round(real / step)
    assert bins.max() == 8 and bins.min() == -7
    assert set(np.unique(bins)) <= set(np.round(v / step))  # every real bin is a simulated one
    for speed, want in ((0.97, v_max), (-0.97, v_max), (-0.85, -7 / 8 * v_max)):
        target = [{"position": [3.0, 0.0, 0.0], "velocity": [-speed * v_max, 0.0, 0.0]}]
        res = fmcw_run(target, duration=2 * 33.333e-3, **QUIET)
        pts = res.received.products["points"]
        strongest = pts[np.argmax(pts[:, 6])]
        assert strongest[5] == pytest.approx(want, rel=1e-9)


def test_zero_padded_range_doppler_maps_peak_on_their_axes() -> None:
    """The map's axes with FFTs longer than the data (``range_fft_size`` 480 for 240 samples,
    an odd ``doppler_fft_size`` of 33 for 16 loops): a point approaching on boresight at
    Doppler bin +2 of the 33 (0.596 m/s, zero Doppler on row 16) from 3.5 m, between two
    bins of the 2.2 cm grid, peaks in every frame on row 18 (``range_doppler_velocity_mps``
    exactly +v) and on the range bin nearest to its range at the frame's middle chirp
    (``range_doppler_range_m``, within half a bin)."""
    radar_ = FmcwRadar(
        FmcwConfig(preset="iwr1443_short_range_3d", range_fft_size=480, doppler_fft_size=33)
    )
    seq, axes = radar_.sequence, radar_.axes()
    ranges, velocity = axes["range_m"], axes["velocity_mps"]
    assert velocity[16] == 0.0
    v, r0 = float(velocity[18]), 3.5
    res = fmcw_run(
        [{"position": [r0, 0.0, 0.0], "velocity": [-v, 0.0, 0.0]}],
        duration=0.2,
        range_fft_size=480,
        doppler_fft_size=33,
        **QUIET,
    )
    maps = res.received.products["range_doppler"]
    np.testing.assert_array_equal(res.received.products["range_doppler_range_m"], ranges)
    assert maps.shape == (6, 33, 480)
    for f, frame in enumerate(maps):
        row, col = np.unravel_index(np.argmax(frame), frame.shape)
        middle = f * seq.frame_period + seq.idle_time + seq.frame_active_time / 2
        assert row == 18
        assert abs(ranges[col] - (r0 - v * middle)) <= (ranges[1] - ranges[0]) / 2


def test_the_aliasing_advice_names_the_fields_that_set_the_slow_time_rate() -> None:
    """The default FMCW radar (3 TX, 70 us chirps: loop rate 4762 Hz, v_max 4.58 m/s) and a
    point approaching at 5.5 m/s: the error names the chirp timing and the TDM order (fmcw has
    no prf field) with the chirp period that reaches 4 v / lambda; that period, or one TX,
    runs. The CW radar names its sample_rate."""
    target = [{"position": [3.0, 0.0, 0.0], "velocity": [-5.5, 0.0, 0.0], "rcs": 1.0}]
    fields = {"kind": "fmcw", "boresight_azimuth_deg": 0.0, "points": False}
    error = {"aliasing": "error"}
    with pytest.raises(SceneError) as info:
        point_run(target, duration=0.2, radar=fields, processing=error)
    seq = FmcwConfig().sequence()
    rate = 4 * 5.5 / seq.wavelength
    period = 1 / (3 * rate)
    text = str(info.value)
    assert "prf" not in text.replace("PRF", "")
    assert (
        f"raise the loop rate to at least {np.ceil(rate):.0f} Hz: shorten radar.idle_time + "
        f"radar.ramp_end_time from 70.00 us to at most {np.floor(period * 1e8) / 100:.2f} us, "
        "or use fewer "
        "than 3 TX in radar.tdm_order (processing.aliasing = 'error' stops such runs)"
    ) in text
    advised = np.floor(period * 1e8) / 1e8  # as printed, rounded down
    for change in ({"idle_time": 1e-6, "ramp_end_time": advised - 1e-6}, {"tdm_order": [1]}):
        point_run(target, duration=0.2, radar={**fields, **change}, processing=error)
    cw = {"kind": "cw", "carrier_frequency": 24e9, "sample_rate": 1000.0}
    with pytest.raises(SceneError, match=r"aliases; raise radar\.sample_rate to at least 1762 Hz"):
        point_run(target, duration=0.3, radar=cw, processing=error)  # 301 > 256-sample window


def test_the_noise_effect_is_refused_beside_the_radars_own_receiver_noise() -> None:
    """The presets add the receiver's thermal noise to the IF samples; the noise effect on top
    would count it twice (and its snr_db would not be the result's SNR): one error naming both
    fields. Without receiver_noise the effect runs and is the only noise."""
    target = [{"position": [3.0, 0.0, 0.0], "velocity": [-1.0, 0.0, 0.0], "rcs": 1.0}]
    radar_ = {"kind": "fmcw", "preset": "iwr1443_short_range_3d", "boresight_azimuth_deg": 0.0}
    cfg = {
        "motion": {"kind": "point_targets", "length": 0.2, "targets": target},
        "scatterers": {"kind": "points"},
        "radar": radar_,
        "scene": {"radar_position": [0.0, 0.0, 0.0]},
        "effects": [{"kind": "noise", "snr_db": 20.0}],
    }
    with pytest.raises(SceneError, match=r"^effects.noise: the 'fmcw' radar adds receiver noise"):
        simulate(validate_run_config(cfg))
    # without maps and points (else the noise goes into the IF samples: mode 'thermal')
    cfg["radar"] = {**radar_, "receiver_noise": False, "points": False, "save_range_doppler": False}
    quiet = {**cfg, "effects": []}
    noisy = simulate(validate_run_config(cfg)).received.signal
    clean = simulate(validate_run_config(quiet)).received.signal
    snr = np.mean(np.abs(clean) ** 2) / np.mean(np.abs(noisy - clean) ** 2)
    assert 10 * np.log10(snr) == pytest.approx(20.0, abs=0.5)


def test_a_gate_of_four_range_resolutions_is_flat_and_a_narrower_one_warns() -> None:
    """The side-by-side example's radar (1 m range resolution): with its 4 m gate a point
    target anywhere within 1 m of the gate's centre comes through at its amplitude to 2 %
    (sqrt_rcs: |y| = 1 for 1 m^2); a 2 m gate (two resolutions) weighed the same target
    0.76 on the gate and 0.85 half a bin off, and is warned about, naming the field and the
    width that is flat."""
    radar_ = load_run_config(EXAMPLES / "walk_side_by_side_fmcw.toml").radar.model_dump()

    def level(offset: float, width: float) -> float:
        cfg = {
            "motion": {
                "kind": "point_targets",
                "length": 0.5,
                "targets": [{"position": [30.0 + offset, 0.0, 0.0], "rcs": 1.0}],
            },
            "scatterers": {"kind": "points"},
            "radar": {**radar_, "gate_width": width},
            "scene": {"radar_position": [0.0, 0.0, 0.0], "gate": 30.0},
        }
        return float(np.median(np.abs(simulate(validate_run_config(cfg)).received.signal)))

    for offset in (0.0, 0.25, 0.5, 0.8, 1.0):
        assert level(offset, 4.0) == pytest.approx(1.0, abs=0.02)
    with pytest.warns(UserWarning, match=r"radar.gate_width: 2 m spans 2\.0 range resolutions"):
        narrow = level(0.0, 2.0)
    assert narrow < 0.8


@pytest.mark.parametrize(
    ("path", "range_fft_size"), [("analytic", None), ("analytic", 512), ("raw", None)]
)
def test_each_scatterers_response_is_its_lone_receive(
    path: str, range_fft_size: int | None
) -> None:
    """``point_responses`` (the clutter patches' responses, FMCW's ``receive_each``: all the
    scatterers in one pass over the frames, at the gate's bins only) gives each scatterer's
    own slow-time signal: a receive of that scatterer alone, to 1e-12 of the largest, with
    three TXs in turn, a padded range FFT, a gate that moves and a radar off the origin; the
    receiver noise of the preset is left out of both."""
    from mdframework import point_responses

    wf = FmcwRadar(
        FmcwConfig(preset="iwr1443_short_range_3d", path=path, range_fft_size=range_fft_size)
    )
    t = wf.pulse_times(0.0, 0.2)
    n = t.size
    gate = np.linspace(3.0, 2.6, n)
    r = np.random.default_rng(4).uniform(2.2, 3.5, 12)  # inside, at the edge and outside the gate
    origin = np.array([0.5, -1.0, 1.0])
    each = point_responses(
        wf, np.broadcast_to(r, (n, r.size)), np.ones((n, r.size)), gate, origin, t
    )
    alone = np.stack([
        receive_points(wf, np.full((n, 1), ri), np.ones((n, 1)), gate, origin, t).signal for ri in r
    ])  # fmt: skip
    assert each.shape == (r.size, n) and np.all(np.abs(alone).max(axis=1) > 0)
    np.testing.assert_allclose(each, alone, rtol=0, atol=1e-12 * np.abs(alone).max())


def test_each_scatterers_response_on_a_radar_without_its_own() -> None:
    """The interface's default ``receive_each`` (LFM): each scatterer's lone receive, exactly."""
    from mdframework import point_responses

    wf = LfmPulseDoppler(LfmConfig(precision="float64"))
    ranges = np.random.default_rng(6).uniform(9.0, 11.0, (300, 5))
    gate = np.full(300, 10.0)
    each = point_responses(wf, ranges, np.ones_like(ranges), gate)
    for i in range(5):
        alone = receive_points(wf, ranges[:, i : i + 1], np.ones((300, 1)), gate).signal
        np.testing.assert_array_equal(each[i], alone)


def test_the_default_receive_each_passes_each_scatterers_shape_along() -> None:
    """The default ``receive_each`` gives the radar each scatterer with its shape fields
    (``Scatterers.only``), for a radar that reads them."""
    rng = np.random.default_rng(2)
    n, k = 50, 3
    scat = Scatterers(
        rng.uniform(5, 6, (n, k, 3)),
        np.ones((n, k)),
        ("a", "b", "c"),
        semi_axes=rng.uniform(0.05, 0.2, (k, 3)),
        axes=rng.normal(size=(n, k, 3)),
        centres=rng.uniform(5, 6, (n, k, 3)),
        specular=np.array([True, False, True]),
    )
    one = scat.only(2)
    assert one.names == ("c",) and one.positions.shape == (n, 1, 3)
    assert one.semi_axes is not None and np.array_equal(one.semi_axes, scat.semi_axes[2:])
    assert one.axes is not None and np.array_equal(one.axes, scat.axes[:, 2:])
    assert one.centres is not None and np.array_equal(one.centres, scat.centres[:, 2:])
    assert one.specular is not None and one.specular.tolist() == [True]

    seen: list[tuple[str, ...]] = []

    class Shaped(LfmPulseDoppler):
        def receive_signal(self, block: PulseBlock) -> Any:
            assert block.scatterers.semi_axes is not None and not block.receiver_noise
            seen.append(block.scatterers.names)
            return super().receive_signal(block)

    wf = Shaped(LfmConfig(precision="float64"))
    t = np.arange(n) / wf.prf
    ranges = np.linalg.norm(scat.positions, axis=-1)
    each = wf.receive_each(PulseBlock(0, t, scat, ranges, ranges[:, 0], np.zeros(3)))
    assert each.shape == (k, n) and seen == [("a",), ("b",), ("c",)]


def test_the_receiver_noise_follows_the_runs_seed_unless_noise_seed_is_given() -> None:
    """The run's `seed` is the seed of every random draw: the receiver noise was seeded by
    `noise_seed` (default 0) alone, so that runs of any seed, and every record of a dataset,
    had the same noise. Without `noise_seed` it is the run's seed now: seed 0 keeps the noise
    it always had; a `noise_seed` given is the same whatever the run's seed."""

    def signal(seed: int, **radar: Any) -> np.ndarray:
        cfg = {
            "motion": {"kind": "point_targets", "length": 0.1, "targets": TARGET},
            "scatterers": {"kind": "points"},
            "radar": {"kind": "fmcw", "preset": "iwr1443_short_range_3d", **radar},
            "scene": {"radar_position": [0.0, 0.0, 0.0]},
            "seed": seed,
        }
        return np.asarray(simulate(validate_run_config(cfg)).received.signal)

    one, two = signal(1), signal(2)
    assert not np.array_equal(one, two)
    assert np.array_equal(signal(0), signal(0, noise_seed=0))
    assert np.array_equal(signal(1, noise_seed=5), signal(2, noise_seed=5))
    assert np.array_equal(signal(0), signal(3, noise_seed=0))  # 0 given is not "not given"
    assert np.array_equal(one, signal(1))
    assert np.array_equal(one, signal(7, noise_seed=1))  # the run's seed stands for noise_seed


TARGET = [{"position": [0.0, 3.0, 0.0], "velocity": [0.0, -1.0, 0.0], "rcs": 1.0}]


@pytest.mark.parametrize("gate", [10.0, 20.0])
def test_a_fixed_gate_that_misses_the_target_is_an_empty_result(gate: float) -> None:
    """A 77 GHz sensor (maximum range 12.49 m) with a fixed 2 m gate at 10 m (inside the
    range) or 20 m (beyond it) while its point target closes from 5 to 4 m: the gate reads
    only the target's range sidelobes (1e-7 of its amplitude at 10 m, a clean Doppler line in
    a spectrogram scaled to its own peak) or nothing, and the run warns that the gate misses
    the scatterers, naming scene.gate (it said nothing at 10 m and blamed the range equation
    at 20 m). The same gate on the target is not warned about."""
    from mdframework.pipeline import EmptyResultWarning

    radar_ = {
        "kind": "fmcw",
        "slope": 60e12,
        "idle_time": 100e-6,
        "ramp_end_time": 60e-6,
        "sample_rate": 5e6,
        "n_samples": 256,
        "n_loops": 32,
        "frame_period": 0.05,
        "points": False,
        "save_range_doppler": False,
    }

    def run(at: float) -> Any:
        cfg = {
            "motion": {
                "kind": "point_targets",
                "length": 1.0,
                "targets": [{"position": [5.0, 0.0, 0.0], "velocity": [-1.0, 0.0, 0.0]}],
            },
            "scatterers": {"kind": "points"},
            "radar": radar_,
            "scene": {"radar_position": [0.0, 0.0, 0.0], "gate": at},
        }
        return simulate(validate_run_config(cfg))

    with pytest.warns(EmptyResultWarning, match=rf"fixed range gate at {gate:g} m misses"):
        run(gate)
    with warnings.catch_warnings():
        warnings.simplefilter("error", EmptyResultWarning)
        assert np.abs(run(4.5).received.signal).min() > 0


def test_a_target_beyond_the_unambiguous_range_of_the_prf_is_warned_about() -> None:
    """An X-band pulse-Doppler radar at PRF 1 MHz has the unambiguous range
    c / (2 PRF) = 149.9 m: a target at 300 m returns two pulses later (a real radar sees it at
    300 m modulo 149.9 m, 0.2 m). The run warns naming radar.prf, the range and the PRF that
    reaches it, and so it does for a target at 200 m (seen at 50.1 m); at PRF 10 kHz (14.99 km)
    it does not."""
    target = [{"position": [300.0, 0.0, 0.0], "velocity": [-2.0, 0.0, 0.0]}]
    radar_ = {"kind": "lfm", "carrier_frequency": 10e9, "bandwidth": 1e6, "pulse_width": 1e-6}
    seen = r"radar\.prf: .* 300(\.0)? m .* 149\.9 m .* sees it at 0\.2075 m .* 499\.7 kHz"
    with pytest.warns(UserWarning, match=seen):
        point_run(target, duration=0.05, radar={**radar_, "prf": 1e6})
    nearer = [{"position": [200.0, 0.0, 0.0], "velocity": [-2.0, 0.0, 0.0]}]
    with pytest.warns(UserWarning, match=r"radar\.prf: .* 200(\.0)? m .* sees it at 50\.1 m"):
        point_run(nearer, duration=0.05, radar={**radar_, "prf": 1e6})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        point_run(target, duration=0.05, radar={**radar_, "prf": 1e4})


@pytest.mark.parametrize(
    ("radar_", "start"),
    [
        ({"kind": "lfm", "prf": 1e4, "pulse_width": 2e-4}, "radar.pulse_width: 0.0002 s is "),
        ({"kind": "lfm", "carrier_frequency": 1e9, "bandwidth": 3e9}, "radar.bandwidth: 3e+09 Hz"),
        ({"kind": "lfm", "bandwidth": 1e5}, "radar.bandwidth: bandwidth x pulse_width"),
        ({"kind": "lfm", "path": "raw", "sample_rate": 1e8}, "radar.sample_rate: 1e+08 Hz is "),
        ({"kind": "fmcw", "range_fft_size": 100}, "radar.range_fft_size: 100 is below n_samples"),
        ({"kind": "fmcw", "n_loops": 16, "doppler_fft_size": 8}, "radar.doppler_fft_size: 8 is "),
    ],
)
def test_inconsistent_pulse_and_fft_settings_name_their_field(
    radar_: dict[str, Any], start: str
) -> None:
    """A pulse longer than its interval, a band reaching 0 Hz, and the other checks across a
    radar's fields read 'radar: pulse_width (...) must ...' without the field in the
    location; they now name it as every other field error does ('radar.pulse_width: ...')."""
    cfg = {
        "motion": {"kind": "point_targets", "length": 1.0, "targets": [{"position": [3, 0, 0]}]},
        "scatterers": {"kind": "points"},
        "radar": radar_,
    }
    with pytest.raises(ConfigError) as err:
        validate_run_config(cfg, source="run.toml")
    msg = str(err.value)
    assert msg.startswith(f"run.toml: {start}"), msg
    assert "\n" not in msg


def test_the_gate_gain_folds_ranges_as_the_range_fft_does() -> None:
    """The empty-result check's gate_gain (maximum range 49.97 m, resolution 0.195 m, the
    margin 3 resolutions, a 2 m gate): a scatterer within the margin of the bins the gate reads
    reaches it, one farther does not; a range beyond the maximum counts where its beat
    frequency folds (120 m reads as 20 m), the range FFT is cyclic (0.05 m is next to the
    last bin, 49.77 m), and a gate beyond the axis reads its nearest bin."""
    wf = FmcwRadar(FmcwConfig(sample_rate=10e6))
    assert wf.sequence.max_range == pytest.approx(49.965, abs=1e-3)

    def gain(at: float, gate: float) -> float:
        return float(wf.gate_gain(np.array([[at]]), np.array([gate]))[0, 0])

    assert gain(20.3, 20.0) == 1.0 and gain(25.0, 20.0) == 0.0
    assert gain(120.0, 20.0) == 1.0 and gain(125.0, 20.0) == 0.0  # folded: 20.0 and 25.0 m
    assert gain(0.05, 49.9) == 1.0  # cyclic: across the end of the axis
    assert gain(49.7, 60.0) == 1.0 and gain(45.0, 60.0) == 0.0  # the last bin, 49.77 m
