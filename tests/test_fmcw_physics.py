"""FMCW chirp-sequence physics against analytic references (mdframework.physics.fmcw)."""

from __future__ import annotations

import numpy as np
import pytest

from mdframework.constants import SPEED_OF_LIGHT as C
from mdframework.physics import fmcw

#: The IWR1443 short-range 3-D demo timing (start 77 GHz, 70 MHz/us, 240 samples at 4.884 Msps,
#: idle 7 us, ramp 57.14 us, TX order 1-3-2, 16 loops, 33.333 ms frames).
SEQ = fmcw.ChirpSequence(77e9, 70e12, 7e-6, 7e-6, 57.14e-6, 4.884e6, 240, 16, (0, 2, 1), 33.333e-3)
HALF = C / SEQ.centre_frequency / 2.0
#: TX1 (0, 0), TX2 (lambda, lambda/2 up), TX3 (2 lambda, 0); four RX lambda/2 apart; the
#: virtual array centred on the sensor's position.
ANT = fmcw.Antennas(
    tx=np.array([[0.0, 0.0], [2.0, 1.0], [4.0, 0.0]]) * HALF,
    rx=np.array([[k, 0.0] for k in range(4)]) * HALF,
).centred()
AXES = fmcw.sensor_axes(0.0, 0.0)  # boresight along +x of the scene, x_s = -y, z_s = +z
RADAR = np.array([0.0, 0.0, 1.0])


def scene_point(rng: float, az_deg: float, el_deg: float) -> np.ndarray:
    """Scene position of a point at sensor range, azimuth (to the sensor's right), elevation."""
    az, el = np.deg2rad(az_deg), np.deg2rad(el_deg)
    local = rng * np.array([np.sin(az) * np.cos(el), np.cos(az) * np.cos(el), np.sin(el)])
    return np.asarray(RADAR + local @ AXES)


def one_frame(
    start: np.ndarray, velocity: np.ndarray, path: str, seq: fmcw.ChirpSequence = SEQ
) -> np.ndarray:
    """Range profiles (chirps_per_frame, n_rx, n_samples) of a point moving at ``velocity``."""
    t = fmcw.chirp_times(seq, 0.0, seq.frame_period)
    pos = (start[None, :] + t[:, None] * velocity[None, :])[:, None, :]
    return fmcw.chirp_profiles(
        pos,
        np.ones((t.size, 1)),
        RADAR,
        AXES,
        seq,
        ANT,
        window_name="hann",
        n_fft=seq.n_samples,
        path=path,  # type: ignore[arg-type]
    )


def frame_points(profiles: np.ndarray, seq: fmcw.ChirpSequence = SEQ, **kw: object) -> np.ndarray:
    cube = fmcw.virtual_cube(profiles, seq, 3)
    rd = fmcw.range_doppler(cube, "hann", seq.n_loops)
    grid = fmcw.angle_grid(ANT.virtual, seq.wavelength)
    settings = fmcw.Detection(cfar_range=None, multi_peak=None, **kw)  # type: ignore[arg-type]
    pts = fmcw.detect_points(
        rd,
        fmcw.range_axis(seq, seq.n_samples),
        fmcw.doppler_axis(seq, seq.n_loops),
        grid,
        ANT.slot_of_virtual(seq),
        seq.chirp_period,
        seq.wavelength,
        settings,
    )
    # the strongest point (no noise: every other "detection" is a sidelobe)
    power = fmcw.detection_map(rd)
    return pts, power


def test_derived_quantities_of_the_iwr1443_demo() -> None:
    # the values the RadHAR driver used: range bin 0.043577 m, 10.46 m, 4.92 m/s
    assert SEQ.range_resolution == pytest.approx(C / (2 * 70e12 * 240 / 4.884e6), rel=1e-12)
    assert SEQ.range_resolution == pytest.approx(0.043577, abs=1e-6)
    assert SEQ.max_range == pytest.approx(10.4585, abs=1e-4)
    assert SEQ.max_velocity == pytest.approx(C / SEQ.centre_frequency / (4 * 3 * 64.14e-6))
    assert SEQ.max_velocity == pytest.approx(4.918, abs=2e-3)
    assert SEQ.velocity_resolution == pytest.approx(2 * SEQ.max_velocity / 16)
    assert SEQ.problems(4e9) == []


def test_beat_frequency_is_2SR_over_c() -> None:
    """The IF of a point at R is a tone at -2 S R / c (the conjugate-mixer convention)."""
    r = np.array([[1.7], [4.5]])  # beat frequencies below fs / 2 for the phase estimator
    y = fmcw.if_samples(2 * r / C, np.ones_like(r), SEQ)
    est = np.angle(np.sum(y[:, 1:] * np.conj(y[:, :-1]), axis=1)) * SEQ.sample_rate / (2 * np.pi)
    np.testing.assert_allclose(-est, fmcw.beat_frequency(r[:, 0], SEQ.slope), rtol=1e-9)
    assert float(fmcw.beat_frequency(1.0, 70e12)) == pytest.approx(2 * 70e12 / C, rel=1e-15)
    # the range profile peaks at the bin of that range, refined to well within a bin
    prof = np.abs(fmcw.range_profile(y, "hann", 1024))
    axis = fmcw.range_axis(SEQ, 1024)
    np.testing.assert_allclose(axis[np.argmax(prof, axis=1)], r[:, 0], atol=axis[1] / 2 + 1e-12)


