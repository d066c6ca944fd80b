"""Radar physics against analytic references (physics.md sections 0, 1 and 5)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import peak_frequency_per_frame, phase_increment_doppler, point_run

from mdframework.constants import SPEED_OF_LIGHT
from mdframework.physics import radar

FC = 15e9
PRF = 2400.0


def test_written_out_constants_are_scipys_exact_values() -> None:
    import scipy.constants

    from mdframework.constants import BOLTZMANN

    assert SPEED_OF_LIGHT == scipy.constants.speed_of_light
    assert BOLTZMANN == scipy.constants.Boltzmann


def test_prf_needed_inverts_the_unambiguous_velocity() -> None:
    """lambda PRF / 4 at the PRF min_prf_for_velocity gives back the speed (15 GHz: 3 m/s
    needs 4 * 3 / 0.019986 = 600.4 Hz)."""
    prf = radar.min_prf_for_velocity(3.0, FC)
    assert prf == pytest.approx(4 * 3.0 / (SPEED_OF_LIGHT / FC), rel=1e-12)
    assert prf == pytest.approx(600.415, abs=1e-3)
    assert radar.max_unambiguous_velocity(FC, prf) == pytest.approx(3.0, rel=1e-12)


def test_wavelength_and_velocity_scale() -> None:
    assert radar.wavelength(FC) == pytest.approx(0.019986163867, rel=1e-11)
    assert float(radar.velocity_to_doppler(1.0, FC)) == pytest.approx(100.069228559, rel=1e-11)
    assert float(radar.doppler_to_velocity(100.069228559, FC)) == pytest.approx(1.0, rel=1e-11)


def test_unambiguous_velocity() -> None:
    assert radar.max_unambiguous_velocity(FC, 2400) == pytest.approx(11.991698, abs=1e-6)
    assert radar.max_unambiguous_velocity(FC, 1200) == pytest.approx(5.995849, abs=1e-6)


def test_aliasing_formula() -> None:
    true = float(radar.velocity_to_doppler(15.0, FC))
    assert true == pytest.approx(1501.0384, abs=1e-4)
    assert float(radar.alias_frequency(true, PRF)) == pytest.approx(-898.9616, abs=1e-4)


def test_receding_point_peaks_at_minus_100_069_hz() -> None:
    res = point_run([{"position": [100.0, 0, 0], "velocity": [1.0, 0, 0]}])
    bin_hz = PRF / 1024
    peaks = peak_frequency_per_frame(res)
    assert np.all(np.abs(peaks - (-100.069228559)) <= bin_hz / 2 + 1e-9)
    # the phase-increment estimator is exact (section 5: 3e-10 relative)
    est = phase_increment_doppler(res.received.signal, PRF)
    assert est == pytest.approx(-100.069228559, rel=1e-8)


def test_on_bin_case_exact() -> None:
    """PRF 2400, N_fft 256, Hann 256, hop 64: 0.936851431 m/s approach peaks at exactly
    +93.75 Hz in every one of the 72 frames of 2 s."""
    res = point_run(
        [{"position": [50.0, 0, 0], "velocity": [-0.936851431, 0, 0]}],
        processing={"window_length": 256, "hop": 64, "nfft": 256},
    )
    peaks = peak_frequency_per_frame(res)
    assert peaks.shape == (72,)
    assert np.all(peaks == 93.75)
    # the on-bin peak has no scalloping: the neighbours are exactly symmetric
    k = int(np.argmax(res.spectrogram.power[:, 0]))
    col = res.spectrogram.power[:, 0]
    assert col[k - 1] == pytest.approx(col[k + 1], rel=1e-6, abs=0)


def test_receding_point_peaks_at_the_nearest_bin_minus_103_125_hz() -> None:
    """Section 5: with N_fft 256 (bins of 9.375 Hz) 1 m/s receding (-100.069 Hz) peaks at
    -103.125 Hz, the nearest bin, in every frame (not at -93.75 Hz, a bin toward zero)."""
    res = point_run(
        [{"position": [100.0, 0, 0], "velocity": [1.0, 0, 0]}],
        processing={"window_length": 256, "hop": 64, "nfft": 256},
    )
    peaks = peak_frequency_per_frame(res)
    assert peaks.shape == (72,)
    assert np.all(peaks == -103.125)


def test_sign_convention_end_to_end() -> None:
    """An approaching scatterer is at positive Doppler and velocity in the stored arrays."""
    res = point_run([{"position": [30.0, 0, 0], "velocity": [-2.0, 0, 0]}])
    k = np.argmax(res.spectrogram_db.mean(axis=1))
    assert res.velocity[k] == pytest.approx(2.0, abs=0.01)
    assert res.spectrogram.doppler[k] > 0


def test_aliased_target_observed_at_minus_899_hz() -> None:
    with pytest.warns(UserWarning, match="aliases"):
        res = point_run([{"position": [100.0, 0, 0], "velocity": [-15.0, 0, 0]}], duration=1.0)
    est = phase_increment_doppler(res.received.signal, PRF)
    assert est == pytest.approx(-898.9616, abs=1e-3)
    assert np.all(np.abs(peak_frequency_per_frame(res) + 898.9616) <= PRF / 1024 / 2 + 1e-9)


def test_range_equation_reference_values() -> None:
    lam = radar.wavelength(FC)
    a = radar.range_equation_amplitude(1.0, 10.0, wavelength=lam)
    assert float(a) == pytest.approx(4.486572e-6, rel=1e-6, abs=0)
    assert float(a) ** 2 == pytest.approx(2.012933e-11, rel=1e-6, abs=0)
    ratio = radar.range_equation_amplitude(1.0, 5.0, wavelength=lam) / a
    assert float(ratio) == pytest.approx(4.0, rel=1e-14)
    # amplitude scales with sqrt(rcs) and sqrt(P_t), linearly with gain, 1/sqrt(losses)
    a2 = radar.range_equation_amplitude(
        4.0, 10.0, wavelength=lam, transmit_power=9.0, gain=2.0, system_loss=4.0
    )
    assert float(a2 / a) == pytest.approx(2 * 3 * 2 / 2, rel=1e-14)


def test_chen_amplitude_model_is_sqrt_rcs_at_any_range() -> None:
    """amplitude = "sqrt_rcs" (Chen's walker code): sqrt(sigma), no range dependence, on a
    radar config as on the physics function; the default stays the range equation."""
    from mdf_lfm.waveform import LfmConfig, LfmPulseDoppler

    rcs = np.array([[0.25, 1.0], [0.04, 2.0]])
    ranges = np.array([[5.0, 10.0], [7.5, 1000.0]])
    a = radar.scatterer_amplitudes(rcs, ranges, model="sqrt_rcs", wavelength=0.02)
    np.testing.assert_allclose(a, np.sqrt(rcs), rtol=0, atol=0)
    chen = LfmPulseDoppler(LfmConfig(amplitude="sqrt_rcs", transmit_power=50.0))
    np.testing.assert_allclose(chen.amplitudes(ranges, rcs), np.sqrt(rcs), rtol=0, atol=0)
    default = LfmPulseDoppler(LfmConfig())
    np.testing.assert_allclose(
        default.amplitudes(ranges, rcs),
        radar.range_equation_amplitude(rcs, ranges, wavelength=radar.wavelength(15e9)),
        rtol=1e-15,
    )


def test_range_equation_refuses_zero_range() -> None:
    with pytest.raises(ValueError, match="positive"):
        radar.range_equation_amplitude(1.0, np.array([1.0, 0.0]), wavelength=0.02)


def test_compressed_envelope_peak_and_minus_3db_width() -> None:
    tau, bw = 2e-6, 150e6
    assert float(radar.lfm_compressed_envelope(0.0, tau, bw)) == pytest.approx(tau)
    # -3 dB full width from a fine delay grid, in metres of range
    d = np.linspace(-3e-8, 3e-8, 600001)
    chi = radar.lfm_compressed_envelope(d, tau, bw) / tau
    above = d[chi**2 >= 0.5]
    width_m = (above[-1] - above[0]) * SPEED_OF_LIGHT / 2
    assert width_m == pytest.approx(0.88483, abs=2e-4)
    # first null at c / 2B (large-TB limit to within 1 %)
    null = d[(d > 0) & (chi <= 0)][0] * SPEED_OF_LIGHT / 2
    assert null == pytest.approx(SPEED_OF_LIGHT / (2 * bw), rel=0.01)


def test_sinc_gate_response_large_tb_minus_3db_width_and_first_null() -> None:
    """Section 5, large-TB limit (``gate_response = "sinc"``): the -3 dB full width is
    0.885893 c/(2B) = 0.88528 m at 150 MHz and the first null sits at c/(2B) = 0.99931 m."""
    bw = 150e6
    dr = np.linspace(-1.5, 1.5, 3_000_001)
    w = radar.gate_weights(
        dr[:, None], np.zeros(dr.size), pulse_width=1.0, bandwidth=bw, response="sinc"
    )[:, 0]
    above = dr[w**2 >= 0.5]
    assert above[-1] - above[0] == pytest.approx(0.88528, abs=2e-5)
    assert above[-1] - above[0] == pytest.approx(0.885893 * SPEED_OF_LIGHT / (2 * bw), abs=2e-6)
    null = dr[(dr > 0) & (w <= 0)][0]
    assert null == pytest.approx(0.99931, abs=1e-5)


def test_sampled_matched_filter_peak_value_position_and_phase() -> None:
    """Raw chirp echo, pulse-compressed: the peak is a*tau at the target range with phase
    -4 pi f_c R / c mod 2 pi (-2.414527 rad for R = 150 m)."""
    tau, bw, fs, r = 2e-6, 150e6, 1.2e9, 150.0
    t = np.arange(int(2 * r / SPEED_OF_LIGHT * fs) - 3000, int(2 * r / SPEED_OF_LIGHT * fs) + 3000)
    fast = t / fs
    s = radar.raw_pulse_returns(
        np.array([[r]]),
        np.array([[1.0]]),
        fast,
        carrier_frequency=FC,
        pulse_width=tau,
        bandwidth=bw,
    )
    y = radar.matched_filter(s, fs, pulse_width=tau, bandwidth=bw)[0]
    k = int(np.argmax(np.abs(y)))
    assert fast[k] * SPEED_OF_LIGHT / 2 == pytest.approx(r, abs=SPEED_OF_LIGHT / (2 * fs))
    exact = radar.compress_at_delay(
        s, fast, np.array([2 * r / SPEED_OF_LIGHT]), pulse_width=tau, bandwidth=bw
    )[0]
    assert abs(exact) == pytest.approx(tau, rel=1e-3)
    assert np.angle(exact) == pytest.approx(-2.414527, abs=1e-4)
    # and the sampled output follows the analytic envelope chi at every lag within the pulse
    chi = radar.lfm_compressed_envelope(fast - 2 * r / SPEED_OF_LIGHT, tau, bw)
    assert np.max(np.abs(np.abs(y) - np.abs(chi))) < 2e-3 * tau


def test_gate_weight_of_scatterer_half_a_metre_away() -> None:
    w = radar.gate_weights(
        np.array([[10.5]]), np.array([10.0]), pulse_width=1e-6, bandwidth=150e6, response="sinc"
    )
    assert float(w[0, 0]) == pytest.approx(0.636, abs=1e-3)
    w_exact = radar.gate_weights(
        np.array([[10.5]]), np.array([10.0]), pulse_width=1e-6, bandwidth=150e6, response="exact"
    )
    assert float(w_exact[0, 0]) == pytest.approx(0.636, abs=3e-3)


def test_raw_and_analytic_paths_agree() -> None:
    """Two scatterers moving apart inside the gate: the raw path (sampled chirps, matched
    filter) and the analytic path (eq. 4 exact) give the same slow-time signal."""
    targets = [
        {"position": [20.0, 0, 0], "velocity": [-1.2, 0, 0], "rcs": 1.0},
        {"position": [20.3, 0.5, 0], "velocity": [0.8, 0.3, 0], "rcs": 0.3},
    ]
    common = {"pulse_width": 1e-6, "bandwidth": 150e6}
    ana = point_run(targets, duration=0.5, radar={**common, "path": "analytic"})
    raw = point_run(targets, duration=0.5, radar={**common, "path": "raw"})
    a, b = ana.received.signal, raw.received.signal
    assert np.max(np.abs(a - b)) / np.max(np.abs(a)) < 2e-3
    strong = ana.spectrogram_db > -20
    assert np.max(np.abs(ana.spectrogram_db - raw.spectrogram_db)[strong]) < 0.05
    # the range-time map peaks at the strong target's range
    rt, rng = raw.received.range_time, raw.received.range_axis
    assert rt is not None and rng is not None
    assert rng[np.argmax(np.abs(rt[0]))] == pytest.approx(20.0, abs=0.5)


def test_tracking_gate_constant_and_fixed_gate_decays() -> None:
    """physics.md 6.6: a lone target walking away keeps its amplitude in a tracking gate; in a
    fixed gate its amplitude follows the compressed envelope."""
    targets = [{"position": [20.0, 0, 0], "velocity": [1.0, 0, 0]}]
    tracked = point_run(targets, duration=1.5)
    amp = np.abs(tracked.received.signal) * tracked.scatterers.ranges(np.zeros(3))[:, 0] ** 2
    assert np.ptp(amp) / amp.mean() < 1e-12
    fixed = point_run(targets, duration=1.5, scene={"gate": 20.0})
    r = fixed.scatterers.ranges(np.zeros(3))[:, 0]
    lam = radar.wavelength(FC)
    a = radar.range_equation_amplitude(1.0, r, wavelength=lam)
    expected = a * radar.lfm_compressed_envelope(2 * (20.0 - r) / SPEED_OF_LIGHT, 1e-6, 150e6)
    assert np.allclose(np.abs(fixed.received.signal), np.abs(expected) / 1e-6, rtol=1e-9)
    # essentially gone one range cell (c/2B = 0.9993 m, t = 0.9993 s) from the gate
    k = int(np.argmin(np.abs(r - 20.0 - SPEED_OF_LIGHT / 2 / 150e6)))
    assert abs(fixed.received.signal[k]) < 0.01 * abs(fixed.received.signal[0])


@pytest.mark.parametrize("x", [0.0, 0.25, 0.5, 0.77])
def test_summing_range_bins_gives_the_phase_only_return(x: float) -> None:
    """Section 5: sum_k sinc(k - x) = 1 for any sub-bin position x, so summing the sinc-gated
    return over gates spaced c / 2B (Chen's sum over range bins) reproduces the phase-only
    return, to 1e-7 over 6001 gates. The raw path agrees in the large-TB limit: its whole
    compressed range-time row (fs = 2B, so times B / fs), at TB = 1500, is the phase-only
    return to 2 % in magnitude and 0.01 rad in phase (the exact LFM response is not quite the
    sinc; at TB = 150 it falls 9 % short)."""
    bandwidth, tau = 150e6, 1e-5
    c = SPEED_OF_LIGHT
    bin_m = c / (2 * bandwidth)
    r = 100.0 + x * bin_m
    phase_only = np.exp(-4j * np.pi * FC * r / c)
    gates = 100.0 + np.arange(-3000, 3001) * bin_m
    w = radar.gate_weights(
        np.full((gates.size, 1), r), gates, pulse_width=tau, bandwidth=bandwidth, response="sinc"
    )
    assert complex(np.sum(w) * phase_only) == pytest.approx(phase_only, abs=1e-7)
    fs = 2 * bandwidth
    k0 = int((2 * r / c - tau) * fs) - 10
    fast = np.arange(k0, int((2 * r / c + 2 * tau) * fs) + 10) / fs
    kw = {"pulse_width": tau, "bandwidth": bandwidth}
    echo = radar.raw_pulse_returns(
        np.array([[r]]), np.array([[1.0]]), fast, carrier_frequency=FC, **kw
    )
    total = complex(np.sum(radar.matched_filter(echo, fs, **kw)) / tau * bandwidth / fs)
    assert abs(total / phase_only) == pytest.approx(1.0, abs=0.02)
    assert abs(np.angle(total / phase_only)) < 0.01


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_analytic_amplitude_is_the_range_equation_with_gain_and_losses(precision: str) -> None:
    """A still point in the tracking gate gives |y| = sqrt(P_t G^2 lambda^2 sigma / ((4 pi)^3
    R^4 L_s L_a)) (physics.md 1.3), written out here with G = 10^(dBi/10) and each loss
    10^(dB/10): P_t = 2 W, 20 dBi, L_s = 3 dB, L_a = 1 dB, sigma = 0.5 m^2, R = 10 m, to the
    precision's rounding. The analytic path builds this product itself (not through
    radar.range_equation_amplitude), so a gain taken once, a dBi read as an amplitude ratio or
    a loss that divides the other by the wrong sign each shows here."""
    lam = SPEED_OF_LIGHT / FC
    g, loss = 10.0 ** (20.0 / 10), 10.0 ** (3.0 / 10) * 10.0 ** (1.0 / 10)
    expected = np.sqrt(2.0 * g**2 * lam**2 * 0.5 / ((4 * np.pi) ** 3 * 10.0**4 * loss))
    powered = {"transmit_power": 2.0, "gain_dbi": 20.0, "system_loss_db": 3.0}
    res = point_run(
        [{"position": [10.0, 0, 0], "velocity": [0.0, 0, 0], "rcs": 0.5}],
        duration=0.2,
        radar={**powered, "atmospheric_loss_db": 1.0, "precision": precision},
    )
    rtol = 1e-6 if precision == "float32" else 1e-12
    np.testing.assert_allclose(np.abs(res.received.signal), expected, rtol=rtol)


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_analytic_sinc_gate_weights_a_point_half_a_metre_away_by_0_636(precision: str) -> None:
    """gate_response = "sinc" on the plugin's analytic path (its own float32/float64 code, not
    radar.gate_weights): a still point 0.5 m beyond a fixed 10 m gate is weighted by
    sinc(2 B (0.5 m) / c) = sinc(0.5 / 0.9993) = 0.636 (physics.md 1.4), relative to the
    range-equation amplitude at its own range."""
    res = point_run(
        [{"position": [10.5, 0, 0], "velocity": [0.0, 0, 0]}],
        duration=0.2,
        radar={"gate_response": "sinc", "precision": precision},
        scene={"gate": 10.0},
    )
    a = radar.range_equation_amplitude(1.0, 10.5, wavelength=SPEED_OF_LIGHT / FC)
    weight = np.abs(res.received.signal) / float(a)
    np.testing.assert_allclose(weight, np.sinc(2 * 150e6 * 0.5 / SPEED_OF_LIGHT), rtol=1e-5)
    assert weight[0] == pytest.approx(0.636, abs=1e-3)