@pytest.mark.parametrize("n_samples", [240, 37, 5])
@pytest.mark.parametrize(("r_min", "r_max", "rtol"), [(0.3, 10.0, 1e-12), (50.0, 3000.0, 1e-9)])
def test_if_samples_are_the_mixer_output_sample_by_sample(
    n_samples: int, r_min: float, r_max: float, rtol: float
) -> None:
    """The IF samples (built from tables of exponentials) equal the de-chirped mixer output
    ``sum_i a_i exp(-j 2 pi (f0 tau + S tau (t0 + m/fs) - S tau^2 / 2))`` written out sample by
    sample, for sample counts that are and are not multiples of the table length: within 1e-12
    of the peak inside the IWR1443's range, 1e-9 for far targets whose beat frequency is many
    times the sample rate (aliased; their phase reaches 1e5 cycles, whose float64 spacing is
    1.5e-11 cycles, and the direct cosine/sine evaluation differs from this sum as much)."""
    import dataclasses

    seq = dataclasses.replace(SEQ, n_samples=n_samples)
    rng = np.random.default_rng(7)
    tau = 2 * rng.uniform(r_min, r_max, (6, 4)) / C
    a = rng.uniform(0.1, 1.0, tau.shape)
    t = seq.adc_start_time + np.arange(n_samples) / seq.sample_rate
    ref = np.zeros((tau.shape[0], n_samples), complex)
    for c in range(tau.shape[0]):
        for i in range(tau.shape[1]):
            cycles = np.mod(seq.start_frequency * tau[c, i], 1.0) + seq.slope * tau[c, i] * (
                t - 0.5 * tau[c, i]
            )
            ref[c] += a[c, i] * np.exp(-2j * np.pi * np.mod(cycles, 1.0))
    y = fmcw.if_samples(tau, a, seq)
    assert y.shape == ref.shape and y.flags.c_contiguous
    assert np.max(np.abs(y - ref)) < rtol * np.max(np.abs(ref))


def test_range_resolution_is_c_over_2B() -> None:
    """With a rectangular window, bins c/2B apart are orthogonal: an on-bin target leaves every
    other bin at zero, and two targets one resolution cell apart are both resolved exactly."""
    assert SEQ.range_resolution == pytest.approx(C / (2 * SEQ.sampled_bandwidth), rel=1e-15)
    dr = SEQ.range_resolution
    r = np.array([[40 * dr, 41 * dr]])
    prof = fmcw.range_profile(fmcw.if_samples(2 * r / C, np.ones_like(r), SEQ), "rect", 240)
    mag = np.abs(prof[0])
    np.testing.assert_allclose(mag[[40, 41]], 1.0, rtol=1e-9)
    assert np.max(np.delete(mag, [40, 41])) < 1e-9


def test_raw_and_analytic_range_profiles_are_identical() -> None:
    """The closed form equals the sampled IF and FFT at every bin (1e-12 of the peak), for every
    window and with zero-padding."""
    rng = np.random.default_rng(1)
    r = rng.uniform(0.5, 9.0, (5, 7))
    a = rng.uniform(0.1, 1.0, (5, 7))
    y = fmcw.if_samples(2 * r / C, a, SEQ)
    for name in fmcw.WINDOWS:
        for n_fft in (240, 512):
            raw = fmcw.range_profile(y, name, n_fft)  # type: ignore[arg-type]
            ana = fmcw.analytic_range_profile(
                2 * r / C,
                a,
                SEQ,
                name,
                n_fft,
                np.arange(n_fft),  # type: ignore[arg-type]
            )
            assert np.max(np.abs(raw - ana)) < 1e-12 * np.max(np.abs(raw))


def test_closed_form_holds_for_targets_on_and_next_to_a_bin() -> None:
    """Hard case: targets exactly on a range bin, 1e-13 .. 1e-6 of a bin beside one, at zero
    range and one maximum range out (aliased onto bin 0): the closed form still equals the
    sampled FFT to 1e-12 of the peak (a ratio of two small sines taken of differently rounded
    arguments was off by 3.7e-6 of the peak here; now 2.4e-14)."""
    k = np.array([0, 1, 37, 120, 239, 240])
    offsets = np.array([0.0, 1e-13, -1e-11, 1e-9, -1e-7, 1e-6])
    x = (k[:, None] + offsets[None, :]) / 240  # beat frequency [cycles per sample]
    delays = x * SEQ.sample_rate / SEQ.slope
    a = np.linspace(0.5, 1.0, delays.size).reshape(delays.shape)
    for name in fmcw.WINDOWS:
        raw = fmcw.range_profile(fmcw.if_samples(delays, a, SEQ), name, 240)  # type: ignore[arg-type]
        ana = fmcw.analytic_range_profile(delays, a, SEQ, name, 240, np.arange(240))  # type: ignore[arg-type]
        assert np.max(np.abs(raw - ana)) < 1e-12 * np.max(np.abs(raw)), name


def test_per_channel_profiles_equal_the_sampled_fft_of_each_channel() -> None:
    """The closed form with a phasor per channel and scatterer (the analytic path's receive
    channels) equals, channel by channel, the sampled IF of the same complex amplitudes and its
    FFT, to 1e-12 of the peak, at every bin and for every window. Hard cases in one frame: a
    target exactly on a bin, 1e-9 of a bin beside one, at zero range, and two targets beside
    the same bin in the same chirp (the direct evaluations near a bin must add up, not
    overwrite each other)."""
    rng = np.random.default_rng(7)
    n_chirps, n_rx = 6, 3
    hard = np.array([37.0, 37.0 + 1e-9, 0.0, 120.0 + 2e-4, 120.0 - 3e-4]) / 240
    x = np.hstack([np.tile(hard, (n_chirps, 1)), rng.uniform(0.02, 0.9, (n_chirps, 4))])
    delays = x * SEQ.sample_rate / SEQ.slope  # x: beat frequency [cycles per sample]
    a = rng.uniform(0.2, 1.0, delays.shape)
    phasors = np.exp(1j * rng.uniform(-np.pi, np.pi, (n_chirps, n_rx, delays.shape[1])))
    for name in fmcw.WINDOWS:
        ana = fmcw.analytic_range_profile(delays, a, SEQ, name, 240, np.arange(240), phasors)  # type: ignore[arg-type]
        for r in range(n_rx):
            samples = fmcw.if_samples(delays, a * phasors[:, r, :], SEQ)  # complex amplitudes
            raw = fmcw.range_profile(samples, name, 240)  # type: ignore[arg-type]
            assert np.max(np.abs(raw - ana[:, r])) < 1e-12 * np.max(np.abs(raw)), (name, r)


def test_bins_near_are_every_bin_within_the_margin_once() -> None:
    """The bins within ``margin`` of each range (after IF aliasing) are the sorted distinct
    bins of a plain per-range enumeration, ranges beyond the maximum and at 0 included."""
    rng = np.random.default_rng(3)
    ranges = np.concatenate([rng.uniform(0.0, 2.5 * SEQ.max_range, 40), [0.0, SEQ.max_range, 1e-9]])
    for margin in (0, 2, 8):
        expected = sorted(
            {
                (int(np.floor(r / SEQ.max_range * 240 % 240)) + d) % 240
                for r in ranges
                for d in range(-margin, margin + 2)
            }
        )
        got = fmcw.bins_near(ranges, SEQ, 240, margin)
        assert got.dtype == np.int64
        assert got.tolist() == expected


def test_target_beyond_max_range_aliases_in_the_if() -> None:
    """Hard case: at 1.3 x the maximum range the beat frequency exceeds fs and the target
    appears at 0.3 x, in the raw and the analytic path alike."""
    r = np.array([[1.3 * SEQ.max_range]])
    y = fmcw.if_samples(2 * r / C, np.ones_like(r), SEQ)
    raw = np.abs(fmcw.range_profile(y, "hann", 240))[0]
    ana = np.abs(
        fmcw.analytic_range_profile(2 * r / C, np.ones_like(r), SEQ, "hann", 240, np.arange(240))
    )[0]
    axis = fmcw.range_axis(SEQ, 240)
    assert axis[np.argmax(raw)] == pytest.approx(0.3 * SEQ.max_range, abs=SEQ.range_resolution)
    np.testing.assert_allclose(raw, ana, atol=1e-12)
    assert fmcw.bins_near(r[0], SEQ, 240, 0)[0] == int(0.3 * 240)


def test_doppler_is_2v_over_lambda() -> None:
    """A target approaching at v peaks at Doppler 2 v / lambda (lambda at the centre of the
    sampled band); on a bin exactly, at that bin."""
    v = 3 * SEQ.velocity_resolution  # on bin +3
    start = scene_point(4.0, 0.0, 0.0)
    prof = one_frame(start, -v * (start - RADAR) / np.linalg.norm(start - RADAR), "raw")
    rd = fmcw.range_doppler(fmcw.virtual_cube(prof, SEQ, 3), "hann", 16)
    power = fmcw.detection_map(rd)
    d, _ = np.unravel_index(np.argmax(power), power.shape)
    fd = fmcw.doppler_axis(SEQ, 16)
    assert fd[d] == pytest.approx(2 * v / SEQ.wavelength, rel=1e-9)
    # phase increment of one virtual channel across loops: 2 v / lambda to 0.1 % of a bin
    k = int(np.argmax(np.abs(prof[0, 0])))
    x = prof[0::3, 0, k]
    est = np.angle(np.sum(x[1:] * np.conj(x[:-1]))) / (2 * np.pi * SEQ.loop_period)
    assert est == pytest.approx(2 * v / SEQ.wavelength, abs=1e-3 / (16 * SEQ.loop_period))


@pytest.mark.parametrize("name", sorted(fmcw.WINDOWS))
def test_range_doppler_map_peaks_at_the_target_amplitude(name: str) -> None:
    """Absolute level (docs/fmcw.md: the map is in W): a target of amplitude a = 0.37 sqrt(W)
    on range bin 40 and Doppler bin +3 (its slow-time phase advances 3/16 of a cycle per loop)
    peaks in every virtual channel at |RD| = a and in the detection map at n_virt a^2 [W], to
    1e-9, whatever the window: the range and the Doppler FFT each divide by the sum of their
    window (dividing the Doppler FFT by n_loops would leave a Hann-windowed map 6 dB low)."""
    a, d, k = 0.37, 3, 40
    t = fmcw.chirp_times(SEQ, 0.0, SEQ.frame_period)  # (48,) one frame, TDM slots included
    fd = d / (SEQ.n_loops * SEQ.loop_period)  # on Doppler bin d
    amp = (a * np.exp(2j * np.pi * fd * t))[:, None]  # approaching: the phase advances
    delays = np.full((t.size, 1), 2 * k * SEQ.range_resolution / C)  # on range bin k
    prof = fmcw.range_profile(fmcw.if_samples(delays, amp, SEQ), name, 240)  # type: ignore[arg-type]
    rd = fmcw.range_doppler(fmcw.virtual_cube(prof[:, None, :], SEQ, 3), name, 16)  # type: ignore[arg-type]
    row = (16 - 1) // 2 + d  # zero Doppler at row 7 of 16
    assert fmcw.doppler_axis(SEQ, 16)[row] == pytest.approx(fd, rel=1e-12)
    np.testing.assert_allclose(np.abs(rd[:, row, k]), a, rtol=1e-9)
    power = fmcw.detection_map(rd)
    assert np.unravel_index(np.argmax(power), power.shape) == (row, k)
    assert power[row, k] == pytest.approx(3 * a**2, rel=1e-9)


@pytest.mark.parametrize("name", sorted(fmcw.WINDOWS))
def test_one_loop_per_frame_keeps_the_target_amplitude(name: str) -> None:
    """Hard case n_loops = 1: a one-sample window is [1] whatever its name (a periodic Hann
    formula gives [0] and nulled the only loop, then 0/0), so the Doppler "FFT" of one loop is
    the identity: the map holds each virtual channel's range profile, a lone on-bin target at
    its amplitude a in every channel and n_virt a^2 in the detection map, at 0 Hz."""
    seq = fmcw.ChirpSequence(77e9, 70e12, 7e-6, 7e-6, 57.14e-6, 4.884e6, 240, 1, (0, 2, 1), 33e-3)
    a, k = 0.37, 40
    np.testing.assert_array_equal(fmcw.window(name, 1), [1.0])  # type: ignore[arg-type]
    assert fmcw.window_transform(name, 1, np.array([0.0, 0.3]))[1] == 1.0  # type: ignore[arg-type]
    t = fmcw.chirp_times(seq, 0.0, seq.frame_period)
    amp = np.full((t.size, 1), a, dtype=np.complex128)
    delays = np.full((t.size, 1), 2 * k * seq.range_resolution / C)
    prof = fmcw.range_profile(fmcw.if_samples(delays, amp, seq), "hann", 240)
    cube = fmcw.virtual_cube(prof[:, None, :], seq, 3)
    rd = fmcw.range_doppler(cube, name, 1)  # type: ignore[arg-type]
    np.testing.assert_array_equal(rd, cube)
    np.testing.assert_allclose(np.abs(rd[:, 0, k]), a, rtol=1e-9)
    assert fmcw.doppler_axis(seq, 1).tolist() == [0.0]
    assert fmcw.detection_map(rd)[0, k] == pytest.approx(3 * a**2, rel=1e-9)


def test_velocity_beyond_the_tdm_limit_aliases() -> None:
    """Hard case: the unambiguous velocity is lambda / (4 n_tx T_chirp) (TDM: one sample per
    loop); at 1.25 x it the peak wraps to 1.25 v_max - 2 v_max = -0.75 v_max."""
    vmax = SEQ.max_velocity
    assert vmax == pytest.approx(SEQ.wavelength / (4 * SEQ.n_tx * SEQ.chirp_period), rel=1e-15)
    start = scene_point(4.0, 0.0, 0.0)
    los = (start - RADAR) / np.linalg.norm(start - RADAR)
    fd = fmcw.doppler_axis(SEQ, 16)
    peaks = []
    for v in (0.75 * vmax, 1.25 * vmax):
        rd = fmcw.range_doppler(
            fmcw.virtual_cube(one_frame(start, -v * los, "raw"), SEQ, 3), "hann", 16
        )
        d, _ = np.unravel_index(np.argmax(fmcw.detection_map(rd)), rd.shape[1:])
        peaks.append(fd[d] * SEQ.wavelength / 2)
    assert peaks[0] == pytest.approx(0.75 * vmax, rel=1e-9)
    assert peaks[1] == pytest.approx(-0.75 * vmax, rel=1e-9)


@pytest.mark.parametrize(
    ("az", "el"), [(0.0, 0.0), (20.0, 0.0), (-35.0, 10.0), (25.0, -15.0), (65.0, 0.0)]
)
def test_angle_of_a_point_target_within_one_resolution_cell(az: float, el: float) -> None:
    """A point at (az, el) is placed within one resolution cell in u_x (2 / 8 for the
    8-antenna azimuth row) and u_z (2 / 2 for the two rows); straight ahead its direction
    cosines are 0 to 0.0025 (1/100 of an azimuth cell; what is left is the near-field phase of
    the exact delays at 3 m). 65 deg is the edge of the field of view."""
    start = scene_point(3.0, az, el)
    pts, _ = frame_points(one_frame(start, np.zeros(3), "raw"))
    best = pts[np.argmax(pts[:, 4])]
    ux, uz = np.sin(np.deg2rad(az)) * np.cos(np.deg2rad(el)), np.sin(np.deg2rad(el))
    r = np.linalg.norm(best[:3])
    assert r == pytest.approx(3.0, abs=SEQ.range_resolution)
    assert best[0] / r == pytest.approx(ux, abs=2 / 8 / 4)  # a quarter of a cell in practice
    assert best[2] / r == pytest.approx(uz, abs=2 / 2 / 4)
    if az == 0.0 and el == 0.0:
        assert abs(best[0] / r) < 0.0025 and abs(best[2] / r) < 0.0025


def test_multi_object_beamforming_finds_two_targets_in_one_cell() -> None:
    """Two targets in one range-Doppler cell, at azimuths -30 and +25 deg (their u_x 0.92
    apart, over 3 azimuth cells), the second at 0.7 of the first's amplitude: with
    ``multi_peak`` 0.3 the beam scan returns both directions (each within a quarter of a cell),
    the stronger first; with 0.6 (above the second's 0.49 of the power) only the first."""
    grid = fmcw.angle_grid(ANT.virtual, SEQ.wavelength)
    ux = np.sin(np.deg2rad([-30.0, 25.0]))
    snap = fmcw.steering(ANT.virtual, ux, np.zeros(2), SEQ.wavelength).T @ np.array([1.0, 0.7])
    det, got_ux, got_uz, power = fmcw.estimate_angles(snap[None, :], grid, multi_peak=0.3)
    assert det.tolist() == [0, 0]
    np.testing.assert_allclose(got_ux, ux, atol=2 / 8 / 4)
    np.testing.assert_allclose(got_uz, 0.0, atol=2 / 2 / 4)
    assert power[0] > power[1]
    det, got_ux, _, _ = fmcw.estimate_angles(snap[None, :], grid, multi_peak=0.6)
    assert det.tolist() == [0] and got_ux[0] == pytest.approx(ux[0], abs=2 / 8 / 4)


def test_second_peaks_match_a_dense_local_maximum_filter() -> None:
    """The second peak of each beam map, found by testing only the cells above the threshold,
    is the one a dense 3x3 maximum filter over the whole map finds, among the cells whose whole
    3x3 neighbourhood lies on the grid and is finite (a map with one u_z row has edges in u_x
    only; ties to the lower index): 2000 random maps, with plateaus (integer powers, all-zero
    maps), invisible cells, overflowed and NaN cells, and maps of 1 to 8 cells a side."""
    from scipy.ndimage import maximum_filter, minimum_filter

    def dense(maps: np.ndarray, best: np.ndarray, fraction: float) -> tuple[np.ndarray, ...]:
        n = maps.shape[0]
        det = np.arange(n)
        finite = np.where(np.isfinite(maps), maps, -1.0)
        size = (1, 3, 3 if maps.shape[2] > 1 else 1)
        inside = minimum_filter(np.isfinite(maps), size=size, mode="constant", cval=False)
        local = inside & (finite == maximum_filter(finite, size=size, mode="nearest"))
        peak = maps.reshape(n, -1)[det, best]
        with np.errstate(invalid="ignore"):
            cand = np.where(local & (finite >= fraction * peak[:, None, None]), finite, -np.inf)
        cand = cand.reshape(n, -1)
        cand[det, best] = -np.inf
        second = np.argmax(cand, axis=1)
        has = np.isfinite(cand[det, second])
        return det[has], second[has]

    rng = np.random.default_rng(5)
    found = 0
    for trial in range(2000):
        shape = (int(rng.integers(1, 6)), int(rng.integers(1, 9)), int(rng.integers(1, 9)))
        maps = rng.integers(0, 4, shape).astype(float) if trial % 2 else rng.random(shape)
        if trial % 7 == 0:
            maps[:] = 0.0
        maps[rng.random(shape) < 0.2] = -np.inf
        maps[:, 0, 0] = np.maximum(maps[:, 0, 0], 0.0)  # every map has a visible cell
        if trial % 11 == 0:  # an overflowed beam and a NaN (not from real snapshots)
            maps[0, -1, -1], maps[-1, 0, -1] = np.inf, np.nan
        best = np.argmax(maps.reshape(shape[0], -1), axis=1)
        fraction = float(rng.choice([0.0, 0.3, 0.5, 1.0]))
        want = dense(maps, best, fraction)
        got = fmcw._second_peaks(maps, best, fraction)
        assert got[0].tolist() == want[0].tolist() and got[1].tolist() == want[1].tolist()
        found += want[0].size
    assert found > 600  # many maps have a second peak: the comparison is not vacuous


@pytest.mark.parametrize(("az", "el"), [(0.0, 40.0), (20.0, -50.0), (40.0, 60.0), (75.0, 0.0)])
def test_no_second_point_at_the_edge_of_the_visible_region(az: float, el: float) -> None:
    """Hard case: one target above 30 deg elevation (or near endfire in azimuth). The two rows
    of the elevation array are half a wavelength apart, so the beam map along u_z falls from the
    target to a null one unit of u_z away and then rises again toward a lobe beyond -1, where no
    direction exists; on the edge of the visible region it is still 0.5-0.9 of the peak. With
    ``multi_peak`` 0.5 that edge must not become a second point (it did: straight down, at
    u_z -0.94 to -1); the one point is within a quarter of a cell of the target."""
    grid = fmcw.angle_grid(ANT.virtual, SEQ.wavelength)
    ux = np.sin(np.deg2rad(az)) * np.cos(np.deg2rad(el))
    uz = np.sin(np.deg2rad(el))
    snap = fmcw.steering(ANT.virtual, np.array([ux]), np.array([uz]), SEQ.wavelength)
    det, got_ux, got_uz, _ = fmcw.estimate_angles(snap, grid, multi_peak=0.5)
    assert det.tolist() == [0]
    assert got_ux[0] == pytest.approx(ux, abs=2 / 8 / 4)
    assert got_uz[0] == pytest.approx(uz, abs=2 / 2 / 4)


def test_tdm_phase_compensation_restores_the_angle_of_a_fast_target() -> None:
    """Hard case at the edge of the field of view: a target moving at 0.8 v_max gains phase
    between TDM slots; without compensation the angle is off, with it within 0.02 in u_x."""
    az = 50.0
    start = scene_point(3.0, az, 0.0)
    los = (start - RADAR) / np.linalg.norm(start - RADAR)
    prof = one_frame(start, -0.8 * SEQ.max_velocity * los, "raw")
    ux = np.sin(np.deg2rad(az))
    errs = []
    for comp in (True, False):
        pts, _ = frame_points(prof, tdm_compensation=comp)
        best = pts[np.argmax(pts[:, 4])]
        errs.append(abs(best[0] / np.linalg.norm(best[:3]) - ux))
    assert errs[0] < 0.02
    assert errs[1] > 5 * errs[0]


def test_raw_and_analytic_frames_agree() -> None:
    """The analytic path (far-field phases, 2R/c envelope, bins near the scatterers) against
    the raw path (exact spherical delays per channel, sampled IF): range-Doppler power within
    0.01 dB at the cells above -10 dB and 1e-3 of the peak elsewhere (the bins the analytic
    path leaves out are 67 dB down); the points fall in the same range and Doppler bins and
    their direction cosines agree to 0.005 (1/50 of an azimuth resolution cell)."""
    start = scene_point(3.0, 15.0, 5.0)
    los = (start - RADAR) / np.linalg.norm(start - RADAR)
    raw = one_frame(start, -1.1 * los, "raw")
    ana = one_frame(start, -1.1 * los, "analytic")
    p_raw, pw_raw = frame_points(raw)
    p_ana, pw_ana = frame_points(ana)
    peak = pw_raw.max()
    assert np.max(np.abs(pw_raw - pw_ana)) < 1e-3 * peak
    top = pw_raw > 0.1 * peak
    assert np.max(np.abs(10 * np.log10(pw_ana[top] / pw_raw[top]))) < 0.01
    b_raw, b_ana = p_raw[np.argmax(p_raw[:, 4])], p_ana[np.argmax(p_ana[:, 4])]
    r = np.linalg.norm(b_raw[:3])
    assert np.linalg.norm(b_ana[:3]) == pytest.approx(r, rel=1e-12)  # the same range bin
    assert b_ana[3] == b_raw[3]  # the same Doppler bin
    np.testing.assert_allclose(b_ana[:3] / r, b_raw[:3] / r, atol=0.005)  # 1/50 of a cell


def test_chirp_times_follow_idle_time_and_frame_gaps() -> None:
    t = fmcw.chirp_times(SEQ, 1.0, 1.0 + 3.5 * SEQ.frame_period)
    assert t.shape == (4 * 48,)  # the fourth frame's chirps end 3.08 ms after it starts
    assert t[0] == pytest.approx(1.0 + 7e-6)
    np.testing.assert_allclose(np.diff(t[:48]), 64.14e-6, rtol=1e-9)
    assert t[48] - t[0] == pytest.approx(SEQ.frame_period)
    # a frame whose last chirp would end after `end` is left out
    last = 7e-6 + 47 * 64.14e-6 + 57.14e-6
    assert fmcw.chirp_times(SEQ, 0.0, last - 1e-9).size == 0
    assert fmcw.chirp_times(SEQ, 0.0, last).size == 48


def test_impossible_timing_names_the_field_and_the_limit() -> None:
    from dataclasses import replace

    msgs = replace(SEQ, frame_period=2e-3).problems()
    assert len(msgs) == 1 and msgs[0].startswith("frame_period:") and "3.0787 ms" in msgs[0]
    msgs = replace(SEQ, slope=80e12).problems(4e9)
    assert msgs[0].startswith("slope:") and "4.5712 GHz" in msgs[0] and "4.0000 GHz" in msgs[0]
    msgs = replace(SEQ, n_samples=256).problems()
    assert msgs[0].startswith("ramp_end_time:") and "57.140 us" in msgs[0]


def test_ca_cfar_false_alarm_rate_matches_theory() -> None:
    """CA-CFAR on exponential noise: P_fa = (1 + alpha / N)^-N for N training cells and the
    threshold alpha times their mean (cyclic, so every cell has all N)."""
    rng = np.random.default_rng(7)
    noise = rng.exponential(1.0, (20000, 128))
    settings = fmcw.Cfar("ca", train=8, guard=2, threshold_db=10.0)
    det, est = fmcw.cfar(noise, settings, axis=1, cyclic=True)
    n = 16
    expected = (1 + 10.0 / n) ** -n
    assert det.mean() == pytest.approx(expected, rel=0.1)  # 3 sigma of 1080 expected
    assert np.nanmean(est) == pytest.approx(1.0, rel=0.01)


def test_cfar_modes_at_a_clutter_edge() -> None:
    """At a step in the noise level, smallest-of takes the quiet side, greatest-of the loud
    side, cell averaging the mean; without wrapping, an edge cell uses one side only."""
    p = np.r_[np.ones(20), 100 * np.ones(20)][None, :]
    for mode, want in (("so", 1.0), ("go", 100.0), ("ca", 50.5)):
        _, est = fmcw.cfar(p, fmcw.Cfar(mode, 4, 1, 10.0), axis=1, cyclic=False)  # type: ignore[arg-type]
        assert est[0, 20] == pytest.approx(want)
    _, est = fmcw.cfar(p, fmcw.Cfar("ca", 4, 1, 10.0), axis=1, cyclic=False)
    assert est[0, 0] == pytest.approx(1.0) and est[0, 39] == pytest.approx(100.0)
    # a target 20 dB above a flat floor is detected at 15 dB, not at 25 dB
    q = np.ones((1, 64))
    q[0, 30] = 100.0
    assert fmcw.cfar(q, fmcw.Cfar("ca", 8, 2, 15.0), axis=1, cyclic=False)[0][0].sum() == 1
    assert fmcw.cfar(q, fmcw.Cfar("ca", 8, 2, 25.0), axis=1, cyclic=False)[0][0].sum() == 0


def test_sensor_axes_are_a_right_handed_frame() -> None:
    a = fmcw.sensor_axes(np.deg2rad(30.0), np.deg2rad(-10.0))
    np.testing.assert_allclose(a @ a.T, np.eye(3), atol=1e-15)
    assert np.linalg.det(a) == pytest.approx(1.0)
    np.testing.assert_allclose(a[0, 2], 0.0, atol=1e-15)  # x_s is horizontal
    assert a[2, 2] > 0  # z_s points up


@pytest.mark.parametrize("n_fft", [240, 512])
@pytest.mark.parametrize("name", sorted(fmcw.WINDOWS))
def test_gate_signal_over_every_range_bin_is_the_middle_if_sample(name: str, n_fft: int) -> None:
    """The identity the gate's flat response rests on: a target's range response (the
    sampled sinc, a Dirichlet kernel, with a rectangular window; a sum of shifted ones with the
    cosine windows) summed over every range bin with the gate's phase ramp and scale is one,
    so the gate signal of a gate covering every bin is exactly the IF sample at
    ``m0 = n_samples // 2``: to 1e-12 (complex, amplitudes 1 and 0.4), for targets 0.5 bin
    below to 0.5 bin above bin 120 in 11 steps beside a second one at bin 37.3, every window,
    with and without zero-padding. A bin left out of the sum (even the last one, 120 bins
    from the target) or a halved sum breaks it."""
    x = np.column_stack([120 + np.linspace(-0.5, 0.5, 11), np.full(11, 37.3)])  # [bins of 240]
    delays = x / 240 * SEQ.sample_rate / SEQ.slope  # beat frequency x / 240 cycles per sample
    y = fmcw.if_samples(delays, np.tile([1.0, 0.4], (11, 1)), SEQ)
    prof = fmcw.range_profile(y, name, n_fft)[:, None, :]  # type: ignore[arg-type]
    axis = fmcw.range_axis(SEQ, n_fft)
    everything = np.full(11, SEQ.max_range / 2)  # gate centre; width: twice the range axis
    g = fmcw.gate_signal(prof, axis, everything, 2 * SEQ.max_range, name, 240)  # type: ignore[arg-type]
    np.testing.assert_allclose(g, y[:, 240 // 2], rtol=0, atol=1e-12)


def test_gate_signal_is_flat_inside_the_gate_and_rejects_outside() -> None:
    """The slow-time signal of the gate: a lone target anywhere within 0.8 m of a 2 m gate's
    centre gives its amplitude to 7e-4 (Hann window) with exactly the phase of the middle IF
    sample; targets 1 m and 1.2 m beyond the gate's edges give less than 1e-5."""
    axis = fmcw.range_axis(SEQ, 240)
    r = np.linspace(2.2, 3.8, 801)[:, None]
    y = fmcw.if_samples(2 * r / C, np.ones_like(r), SEQ)
    prof = fmcw.range_profile(y, "hann", 240)[:, None, :]
    g = fmcw.gate_signal(prof, axis, np.full(r.shape[0], 3.0), 2.0, "hann", 240)
    assert np.max(np.abs(np.abs(g) - 1.0)) < 7e-4
    assert np.max(np.abs(np.angle(g * np.conj(y[:, 120])))) < 1e-12
    far = np.array([[1.0], [5.2]])
    y = fmcw.if_samples(2 * far / C, np.ones_like(far), SEQ)
    prof = fmcw.range_profile(y, "hann", 240)[:, None, :]
    out = fmcw.gate_signal(prof, axis, np.full(2, 3.0), 2.0, "hann", 240)
    assert np.max(np.abs(out)) < 1e-5


@pytest.mark.parametrize(
    ("range_window", "doppler_window"), [("hann", "hann"), ("rect", "blackman")]
)
def test_map_noise_power_is_the_mean_noise_of_the_detection_map(
    range_window: str, doppler_window: str
) -> None:
    """Complex white IF noise of power P per sample, through the range and Doppler FFTs of 12
    virtual antennas: the detection map's mean over the 16 x 240 cells of 200 frames is
    map_noise_power to 2 %."""
    rng = np.random.default_rng(5)
    p, n_frames = 2.5e-9, 200
    total = 0.0
    for _ in range(n_frames):
        shape = (SEQ.chirps_per_frame, 4, SEQ.n_samples)
        x = (rng.normal(size=shape) + 1j * rng.normal(size=shape)) * np.sqrt(p / 2)
        prof = fmcw.range_profile(x, range_window, 240)  # type: ignore[arg-type]
        rd = fmcw.range_doppler(fmcw.virtual_cube(prof, SEQ, 3), doppler_window, 16)  # type: ignore[arg-type]
        total += float(np.mean(fmcw.detection_map(rd)))
    expected = fmcw.map_noise_power(p, 12, range_window, 240, doppler_window, 16)  # type: ignore[arg-type]
    assert total / n_frames == pytest.approx(expected, rel=0.02, abs=0)
    if range_window == "hann":  # the coherent gains 2 n / 3 of the docs
        assert expected == pytest.approx(12 * p / (2 * 240 / 3) / (2 * 16 / 3), rel=1e-12, abs=0)


def _detect_points_reference(
    rd: np.ndarray, ranges: np.ndarray, doppler: np.ndarray, settings: fmcw.Detection
) -> np.ndarray:
    """detect_points as it was (np.nonzero of the masks; a slow reference)."""
    power = np.sum(rd.real**2 + rd.imag**2, axis=0)
    mask = power > 0
    level = power + settings.noise_floor if settings.noise_floor > 0 else power
    noise = np.full(power.shape, np.nan)
    if settings.cfar_doppler is not None:
        det, noise = fmcw.cfar(level, settings.cfar_doppler, axis=0, cyclic=True)
        mask &= det
    if settings.cfar_range is not None:
        det, noise = fmcw.cfar(level, settings.cfar_range, axis=1, cyclic=False)
        mask &= det
    mask &= ((ranges >= settings.min_range) & (ranges <= settings.max_range))[None, :]
    if settings.group_doppler:
        mask &= (power >= np.roll(power, 1, axis=0)) & (power >= np.roll(power, -1, axis=0))
    if settings.group_range:
        left = np.concatenate([np.full((power.shape[0], 1), -np.inf), power[:, :-1]], axis=1)
        right = np.concatenate([power[:, 1:], np.full((power.shape[0], 1), -np.inf)], axis=1)
        mask &= (power >= left) & (power >= right)
    di, ri = np.nonzero(mask)
    snaps = np.ascontiguousarray(rd[:, di, ri].T)
    fd = doppler[di]
    if settings.tdm_compensation:
        snaps = fmcw.tdm_compensation(snaps, fd, ANT.slot_of_virtual(SEQ), SEQ.chirp_period)
    grid = fmcw.angle_grid(ANT.virtual, SEQ.wavelength)
    which, ux, uz, _ = fmcw.estimate_angles(snaps, grid, settings.multi_peak)
    r = ranges[ri][which]
    uy = np.sqrt(np.clip(1.0 - ux**2 - uz**2, 0.0, None))
    ref = np.maximum(np.nan_to_num(noise[di, ri], nan=1.0), np.finfo(np.float64).tiny)
    snr = 10.0 * (np.log10(level[di, ri]) - np.log10(ref))[which]
    return np.column_stack([r * ux, r * uy, r * uz, fd[which] * SEQ.wavelength / 2.0, snr])


@pytest.mark.parametrize(
    "settings",
    [
        fmcw.Detection(),
        fmcw.Detection(
            cfar_range=fmcw.Cfar("ca", 8, 2, 12.0),
            cfar_doppler=fmcw.Cfar("go", 4, 1, 8.0),
            group_range=True,
            multi_peak=0.3,
        ),
        fmcw.Detection(
            cfar_range=None, multi_peak=None, noise_floor=1e-3, tdm_compensation=False, max_range=3
        ),
    ],
)
def test_points_are_those_of_the_reference_detection(settings: fmcw.Detection) -> None:
    # five frames of three walkers' points in noise: detect_points (its cells found through the
    # flattened masks, its second beam peaks tested neighbour by neighbour) gives the points of
    # the slow reference, bit for bit
    gen = np.random.default_rng(3)
    t = fmcw.chirp_times(SEQ, 0.0, 5 * SEQ.frame_period)
    starts = [scene_point(r, az, el) for r, az, el in ((2.0, 10, 5), (3.1, -25, 0), (4.4, 40, -8))]
    vel = np.array([[-1.2, 0.3, 0.0], [0.8, -0.5, 0.1], [0.0, 1.5, 0.0]])
    pos = np.stack([s[None, :] + t[:, None] * v for s, v in zip(starts, vel, strict=True)], 1)
    noise = gen.normal(0, 0.05, (t.size, 4, 240)) + 1j * gen.normal(0, 0.05, (t.size, 4, 240))
    prof = fmcw.chirp_profiles(
        pos,
        np.ones(pos.shape[:2]),
        RADAR,
        AXES,
        SEQ,
        ANT,
        window_name="hann",
        n_fft=240,
        path="analytic",
        noise=noise,
    ).reshape(5, SEQ.chirps_per_frame, 4, 240)
    ranges, doppler = fmcw.range_axis(SEQ, 240), fmcw.doppler_axis(SEQ, 16)
    grid = fmcw.angle_grid(ANT.virtual, SEQ.wavelength)
    slots = ANT.slot_of_virtual(SEQ)
    for f in range(5):
        rd = fmcw.range_doppler(fmcw.virtual_cube(prof[f], SEQ, 3), "hann", 16, True)
        ref = _detect_points_reference(rd, ranges, doppler, settings)
        assert ref.shape[0] > 0
        pts = fmcw.detect_points(
            rd, ranges, doppler, grid, slots, SEQ.chirp_period, SEQ.wavelength, settings
        )
        assert np.array_equal(pts, ref)


@pytest.mark.parametrize("multi_peak", [None, 0.3])
def test_angles_of_many_detections_in_chunks_are_those_of_one_scan(
    monkeypatch: pytest.MonkeyPatch, multi_peak: float | None
) -> None:
    # 300 detections of one or two plane waves: the beam scan in chunks of ANGLE_CHUNK gives
    # every detection's directions (and second peaks) as one scan of them all does
    gen = np.random.default_rng(8)
    virt = ANT.virtual
    grid = fmcw.angle_grid(virt, SEQ.wavelength)
    ux, uz = gen.uniform(-0.7, 0.7, (2, 300)), gen.uniform(-0.5, 0.5, (2, 300))
    snaps = sum(
        a[:, None] * fmcw.steering(virt, ux[j], uz[j], SEQ.wavelength)
        for j, a in enumerate((np.ones(300), gen.uniform(0.5, 1.0, 300)))
    ) + 0.05 * gen.normal(size=(300, 12))
    chunked = fmcw.estimate_angles(snaps, grid, multi_peak)
    monkeypatch.setattr(fmcw, "ANGLE_CHUNK", 10**6)
    whole = fmcw.estimate_angles(snaps, grid, multi_peak)
    assert chunked[0].size > (400 if multi_peak else 299)
    for got, want in zip(chunked, whole, strict=True):
        assert np.array_equal(got, want)


def test_cfar_matches_a_cell_by_cell_reference() -> None:
    # each cell's training cells summed one by one (wrapping on a cyclic axis, only those that
    # exist on the other), for random maps, modes, widths (some wider than the axis) and axes
    rng = np.random.default_rng(4)
    for _ in range(150):
        shape = (int(rng.integers(1, 12)), int(rng.integers(1, 40)))
        p = rng.exponential(size=shape)
        mode = str(rng.choice(["ca", "so", "go"]))
        t, g = int(rng.integers(1, 10)), int(rng.integers(0, 6))
        axis, cyclic = int(rng.integers(0, 2)), bool(rng.integers(0, 2))
        det, est = fmcw.cfar(p, fmcw.Cfar(mode, t, g, 5.0), axis=axis, cyclic=cyclic)  # type: ignore[arg-type]
        x = np.moveaxis(p, axis, -1)
        n = x.shape[-1]
        for row in np.ndindex(x.shape[:-1]):
            for j in range(n):
                sides = []
                for cells in (range(j - g - t, j - g), range(j + g + 1, j + g + t + 1)):
                    idx = [c % n for c in cells] if cyclic else [c for c in cells if 0 <= c < n]
                    sides.append([x[row][c] for c in idx])
                means = [np.mean(s) if s else np.nan for s in sides]
                if mode == "ca":
                    both = sides[0] + sides[1]
                    want = np.mean(both) if both else np.nan
                else:
                    pick = np.nanmin if mode == "so" else np.nanmax
                    want = np.nan if np.all(np.isnan(means)) else pick(means)
                got = np.moveaxis(est, axis, -1)[row][j]
                hit = np.moveaxis(det, axis, -1)[row][j]
                if np.isnan(want):
                    assert np.isnan(got) and not hit
                else:
                    assert got == pytest.approx(want, rel=1e-9)
                    assert hit == (x[row][j] > 10**0.5 * want)


def test_clutter_removal_removes_the_static_target_and_keeps_the_moving_one() -> None:
    """Static clutter removal subtracts each channel's and range bin's mean over the loops: a
    still target on range bin 20 (the same value in every loop) vanishes from the
    range-Doppler map, while a target on range bin 40 moving at Doppler bin +3 keeps its
    amplitude a on its own cell to 1e-9 (its slow-time mean over whole cycles is zero)."""
    a, d = 0.37, 3
    n_loops, n_virt, n_bins = 16, 4, 64
    loops = np.arange(n_loops)
    cube = np.zeros((n_virt, n_loops, n_bins), dtype=np.complex128)
    cube[:, :, 20] = 1.5 * np.exp(0.7j)  # still: one value in every loop
    cube[:, :, 40] = a * np.exp(2j * np.pi * d * loops / n_loops)  # Doppler bin +3
    rd = fmcw.range_doppler(cube, "hann", n_loops, clutter_removal=True)
    assert np.max(np.abs(rd[:, :, 20])) < 1e-12
    row = (n_loops - 1) // 2 + d
    np.testing.assert_allclose(np.abs(rd[:, row, 40]), a, rtol=1e-9)
    kept = fmcw.range_doppler(cube, "hann", n_loops)  # without removal the still target stays
    np.testing.assert_allclose(np.abs(kept[:, (n_loops - 1) // 2, 20]), 1.5, rtol=1e-9)


@pytest.mark.parametrize("window", ["hann", "boxcar"])
def test_a_frame_spectrum_is_stamped_at_its_windows_centre(window: str) -> None:
    """One Doppler spectrum per frame (frames with gaps): a point 40 % of the way to v_max
    turns from approaching to receding at the time frame 2's spectrum is stamped with: its
    power splits evenly between the positive and the negative Doppler half, to 1e-6 (an odd
    FFT size: the halves have the same bins). That time is the centre of the window over the
    frame's loops, n_loops / 2 loop periods after its first chirp with the periodic Hann
    window (n_loops = 16 here), (n_loops - 1) / 2 with the boxcar. Stamping every window at
    its middle loop, (n_loops - 1) / 2, stamped a Hann frame half a loop early: a turn at that
    stamp leaves 42 % of the power in the positive half."""
    n_frames, f = 4, 2
    frame = np.arange(n_frames)[:, None] * SEQ.frame_period
    t = (frame + np.arange(SEQ.chirps_per_frame)[None, :] * SEQ.chirp_period).ravel()
    _, _, time = fmcw.frame_spectrogram(np.ones(t.size, complex), SEQ, window, 129, "float64")
    t_rev = time[f]  # from the first chirp, as the chirp times t
    f0 = 0.4 / (2 * SEQ.loop_period)
    signal = np.exp(2j * np.pi * f0 * (t_rev - np.abs(t - t_rev)))
    power, doppler, _ = fmcw.frame_spectrogram(signal, SEQ, window, 129, "float64")
    up, down = power[doppler > 0, f].sum(), power[doppler < 0, f].sum()
    assert up / (up + down) == pytest.approx(0.5, abs=1e-6)
