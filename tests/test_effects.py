"""Physics of the built-in scene effects (noise, clutter, multipath, antenna, attenuation) and
the rule that an effect the scene does not call for does no work."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest
from helpers import traced_peak
from mdf_antenna import one_way_gain
from mdf_antenna.antenna import SINC2_HALF_POWER
from mdf_clutter import GroundClutter, clutter
from mdf_lfm import LfmPulseDoppler
from mdf_noise import ReceiverNoise

from mdframework import Received, SceneContext, Skeleton
from mdframework.check import plan_run
from mdframework.config import validate_run_config
from mdframework.constants import BOLTZMANN, SPEED_OF_LIGHT
from mdframework.physics import radar
from mdframework.physics.spectrogram import spectrogram
from mdframework.pipeline import (
    RunResult,
    build_stages,
    load_motion,
    simulate,
    simulate_motion,
)
from mdframework.plugins import default_registry

LAM = SPEED_OF_LIGHT / 15e9
#: every installed effect (the built-in ones: noise, clutter, multipath, antenna, attenuation,
#: shadowing, static scene; and any other on this machine)
ALL_EFFECTS = tuple(
    default_registry().get("effects", name) for name in default_registry().names("effects")
)
#: the methods through which an effect does work
EFFECT_METHODS = ("__init__", "start_record", "check_radar", "check_effects", "apply", "describe")


def run(
    targets: list[dict[str, Any]],
    effects: list[dict[str, Any]],
    *,
    radar_position: tuple[float, float, float] = (0.0, 0.0, 0.0),
    duration: float = 2.0,
    radar_cfg: dict[str, Any] | None = None,
    gate: str | float = "track",
    seed: int = 0,
    processing: dict[str, Any] | None = None,
) -> RunResult:
    radar_cfg = radar_cfg or {}
    lfm = {"kind": "lfm", "precision": "float64"} if radar_cfg.get("kind", "lfm") == "lfm" else {}
    cfg = {
        "motion": {"kind": "point_targets", "length": duration, "targets": targets},
        "scatterers": {"kind": "points"},
        "radar": {**lfm, **radar_cfg},
        "scene": {"radar_position": list(radar_position), "gate": gate},
        "processing": {"keep_scatterers": True, **(processing or {})},
        "effects": effects,
        "seed": seed,
    }
    return simulate(validate_run_config(cfg))


APPROACHING = [{"position": [20.0, 0.0, 0.0], "velocity": [-1.0, 0.0, 0.0], "rcs": 1.0}]


# --------------------------------------------------------------------------- noise


@pytest.mark.parametrize("snr_db", [-10.0, 0.0, 20.0])
def test_noise_power_matches_requested_snr(snr_db: float) -> None:
    clean = run(APPROACHING, [])
    noisy = run(APPROACHING, [{"kind": "noise", "snr_db": snr_db}])
    noise = noisy.received.signal - clean.received.signal
    p_sig = np.mean(np.abs(clean.received.signal) ** 2)
    measured = 10 * np.log10(p_sig / np.mean(np.abs(noise) ** 2))
    # 4800 complex samples: the power estimate has a relative std of 1/sqrt(4800) = 1.4 %
    assert measured == pytest.approx(snr_db, abs=0.25)
    # white and circular: real and imaginary parts carry equal power, neighbours uncorrelated
    assert np.var(noise.real) / np.var(noise.imag) == pytest.approx(1.0, abs=0.1)
    rho = np.abs(np.mean(noise[1:] * np.conj(noise[:-1]))) / np.mean(np.abs(noise) ** 2)
    assert rho < 0.06
    assert noisy.metadata["effects"][0]["noise_power_w"] == pytest.approx(
        p_sig * 10 ** (-snr_db / 10), rel=1e-12, abs=0
    )


def test_thermal_noise_is_kTF_over_tau_after_compression() -> None:
    tau, bw, nf_db, temp = 2e-6, 150e6, 4.0, 500.0
    eff = {"kind": "noise", "mode": "thermal", "noise_figure_db": nf_db, "temperature": temp}
    rcfg = {"pulse_width": tau, "bandwidth": bw}
    clean = run(APPROACHING, [], radar_cfg=rcfg)
    noisy = run(APPROACHING, [eff], radar_cfg=rcfg)
    expected = BOLTZMANN * temp * 10 ** (nf_db / 10) / tau  # k T F B / (tau B)
    noise = noisy.received.signal - clean.received.signal
    assert np.mean(np.abs(noise) ** 2) == pytest.approx(expected, rel=0.06, abs=0)
    # thermal noise does not depend on the signal (unlike mode 'snr')
    strong = [{**APPROACHING[0], "rcs": 100.0}]
    noisy_strong = run(strong, [eff], radar_cfg=rcfg)
    assert noisy_strong.metadata["effects"][0]["noise_power_w"] == pytest.approx(
        expected, rel=1e-12, abs=0
    )


def test_thermal_noise_is_refused_without_the_range_equation() -> None:
    """With sqrt(rcs) amplitudes the signal is not in watts: k T F / tau beside it would be
    noise some 140 dB below a 1 m^2 target, silently."""
    from mdframework import SceneError

    thermal = [{"kind": "noise", "mode": "thermal"}]
    with pytest.raises(SceneError, match=r"^effects\.noise: mode 'thermal' .*'sqrt_rcs'"):
        run(APPROACHING, thermal, radar_cfg={"amplitude": "sqrt_rcs"}, duration=0.2)
    with pytest.raises(SceneError, match=r"^effects\.noise: mode 'thermal' .*'sqrt_rcs'"):
        run(APPROACHING, thermal, radar_cfg={"kind": "cw", "amplitude": "sqrt_rcs"}, duration=0.2)
    snr = run(APPROACHING, [{"kind": "noise"}], radar_cfg={"amplitude": "sqrt_rcs"}, duration=0.2)
    assert snr.metadata["effects"][0]["noise_power_w"] > 0


def test_thermal_noise_with_a_cw_radar_takes_the_pages_pulse_width_and_bandwidth() -> None:
    """docs/effects.md: the cw radar has neither a pulse width nor a bandwidth; mode thermal
    without them is refused naming the field, and ``pulse_width = 1 / sample_rate`` with
    ``bandwidth = sample_rate`` gives k T F times the I/Q rate, per sample, as the page says."""
    from mdframework import SceneError

    fs = 2400.0
    cw = {"kind": "cw", "sample_rate": fs}
    thermal = {"kind": "noise", "mode": "thermal"}
    refused = r"^effects\.noise\.pulse_width: mode 'thermal' needs pulse_width; the 'cw' "
    with pytest.raises(SceneError, match=refused):
        run(APPROACHING, [thermal], radar_cfg=cw, duration=0.2)
    cfg = {
        "motion": {"kind": "point_targets", "length": 0.2, "targets": APPROACHING},
        "scatterers": {"kind": "points"},
        "radar": cw,
        "effects": [thermal],
    }
    with pytest.raises(SceneError, match=refused):  # mdf check too, before any pulse
        plan_run(validate_run_config(cfg))
    given = {**thermal, "pulse_width": 1 / fs, "bandwidth": fs}
    res = run(APPROACHING, [given], radar_cfg=cw, duration=0.2)
    kt_f = BOLTZMANN * 290.0 * 10 ** (3.0 / 10)  # the effect's default T and F
    assert res.metadata["effects"][0]["noise_power_w"] == pytest.approx(kt_f * fs, rel=1e-12, abs=0)


def test_noise_in_raw_samples_without_a_noise_bandwidth_is_refused_by_mdf_check() -> None:
    """A radar that takes the noise effect into its raw samples (``takes_receiver_inputs``)
    but has no ``sample_rate`` to default the noise bandwidth to (a third-party radar: the
    shipped FMCW radar has one) needs the effect's noise_bandwidth: refused when the run is
    planned (``mdf check``) and built, before any pulse, with one line naming the field; given,
    the run goes."""
    from types import ModuleType
    from typing import Literal

    import synthetic
    from mdf_lfm.waveform import LfmConfig

    from mdframework import SceneError
    from mdframework.plugins import build_registry

    class RawConfig(LfmConfig):
        """The LFM radar's fields (``sample_rate`` None by default)."""

        kind: Literal["raw_lfm"] = "raw_lfm"

    class RawLfm(LfmPulseDoppler):
        """An LFM radar that takes the received-stage effects into its raw samples."""

        name = "raw_lfm"
        Config = RawConfig

        @property
        def takes_receiver_inputs(self) -> bool:
            return True

    module = ModuleType("raw_lfm_plugin")
    module.mdframework_register_radar_waveforms = synthetic.hookimpl(  # type: ignore[attr-defined]
        lambda: [RawLfm]
    )
    reg = build_registry([module])
    thermal = {"kind": "noise", "mode": "thermal"}
    cfg = {
        "motion": {"kind": "point_targets", "length": 0.2, "targets": APPROACHING},
        "scatterers": {"kind": "points"},
        "radar": {"kind": "raw_lfm"},
        "effects": [thermal],
    }
    line = (
        "effects.noise.noise_bandwidth: mode 'thermal' in the raw samples of the 'raw_lfm' "
        "radar needs noise_bandwidth (it has no sample_rate): set it in the effect"
    )
    for call in (plan_run, simulate):
        with pytest.raises(SceneError) as exc:
            call(validate_run_config(cfg, registry=reg), reg)
        assert str(exc.value) == line
    given = {**cfg, "effects": [{**thermal, "noise_bandwidth": 1e6}]}
    plan_run(validate_run_config(given, registry=reg), reg)


def test_noise_floor_in_spectrogram_is_sigma2_sum_w2() -> None:
    """The SNR is per pulse; in the spectrogram the floor per bin is sigma^2 sum(w^2)."""
    noisy = run(APPROACHING, [{"kind": "noise", "snr_db": 0.0}])
    clean = run(APPROACHING, [])
    sigma2 = noisy.metadata["effects"][0]["noise_power_w"]
    spec = spectrogram(noisy.received.signal - clean.received.signal, 2400.0, nfft=256)
    w = np.hanning(257)[:-1]  # scipy's periodic hann of length 256
    assert np.mean(spec.power) == pytest.approx(sigma2 * np.sum(w**2), rel=0.05)


def test_tone_to_floor_gain_of_the_default_window_is_the_pages() -> None:
    """docs/effects.md: a tone of power P peaks at P (sum w)^2 in the spectrogram, over a floor
    of sigma^2 sum w^2 (test above), so the tone-to-floor ratio is the per-pulse SNR plus
    10 log10((sum w)^2 / sum w^2), which the page quotes for the default 256-sample Hann
    window."""
    import re

    from conftest import ROOT

    prf, power = 2400.0, 2.0
    t = np.arange(4800) / prf
    tone = np.sqrt(power) * np.exp(2j * np.pi * (10 * prf / 256) * t)  # on a bin of nfft 256
    spec = spectrogram(tone, prf, nfft=256)
    w = np.hanning(257)[:-1]  # scipy's periodic hann of length 256, the default window
    assert spec.power.max() == pytest.approx(power * w.sum() ** 2, rel=1e-6)
    gain_db = 10 * np.log10(w.sum() ** 2 / np.sum(w**2))
    page = " ".join((ROOT / "docs" / "effects.md").read_text().split())
    quoted = re.search(r"\(\+([\d.]+) dB for a 256-sample Hann window\)", page)
    assert quoted is not None and quoted.group(1) == f"{gain_db:.1f}"


def test_noise_is_seeded() -> None:
    a = run(APPROACHING, [{"kind": "noise"}], seed=3)
    b = run(APPROACHING, [{"kind": "noise"}], seed=3)
    c = run(APPROACHING, [{"kind": "noise"}], seed=4)
    assert np.array_equal(a.received.signal, b.received.signal)
    assert not np.allclose(a.received.signal, c.received.signal)


def test_noise_on_raw_path_reaches_range_time_map() -> None:
    clean = run(APPROACHING, [], radar_cfg={"path": "raw"}, duration=0.2)
    noisy = run(
        APPROACHING, [{"kind": "noise", "snr_db": 10.0}], radar_cfg={"path": "raw"}, duration=0.2
    )
    assert clean.received.range_time is not None and noisy.received.range_time is not None
    diff = noisy.received.range_time - clean.received.range_time
    sigma2 = noisy.metadata["effects"][0]["noise_power_w"]
    assert np.mean(np.abs(diff) ** 2) == pytest.approx(sigma2, rel=0.05, abs=0)


# --------------------------------------------------------------------------- clutter


def clutter_context(gate: float, n: int, seed: int = 0) -> SceneContext:
    t = np.arange(n) / 2400.0
    skel = Skeleton(t, np.zeros((n, 1, 3)), ("target0",))
    wf = LfmPulseDoppler(LfmPulseDoppler.Config())
    return SceneContext(
        np.zeros(3), 2400.0, 15e9, t, np.full(n, gate), skel, wf, np.random.default_rng(seed)
    )


@pytest.mark.parametrize(("spread", "fraction"), [(0.1, 0.3), (0.3, 0.6)])
def test_clutter_sits_at_zero_doppler_with_requested_spread(spread: float, fraction: float) -> None:
    n = 4 * 2400
    ctx = clutter_context(15.0, n)
    eff = GroundClutter(
        GroundClutter.Config(power="rcs", rcs_m2=1.0, wind_fraction=fraction, spread_mps=spread)
    )
    out = eff.apply(Received(np.zeros(n, complex)), ctx).signal
    p_total = np.mean(np.abs(out) ** 2)
    dc = np.mean(out)
    # the stationary part is constant under a fixed gate: all of it at 0 Hz
    assert abs(dc) ** 2 / p_total == pytest.approx(1 - fraction, abs=0.05)
    resid = out - dc
    f = np.fft.fftfreq(n, 1 / 2400.0)
    psd = np.abs(np.fft.fft(resid)) ** 2
    mean_f = np.sum(f * psd) / np.sum(psd)
    std_v = np.sqrt(np.sum((f - mean_f) ** 2 * psd) / np.sum(psd)) * LAM / 2
    assert abs(mean_f) * LAM / 2 < 0.1 * spread  # centred on zero Doppler
    assert std_v == pytest.approx(spread, rel=0.1)


def velocity_spread(x: np.ndarray, rate: float) -> float:
    """Standard deviation [m/s] of the velocity spectrum (15 GHz) of samples ``x`` at ``rate``."""
    f = np.fft.fftfreq(x.shape[-1], 1 / rate)
    w = np.hanning(x.shape[-1])  # a short record's leakage would widen the spectrum
    psd = np.sum(np.abs(np.fft.fft(x * w, axis=-1)) ** 2, axis=tuple(range(x.ndim - 1)))
    mean_f = np.sum(f * psd) / np.sum(psd)
    return float(np.sqrt(np.sum((f - mean_f) ** 2 * psd) / np.sum(psd)) * LAM / 2)


def test_wind_blown_clutter_spread_holds_for_tdm_chirps_and_frame_gaps() -> None:
    """The wind-blown process follows the pulse times, not the pulse count at ``prf``: with
    three transmitters in turn (chirps at 3 x 2400 Hz, each virtual antenna's slow time, every
    third chirp, at the 2400 Hz ``prf``) that slow time has the requested spread (it had three
    times it); with gaps between frames, each frame's samples have the requested spread and
    frames 0.64 s apart are decorrelated (they were as correlated as neighbouring chirps)."""
    spread = 0.3  # 30.0 Hz at 15 GHz: correlated over a few ms
    eff = GroundClutter(GroundClutter.Config(csr_db=0.0, wind_fraction=1.0, spread_mps=spread))
    n = 3 * 4 * 2400
    ctx = clutter_context(15.0, n)
    tdm = dataclasses.replace(ctx, pulse_times=np.arange(n) / (3 * 2400.0))
    out = eff.apply(Received(np.ones(n, complex)), tdm).signal - 1.0
    assert velocity_spread(out[::3], 2400.0) == pytest.approx(spread, rel=0.1)
    # frames of 512 chirps at 2400 Hz, one every 4 x 512 / 2400 s
    frame_t = (np.arange(30)[:, None] * 2048 + np.arange(512)[None, :]) / 2400.0
    n = frame_t.size
    ctx = clutter_context(15.0, n)
    gaps = dataclasses.replace(ctx, pulse_times=frame_t.ravel())
    out = (eff.apply(Received(np.ones(n, complex)), gaps).signal - 1.0).reshape(30, 512)
    assert velocity_spread(out, 2400.0) == pytest.approx(spread, rel=0.15)
    across = np.mean(out[1:, 0] * np.conj(out[:-1, -1])) / np.mean(np.abs(out) ** 2)
    within = np.mean(out[:, 1:] * np.conj(out[:, :-1])) / np.mean(np.abs(out) ** 2)
    assert abs(within) > 0.99
    assert abs(across) < 0.5  # true: exp(-2 pi^2 (30 Hz)^2 (0.64 s)^2) ~ 0


def test_wind_blown_clutter_keeps_chirps_apart_when_frames_sit_half_a_chirp_off() -> None:
    """Frames 100.5 chirp periods apart (times exact in binary) put every other frame's chirps
    half-way between grid points: each chirp still gets its own sample of the process
    (rounding half to even gave pairs of chirps one sample, and the next pair one two grid
    steps on)."""
    tc = 2.0**-13  # chirp period [s]
    frame_t = (np.arange(40)[:, None] * 100.5 + np.arange(16)[None, :]) * tc
    n = frame_t.size
    eff = GroundClutter(GroundClutter.Config(csr_db=0.0, wind_fraction=1.0, spread_mps=0.3))
    ctx = dataclasses.replace(clutter_context(15.0, n), pulse_times=frame_t.ravel())
    out = (eff.apply(Received(np.ones(n, complex)), ctx).signal - 1.0).reshape(40, 16)
    assert np.all(np.abs(np.diff(out, axis=1)) > 0)  # no two chirps share a sample


def test_clutter_rcs_mode_follows_the_range_equation() -> None:
    n = 2400
    ctx = clutter_context(15.0, n)
    eff = GroundClutter(GroundClutter.Config(power="rcs", rcs_m2=2.0))
    out = eff.apply(Received(np.zeros(n, complex)), ctx).signal
    a2 = radar.range_equation_amplitude(2.0, 15.0, wavelength=LAM) ** 2
    # one resolution cell of clutter RCS sigma at the gate gives about a(R, sigma)^2
    assert np.mean(np.abs(out) ** 2) == pytest.approx(a2, rel=0.15)


@pytest.mark.parametrize("kind", ["lfm", "cw"])
def test_clutter_patches_lose_what_their_range_loses_through_the_attenuation(kind: str) -> None:
    """Ground clutter goes through the same rain as the target: with ``attenuation`` in the
    scene (listed anywhere) a patch at range ``r`` carries ``-2 gamma r`` dB more (one patch
    here, the gate fixed at 20 m, no margin), and the summed power follows it (the same draws);
    two attenuation effects (60 % and 40 % of gamma) lose as much together."""
    gamma = 100.0  # dB/km one way
    patch = {
        "kind": "clutter",
        "power": "rcs",
        "rcs_m2": 1.0,
        "wind_fraction": 0.3,
        "patch_spacing_m": 0.5,
        "margin_m": 0.0,
        "range_resolution": 1.0,
    }
    target = [{"position": [20.0, 0.0, 0.0], "velocity": [-1.0, 0.0, 0.0], "rcs": 1e-6}]
    radar_cfg = {"kind": kind}
    plain = run(target, [patch], radar_cfg=radar_cfg, gate=20.0, duration=0.2)
    for effects in ([patch, {"kind": "attenuation", "gas_db_per_km": gamma}],
                    [{"kind": "attenuation", "gas_db_per_km": gamma}, patch],
                    [{"kind": "attenuation", "gas_db_per_km": 0.6 * gamma}, patch,
                     {"kind": "attenuation", "gas_db_per_km": 0.4 * gamma}]):  # fmt: skip
        res = run(target, effects, radar_cfg=radar_cfg, gate=20.0, duration=0.2)
        clutter = next(e for e in res.metadata["effects"] if e["kind"] == "clutter")
        before = plain.metadata["effects"][0]
        r_lo, r_hi = clutter["patch_range_m"]
        assert clutter["n_patches"] == 1 and r_lo == r_hi == before["patch_range_m"][0]
        loss = 10 ** (-2 * gamma * r_lo / 1e4)
        assert clutter["clutter_power_w"] == pytest.approx(
            before["clutter_power_w"] * loss, rel=1e-9, abs=0
        )


@pytest.mark.parametrize("noise_first", [True, False])
def test_snr_and_csr_are_both_relative_to_the_echo_in_either_order(noise_first: bool) -> None:
    """``snr_db`` and ``csr_db`` are set against the echo as the radar gave it: the noise's
    level does not count the clutter, nor the clutter's the noise, whichever comes first (it
    was the signal as each effect got it: 0.4 dB off at 10 dB each)."""
    echo = float(np.mean(np.abs(run(APPROACHING, []).received.signal) ** 2))
    noise = {"kind": "noise", "snr_db": 10.0}
    clutter = {"kind": "clutter", "csr_db": 10.0, "wind_fraction": 0.3}
    res = run(APPROACHING, [noise, clutter] if noise_first else [clutter, noise])
    got = {e["kind"]: e for e in res.metadata["effects"]}
    assert got["noise"]["noise_power_w"] == pytest.approx(echo / 10.0, rel=1e-12, abs=0)
    assert got["clutter"]["clutter_power_w"] == pytest.approx(echo * 10.0, rel=1e-12, abs=0)


def test_clutter_csr_in_pipeline_and_zero_velocity_bin() -> None:
    clean = run(APPROACHING, [])
    res = run(APPROACHING, [{"kind": "clutter", "csr_db": 10.0, "wind_fraction": 0.0}])
    added = res.received.signal - clean.received.signal
    ratio = np.mean(np.abs(added) ** 2) / np.mean(np.abs(clean.received.signal) ** 2)
    assert 10 * np.log10(ratio) == pytest.approx(10.0, abs=1e-9)
    spec = res.spectrogram
    k0 = int(np.argmin(np.abs(spec.doppler)))
    k_target = int(np.argmin(np.abs(spec.doppler - 2.0 / LAM)))  # 1 m/s approaching
    mean_power = spec.power.mean(axis=1)
    assert int(np.argmax(mean_power)) in (k0 - 1, k0, k0 + 1)
    assert mean_power[k_target] > 100 * np.median(mean_power)  # the target is still there


@pytest.mark.parametrize("power", ["csr", "rcs"])
def test_clutter_made_a_group_of_patches_at_a_time_equals_all_patches_at_once(
    power: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Under a tracking gate crossing 25 m (67 patches), the clutter made a few patches at a time
    is the clutter computed directly from all patches' responses and wind-blown processes at
    once (the same draws): stationary ``alpha @ g``, wind-blown ``sum_k g_k u_k``, each scaled to
    its share of the clutter power."""
    monkeypatch.setattr(clutter, "WIND_GRID_VALUES", 3 * 4800)  # groups of 3 patches
    n, spread, fraction = 4800, 0.2, 0.4
    cfg = GroundClutter.Config(
        power=power, csr_db=3.0, rcs_m2=0.7, wind_fraction=fraction, spread_mps=spread
    )
    gate = np.linspace(15.0, 40.0, n)
    ctx = dataclasses.replace(clutter_context(15.0, n, seed=5), gate_range=gate)
    signal = np.exp(2j * np.pi * 40.0 * ctx.pulse_times) * (1.0 + np.arange(n) / n)
    out = GroundClutter(cfg).apply(Received(signal.copy()), ctx).signal

    ref = dataclasses.replace(ctx, rng=np.random.default_rng(5))
    eff = GroundClutter(cfg)
    ranges, g = eff.patch_responses(ref)
    k = ranges.size
    assert k == 67
    alpha = (ref.rng.standard_normal(k) + 1j * ref.rng.standard_normal(k)) / np.sqrt(2)
    rate = 1.0 / np.min(np.diff(ref.pulse_times))  # the grid: the shortest pulse interval
    u = clutter.gaussian_doppler_process(ref.rng, k, n, rate, 2 * spread / LAM)
    stationary, wind = alpha @ g, np.sum(g * u, axis=0)
    if power == "csr":
        p_c = np.mean(np.abs(signal) ** 2) * 10 ** (3.0 / 10)
    else:  # patches every half resolution cell
        p_c = 0.7 * 0.5 * np.sum(np.mean(np.abs(g) ** 2, axis=1))
    expected = (
        signal
        + stationary * np.sqrt((1 - fraction) * p_c / np.mean(np.abs(stationary) ** 2))
        + wind * np.sqrt(fraction * p_c / np.mean(np.abs(wind) ** 2))
    )
    np.testing.assert_allclose(out, expected, rtol=1e-12, atol=0)


def test_wind_processes_in_groups_are_the_processes_made_at_once() -> None:
    """Chirps in frames with gaps (a grid longer than the pulses): the wind-blown processes made
    one or two series at a time are bitwise those made a chunk at a time, and the generator
    ends where it did."""
    frame_t = (np.arange(12)[:, None] * 300 + np.arange(64)[None, :]) / 2400.0
    t = frame_t.ravel()
    at_once, grouped = np.random.default_rng(3), np.random.default_rng(3)
    whole = clutter.wind_processes(at_once, 7, t, 2400.0, 20.0)
    parts = list(clutter.wind_process_groups(grouped, 7, t, 2400.0, 20.0, group_values=5000))
    assert [(lo, hi) for lo, hi, _ in parts] == [(i, i + 1) for i in range(7)]
    assert np.array_equal(np.concatenate([u for _, _, u in parts]), whole)
    assert grouped.standard_normal() == at_once.standard_normal()


def test_clutter_memory_does_not_grow_with_the_patch_count(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A record of 8000 pulses with 127 clutter patches: the clutter's peak memory stays at a few
    dozen slow-time signals (it held every patch's response and wind-blown process, 127 of each
    and their product, over 48 MB)."""
    import tracemalloc

    monkeypatch.setattr(clutter, "WIND_GRID_VALUES", 2 * 8000)
    n = 8000
    ctx = dataclasses.replace(clutter_context(15.0, n), gate_range=np.linspace(15.0, 70.0, n))
    eff = GroundClutter(GroundClutter.Config(csr_db=0.0))
    data = Received(np.ones(n, complex))
    tracemalloc.start()
    try:
        eff.apply(data, ctx)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert eff.describe()["n_patches"] == 127
    assert peak < 40 * n * 16  # 40 complex slow-time signals: 5 MB


@pytest.mark.parametrize(("path", "n", "margin"), [("analytic", 20_000, None), ("raw", 8_000, 0.5)])
def test_clutter_memory_grows_with_the_record_by_a_few_signals(
    path: str, n: int, margin: float | None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Records of n and 3n pulses (calls of the waveform of 2000 pulses): the clutter's peak
    memory grows by a dozen slow-time signals (its sums, the wind-blown process), on the
    analytic and the raw LFM path, whose working arrays do not grow. Each call of the
    waveform spanned the whole record: the patches' positions (n, 16, 3) and, on the raw path,
    a range-time map of every pulse (a 10-minute record with clutter peaked above 1.2 GB)."""

    def peak(pulses: int) -> int:
        monkeypatch.setattr(clutter, "WIND_GRID_VALUES", pulses)  # one process at a time
        wf = LfmPulseDoppler(LfmPulseDoppler.Config(path=path))
        ctx = dataclasses.replace(clutter_context(15.0, pulses), waveform=wf)
        eff = GroundClutter(GroundClutter.Config(csr_db=0.0, margin_m=margin))
        _, traced = traced_peak(lambda: eff.apply(Received(np.ones(pulses, complex)), ctx))
        assert eff.describe()["n_patches"] == (17 if margin is None else 3)
        return traced

    monkeypatch.setattr(clutter, "PULSES_PER_CALL", 2000)
    peak(n)  # the first call imports what the radar needs (scipy.signal on the raw path)
    small = peak(n)
    assert peak(3 * n) - small < 12 * (2 * n) * 16


def test_clutter_with_a_radar_without_bandwidth_is_refused_before_any_pulse() -> None:
    """A CW radar gives no range resolution: the clutter effect without ``range_resolution`` is
    refused when the run's plugins are built (the radar never receives a pulse), on one line
    naming the field; with the field the same scene builds."""
    from mdframework.errors import SceneError
    from mdframework.pipeline import build_stages

    cfg = {
        "motion": {"kind": "point_targets", "length": 0.5, "targets": APPROACHING},
        "scatterers": {"kind": "points"},
        "radar": {"kind": "cw"},
        "effects": [{"kind": "clutter", "csr_db": 10.0}],
    }
    with pytest.raises(SceneError, match=r"^effects\.clutter: .*set range_resolution$"):
        build_stages(validate_run_config(cfg))
    cfg["effects"] = [{"kind": "clutter", "csr_db": 10.0, "range_resolution": 0.5}]
    assert build_stages(validate_run_config(cfg)).effects[0].name == "clutter"


def test_clutter_on_an_fmcw_radar_with_receiver_noise_holds_no_copy_of_that_noise() -> None:
    """The FMCW presets add receiver noise in the radar itself. Each clutter patch's response is
    the patch's alone: stationary clutter under a fixed gate stays at zero Doppler, and the
    clutter is the same with the radar's noise on or off. Each patch's response held the
    frame's noise, summed over the patches: a quarter of the stationary clutter's power was
    white, and ``power = "rcs"`` counted the noise as clutter power (10 % here). The clutter
    takes the FMCW radar's own range resolution (it asked for ``range_resolution``)."""
    from mdf_fmcw import FmcwRadar

    def clutter_of(receiver_noise: bool, power: str) -> np.ndarray:
        wf = FmcwRadar(
            FmcwRadar.Config(preset="iwr1443_short_range_3d", receiver_noise=receiver_noise)
        )
        t = wf.pulse_times(0.0, 0.5)
        n = t.size
        skel = Skeleton(t, np.zeros((n, 1, 3)), ("target0",))
        ctx = SceneContext(
            np.zeros(3), wf.prf, wf.carrier_frequency, t, np.full(n, 3.0), skel, wf,
            np.random.default_rng(3),
        )  # fmt: skip
        cfg = GroundClutter.Config(power=power, csr_db=0.0, rcs_m2=1.0, wind_fraction=0.0)
        signal = np.full(n, 1e-6, complex)
        return GroundClutter(cfg).apply(Received(signal), ctx).signal - signal

    for power in ("csr", "rcs"):
        noisy, clean = clutter_of(True, power), clutter_of(False, power)
        np.testing.assert_allclose(noisy, clean, rtol=1e-12, atol=0.0)
    first_slot = noisy[::3]  # one TX's chirps: one virtual antenna's slow time
    dc_fraction = abs(np.mean(first_slot)) ** 2 / np.mean(np.abs(first_slot) ** 2)
    assert dc_fraction > 0.999  # all of the stationary clutter at zero Doppler


@pytest.mark.parametrize("radar", ["lfm", "fmcw"])
def test_clutter_made_a_part_of_the_record_at_a_time_is_the_clutter_made_at_once(
    radar: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The patches' responses made 100 pulses at a time (on the FMCW radar, rounded down to its
    whole frames of 48 chirps: 96) give the clutter made from one call per patch group over the
    whole record, under a tracking gate (108 and 18 patches), in both power modes."""
    from mdf_fmcw import FmcwRadar

    if radar == "fmcw":
        wf: Any = FmcwRadar(FmcwRadar.Config(preset="iwr1443_short_range_3d"))
        t = wf.pulse_times(0.0, 0.5)
        assert wf.block_multiple == 48
    else:
        wf = LfmPulseDoppler(LfmPulseDoppler.Config())
        t = np.arange(1000) / 2400.0
    n = t.size
    skel = Skeleton(t, np.zeros((n, 1, 3)), ("target0",))
    gate = np.linspace(3.0, 5.0, n)
    signal = np.exp(2j * np.pi * 40.0 * t) * 1e-6

    def clutter_of(power: str, per_call: int) -> np.ndarray:
        monkeypatch.setattr(clutter, "PULSES_PER_CALL", per_call)
        ctx = SceneContext(
            np.zeros(3), wf.prf, wf.carrier_frequency, t, gate, skel, wf, np.random.default_rng(3)
        )
        cfg = GroundClutter.Config(power=power, csr_db=0.0, rcs_m2=1.0, wind_fraction=0.4)
        eff = GroundClutter(cfg)
        out = eff.apply(Received(signal.copy()), ctx).signal - signal
        assert eff.describe()["n_patches"] == (108 if radar == "fmcw" else 18)
        return out

    for power in ("csr", "rcs"):
        whole = clutter_of(power, 1 << 30)
        assert np.mean(np.abs(whole) ** 2) > 0
        np.testing.assert_allclose(clutter_of(power, 100), whole, rtol=1e-12, atol=0.0)


def test_a_radar_may_set_its_own_range_resolution() -> None:
    """A radar plugin that sets ``self.range_resolution`` (as a third party's might, in its
    ``__init__``) keeps it, and the clutter's cells follow it; else the config's bandwidth
    gives it (``c / 2B``); the FMCW radar's is its sampled sweep's."""
    from mdf_fmcw import FmcwRadar

    class Coarse(LfmPulseDoppler):
        def __init__(self, config: Any) -> None:
            super().__init__(config)
            self.range_resolution = 0.25

    ctx = clutter_context(15.0, 10)
    eff = GroundClutter(GroundClutter.Config())
    assert eff.resolution(ctx) == pytest.approx(SPEED_OF_LIGHT / (2 * 150e6), rel=1e-12)
    assert eff.resolution(dataclasses.replace(ctx, waveform=Coarse(Coarse.Config()))) == 0.25
    fmcw = FmcwRadar(FmcwRadar.Config(preset="iwr1443_short_range_3d"))
    assert fmcw.range_resolution == pytest.approx(0.043577, abs=1e-6)


# --------------------------------------------------------------------------- multipath

MP_RADAR = (10.0, 0.0, 5.0)
MP_TARGET = [{"position": [0.0, 0.0, 1.0], "velocity": [0.0, 0.0, 2.0], "rcs": 1.0}]


def mp_geometry(t: float) -> tuple[float, float, float, float]:
    """Direct and image ranges [m] and range rates [m/s] of MP_TARGET at time t."""
    z = 1.0 + 2.0 * t
    rd = np.hypot(10.0, 5.0 - z)
    rb = np.hypot(10.0, 5.0 + z)
    return rd, rb, -2.0 * (5.0 - z) / rd, 2.0 * (5.0 + z) / rb


def test_multipath_image_at_right_delay() -> None:
    """Raw fast-time path at 1.5 GHz bandwidth (0.1 m resolution): the range profile of one
    pulse peaks at R_d, (R_d + R_b)/2 and R_b."""
    res = run(
        MP_TARGET,
        [{"kind": "multipath", "reflection_magnitude": 0.8}],
        radar_position=MP_RADAR,
        duration=0.15,
        radar_cfg={"path": "raw", "bandwidth": 1.5e9},
        processing={"window_length": 128},
    )
    rt, axis = res.received.range_time, res.received.range_axis
    assert rt is not None and axis is not None
    k = 100
    rd, rb, _, _ = mp_geometry(res.pulse_times[k])
    prof = np.abs(rt[k])
    peaks = [i for i in range(1, len(prof) - 1) if prof[i] >= prof[i - 1] and prof[i] > prof[i + 1]]
    top = sorted(peaks, key=lambda i: -prof[i])[:3]
    found = np.sort(axis[top])
    expected = np.array([rd, 0.5 * (rd + rb), rb])
    assert np.allclose(found, expected, atol=0.06)  # fast-time grid spacing 0.05 m
    # amplitudes: |Gamma|^2 (R_d/R_b)^2 for the image, 2|Gamma| R_d/R_b-ish for the bounce
    amp = {round(float(axis[i]), 1): prof[i] for i in top}
    direct = amp[round(float(found[0]), 1)]
    image = amp[round(float(found[2]), 1)]
    assert image / direct == pytest.approx(0.8**2 * (rd / rb) ** 2, rel=0.1)


def test_multipath_extra_path_is_the_records_mean_whatever_the_blocks() -> None:
    """The metadata's mean extra path lengths are the whole record's: they were the last
    block's, so a record cut into other blocks (processing.block_pulses) wrote other values
    into metadata.json (0.65 against 0.75 m on a CMU walk). They are the mean to about 1 um,
    summed exactly, so that they are the same to the bit."""
    out = []
    for block in (16, 4096):
        res = run(
            MP_TARGET,
            [{"kind": "multipath"}],
            radar_position=MP_RADAR,
            duration=0.5,
            processing={"block_pulses": block},
        )
        out.append(res.metadata["effects"][0]["extra_path_m"])
        rd, rb, _, _ = mp_geometry(res.pulse_times)
        assert out[-1]["image_mean"] == pytest.approx(np.mean(2.0 * (rb - rd)), abs=2e-6)
        assert out[-1]["bounce_mean"] == pytest.approx(np.mean(rb - rd), abs=1e-6)
    assert out[0] == out[1]  # to the bit


def test_multipath_extra_path_of_a_second_record_is_its_own() -> None:
    """Stages reused for another record (a dataset worker's) start the sums again: the second
    record's mean is its own, not the mean of both."""

    def config(start: float) -> Any:
        return validate_run_config(
            {
                "motion": {
                    "kind": "point_targets",
                    "length": 1.0,
                    "targets": MP_TARGET,
                    "start": start,
                    "duration": 0.5,
                },
                "scatterers": {"kind": "points"},
                "radar": {"kind": "lfm", "precision": "float64"},
                "scene": {"radar_position": list(MP_RADAR)},
                "effects": [{"kind": "multipath"}],
            }
        )

    stages = build_stages(config(0.0))
    motion = load_motion(stages.source)
    first = simulate_motion(config(0.0), stages, motion).metadata["effects"][0]
    second = simulate_motion(config(0.5), stages, motion).metadata["effects"][0]
    alone = simulate(config(0.5)).metadata["effects"][0]
    assert second["extra_path_m"] == alone["extra_path_m"]
    assert alone["extra_path_m"]["bounce_mean"] > first["extra_path_m"]["bounce_mean"] + 0.5


def test_multipath_image_at_right_doppler() -> None:
    """Vertical motion under a raised radar: the direct echo approaches (positive Doppler), the
    image recedes (negative), the bounce path sits at their mean."""
    res = run(
        MP_TARGET,
        [{"kind": "multipath"}],
        radar_position=MP_RADAR,
        duration=0.5,
        processing={"nfft": 4096, "hop": 32},
    )
    spec = res.spectrogram
    m = len(spec.time) // 2
    t_mid = spec.time[m]
    _, _, rd_dot, rb_dot = mp_geometry(t_mid)
    expected = {
        "direct": -2 * rd_dot / LAM,
        "bounce": -(rd_dot + rb_dot) / LAM,
        "image": -2 * rb_dot / LAM,
    }
    assert expected["direct"] > 40 and expected["image"] < -80
    col = spec.power[:, m]
    for name, f0 in expected.items():
        window = np.abs(spec.doppler - f0) < 15.0
        f_peak = spec.doppler[window][np.argmax(col[window])]
        assert f_peak == pytest.approx(f0, abs=3.0), name
        # a true local maximum of the column, not a sidelobe slope
        assert col[window].max() > 10 * np.median(col)


def test_multipath_reflection_phase_is_exact() -> None:
    """The virtual scatterers carry Gamma's phase as a sub-wavelength range offset."""
    base = run(
        MP_TARGET,
        [
            {
                "kind": "multipath",
                "paths": "image",
                "reflection_magnitude": 1.0,
                "reflection_phase_deg": 0.0,
            }
        ],
        radar_position=MP_RADAR,
        duration=0.2,
        processing={"window_length": 128},
    )
    flip = run(
        MP_TARGET,
        [
            {
                "kind": "multipath",
                "paths": "image",
                "reflection_magnitude": 1.0,
                "reflection_phase_deg": 90.0,
            }
        ],
        radar_position=MP_RADAR,
        duration=0.2,
        processing={"window_length": 128},
    )
    names = base.scatterers.names
    assert names == ("target0", "target0~image")
    lam = LAM
    r0 = base.scatterers.ranges(np.array(MP_RADAR))[:, 1]
    r1 = flip.scatterers.ranges(np.array(MP_RADAR))[:, 1]
    # Gamma^2 = exp(j pi): phase pi -> offset lambda/4 either way
    ph = radar.carrier_phasor(r1, 15e9) / radar.carrier_phasor(r0, 15e9)
    assert np.allclose(ph, -1.0, atol=1e-9)
    assert np.max(np.abs(r1 - r0)) <= lam / 4 + 1e-12


# --------------------------------------------------------------------------- antenna


@pytest.mark.parametrize("pattern", ["gaussian", "uniform"])
@pytest.mark.parametrize("bw_deg", [5.0, 20.0, 60.0])
def test_antenna_gain_is_minus_3db_at_beamwidth_edge(pattern: str, bw_deg: float) -> None:
    bw = np.deg2rad(bw_deg)
    bore = np.array([1.0, 0.0, 0.0])
    edge = bw / 2
    az_edge = np.array([np.cos(edge), np.sin(edge), 0.0])
    el_edge = np.array([np.cos(edge), 0.0, np.sin(edge)])
    for d in (az_edge, el_edge):
        g = one_way_gain(d, bore, pattern=pattern, beamwidth_az=bw, beamwidth_el=bw)
        assert 10 * np.log10(g) == pytest.approx(10 * np.log10(0.5), abs=1e-9)
    inside = one_way_gain(
        np.array([1.0, 0.01, 0.0]), bore, pattern=pattern, beamwidth_az=bw, beamwidth_el=bw
    )
    assert 0.5 < inside < 1.0
    assert one_way_gain(bore, bore, pattern=pattern, beamwidth_az=bw, beamwidth_el=bw) == 1.0
    assert one_way_gain(-bore, bore, pattern=pattern, beamwidth_az=bw, beamwidth_el=bw) == 0.0


def test_sinc2_half_power_constant_is_the_root() -> None:
    """The written-out half-power point is the root of sinc(x)^2 = 1/2 in (0, 1)."""
    from scipy.optimize import brentq

    root = brentq(lambda x: np.sinc(x) ** 2 - 0.5, 0.1, 0.9, xtol=1e-15)
    assert SINC2_HALF_POWER == pytest.approx(root, abs=2e-15)
    assert np.sinc(SINC2_HALF_POWER) ** 2 == pytest.approx(0.5, abs=1e-15)


def test_uniform_aperture_first_sidelobe_and_null() -> None:
    bw = np.deg2rad(10.0)
    d_over_lam = SINC2_HALF_POWER / np.sin(bw / 2)
    null = np.arcsin(1.0 / d_over_lam)
    g = one_way_gain(
        np.array([np.cos(null), np.sin(null), 0.0]),
        np.array([1.0, 0, 0]),
        pattern="uniform",
        beamwidth_az=bw,
        beamwidth_el=bw,
    )
    assert g < 1e-20
    th = np.linspace(null, 2 * null, 2001)
    d = np.stack([np.cos(th), np.sin(th), 0 * th], axis=1)
    side = one_way_gain(
        d, np.array([1.0, 0, 0]), pattern="uniform", beamwidth_az=bw, beamwidth_el=bw
    ).max()
    assert 10 * np.log10(side) == pytest.approx(-13.26, abs=0.05)


@pytest.mark.parametrize("pattern", ["gaussian", "uniform"])
def test_antenna_two_way_gain_end_to_end(pattern: str) -> None:
    """A target at the beam edge returns 6 dB less power (one way -3 dB, twice)."""
    bw = 16.0
    edge = np.deg2rad(bw / 2)
    r = 30.0
    target = [{"position": [r * np.cos(edge), r * np.sin(edge), 0.0], "rcs": 1.0}]
    ant = {
        "kind": "antenna",
        "pattern": pattern,
        "beamwidth_az_deg": bw,
        "pointing": "angles",
        "azimuth_deg": 0.0,
        "elevation_deg": 0.0,
    }
    plain = run(target, [], duration=0.2, processing={"window_length": 128})
    weighted = run(target, [ant], duration=0.2, processing={"window_length": 128})
    ratio = np.abs(weighted.received.signal) ** 2 / np.abs(plain.received.signal) ** 2
    assert np.allclose(10 * np.log10(ratio), 20 * np.log10(0.5), atol=1e-9)


def test_antenna_pointing_at_target_tracks_it() -> None:
    """Pointing at the target: boresight gain (no change); steering 'track' keeps a crossing
    target on boresight, a fixed beam does not."""
    crossing = [{"position": [30.0, -8.0, 0.0], "velocity": [0.0, 8.0, 0.0], "rcs": 1.0}]
    plain = run(crossing, [], duration=2.0)
    ant = {"kind": "antenna", "beamwidth_az_deg": 10.0}
    tracked = run(crossing, [{**ant, "steering": "track"}], duration=2.0)
    fixed = run(crossing, [ant], duration=2.0)
    assert np.allclose(np.abs(tracked.received.signal), np.abs(plain.received.signal), rtol=1e-9)
    edge = np.abs(fixed.received.signal[[0, -1]]) / np.abs(plain.received.signal[[0, -1]])
    assert np.all(edge < 0.5)  # ~15 degrees off a 10-degree beam at both ends


def test_antenna_after_multipath_weighs_each_path_by_its_own_directions() -> None:
    """A beam aimed horizontally at a target level with the radar, 3 m away, 1 m above the
    ground: the ground-bounce paths leave the radar 33.7 deg below boresight. The image gets
    the two-way gain of that direction, the single bounce one way direct and one way down."""
    bw, gamma = 20.0, 0.6
    eff = [
        {"kind": "multipath", "reflection_magnitude": gamma, "reflection_phase_deg": 0.0},
        {
            "kind": "antenna",
            "beamwidth_az_deg": bw,
            "pointing": "angles",
            "azimuth_deg": 0.0,
            "elevation_deg": 0.0,
        },
    ]
    res = run([{"position": [3.0, 0.0, 1.0], "rcs": 1.0}], eff, radar_position=(0.0, 0.0, 1.0))
    rcs = dict(zip(res.scatterers.names, res.scatterers.rcs[0], strict=True))
    r_d, r_b = 3.0, np.hypot(3.0, 2.0)
    g_b = np.exp(-4 * np.log(2) * (np.degrees(np.arctan2(2.0, 3.0)) / bw) ** 2)  # one way
    assert 10 * np.log10(g_b) == pytest.approx(-34.17, abs=0.01)
    from conftest import ROOT

    page = " ".join((ROOT / "docs" / "effects.md").read_text().split())
    below, two_way = np.degrees(np.arctan2(2.0, 3.0)), -20 * np.log10(g_b)
    assert f"the image lies {below:.1f} deg below boresight" in page
    assert f"with a {bw:g} deg Gaussian beam its two-way gain is {two_way:.1f} dB down" in page
    assert rcs["target0"] == pytest.approx(1.0, rel=1e-12)
    assert rcs["target0~image"] == pytest.approx(gamma**4 * g_b**2, rel=1e-9)
    r_m = (r_d + r_b) / 2  # a 0 deg reflection phase: no range offset
    bounce = 4 * gamma**2 * g_b * r_m**4 / (r_d**2 * r_b**2)
    assert rcs["target0~bounce"] == pytest.approx(bounce, rel=1e-9)


def test_antenna_before_multipath_or_static_scene_is_refused() -> None:
    """Listed first, the pattern would give the bounced paths the direct path's gain, and the
    room's reflectors none."""
    from mdframework import SceneError

    eff = [{"kind": "antenna"}, {"kind": "noise"}, {"kind": "multipath"}]
    with pytest.raises(
        SceneError,
        match=r"^effects: antenna \(effects\[0\]\) .* multipath "
        r"\(effects\[2\]\).*list antenna after multipath$",
    ):
        run(APPROACHING, eff, radar_position=(0.0, 0.0, 1.0))
    assert run(APPROACHING, eff[::-1], radar_position=(0.0, 0.0, 1.0)).metadata["effects"]
    room = {"kind": "static_scene", "reflectors": [{"position": [5.0, 5.0, 0.0], "rcs_m2": 1.0}]}
    with pytest.raises(SceneError, match=r"^effects: antenna .* static_scene \(effects\[1\]\)"):
        run(APPROACHING, [{"kind": "antenna"}, room])
    # the room's reflector 45 deg off a 20 deg beam aimed at the target: -61 dB one way
    weighed = run(APPROACHING, [room, {"kind": "antenna"}], duration=0.2)
    g = np.exp(-4 * np.log(2) * (45.0 / 20.0) ** 2)
    assert weighed.scatterers.rcs[0, 1] == pytest.approx(g**2, rel=1e-9, abs=0)


# --------------------------------------------------------------------------- attenuation


def test_attenuation_grows_with_range_as_specified() -> None:
    target = [{"position": [500.0, 0.0, 0.0], "velocity": [4.0, 0.0, 0.0], "rcs": 1.0}]
    k, alpha, rain = 0.04, 1.1, 25.0
    eff = {
        "kind": "attenuation",
        "gas_db_per_km": 0.05,
        "rain_rate_mm_per_h": rain,
        "rain_k": k,
        "rain_alpha": alpha,
    }
    plain = run(target, [], duration=2.0)
    att = run(target, [eff], duration=2.0)
    gamma = 0.05 + k * rain**alpha  # one way, dB/km
    rng = plain.gate_range
    loss_db = 10 * np.log10(np.abs(att.received.signal) ** 2 / np.abs(plain.received.signal) ** 2)
    assert np.allclose(loss_db, -2 * gamma * rng / 1000, atol=1e-9)
    # linear in range: the slope is the two-way specific attenuation
    slope = np.polyfit(rng, loss_db, 1)[0] * 1000
    assert slope == pytest.approx(-2 * gamma, rel=1e-9)
    assert att.metadata["effects"][0]["specific_attenuation_db_per_km"] == pytest.approx(gamma)


def test_attenuation_takes_each_added_path_over_its_own_length() -> None:
    """After multipath, the double-bounce image loses ``2 gamma R_b`` (its own round trip), and
    a static reflector its own range's loss; listed before them, either would keep the direct
    path's loss (or none): that order is refused."""
    from mdframework import SceneError

    gamma = 100.0  # dB/km one way
    att = {"kind": "attenuation", "gas_db_per_km": gamma}
    image = {"kind": "multipath", "reflection_magnitude": 1.0, "reflection_phase_deg": 0.0}
    room = {"kind": "static_scene", "reflectors": [{"position": [0.0, 20.0, 1.0], "rcs_m2": 1.0}]}
    target = [{"position": [10.0, 0.0, 1.5], "velocity": [0.0, 0.0, 0.0], "rcs": 1.0}]
    radar_at = (0.0, 0.0, 1.0)
    res = run(target, [{**image, "paths": "image"}, room, att], radar_position=radar_at)
    r_b = float(np.hypot(10.0, 2.5))  # radar (z = 1) to the image (z = -1.5)
    assert res.scatterers.names[1:] == ("target0~image", "static0")
    assert res.scatterers.rcs[0, 1] == pytest.approx(10 ** (-2 * gamma * r_b / 1e4), rel=1e-9)
    assert res.scatterers.rcs[0, 2] == pytest.approx(10 ** (-2 * gamma * 20.0 / 1e4), rel=1e-9)
    for first in (image, room):
        with pytest.raises(
            SceneError,
            match=rf"^effects: attenuation \(effects\[0\]\) is listed before {first['kind']} "
            rf"\(effects\[1\]\), .*: list attenuation after {first['kind']}$",
        ):
            run(target, [att, first], radar_position=radar_at)


def test_attenuation_rain_needs_coefficients() -> None:
    with pytest.raises(Exception, match="rain_k"):
        run(APPROACHING, [{"kind": "attenuation", "rain_rate_mm_per_h": 5.0}])


# --------------------------------------------------------------------------- on demand


def _explode(*args: Any, **kwargs: Any) -> None:
    raise AssertionError("an effect the scene does not call for did work")


def test_effects_not_called_for_are_never_constructed_or_run(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    assert {"noise", "clutter", "multipath", "antenna", "attenuation", "shadowing"} <= {
        cls.name for cls in ALL_EFFECTS
    }
    for cls in ALL_EFFECTS:
        for method in EFFECT_METHODS:
            monkeypatch.setattr(cls, method, _explode)
    res = run(APPROACHING, [])
    assert res.metadata["effects"] == []
    cfg = {"motion": {"kind": "boulic", "duration": 1.0}, "scatterers": {"kind": "ellipsoid"}}
    assert simulate(validate_run_config(cfg)).metadata["effects"] == []


def test_only_the_named_effect_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    for cls in ALL_EFFECTS:
        if cls is not ReceiverNoise:
            for method in EFFECT_METHODS:
                monkeypatch.setattr(cls, method, _explode)
    res = run(APPROACHING, [{"kind": "noise"}])
    assert [e["kind"] for e in res.metadata["effects"]] == ["noise"]


def test_metadata_records_effects_in_stage_order() -> None:
    effects = [
        {"kind": "noise", "snr_db": 30.0},
        {"kind": "multipath", "ground_height": -1.0},
        {"kind": "clutter"},
        {"kind": "attenuation", "gas_db_per_km": 0.1},
        {"kind": "antenna", "beamwidth_az_deg": 30.0},
    ]
    res = run(APPROACHING, effects)
    ran = [(e["kind"], e["stage"]) for e in res.metadata["effects"]]
    assert ran == [
        ("multipath", "scatterers"),
        ("attenuation", "scatterers"),
        ("antenna", "scatterers"),
        ("noise", "received"),
        ("clutter", "received"),
    ]
    assert res.scatterers.names == ("target0", "target0~image", "target0~bounce")
    assert np.all(np.isfinite(res.spectrogram_db))


def test_multipath_over_a_raised_ground_mirrors_in_that_plane() -> None:
    """Ground plane at z = 0.5 m, Gamma real (phase 0, so no range offset): the image scatterer
    lies at the range of the target mirrored in z = 0.5, R_b = hypot(10, (5 - 0.5) + (z - 0.5)),
    and the single-bounce one at (R_d + R_b) / 2, to 1e-9 m at every pulse (the default ground
    at z = 0 cannot tell 2h - z from h - z)."""
    res = run(
        MP_TARGET,
        [{"kind": "multipath", "ground_height": 0.5, "reflection_phase_deg": 0.0}],
        radar_position=MP_RADAR,
        duration=0.2,
    )
    names = res.scatterers.names
    ranges = res.scatterers.ranges(np.array(MP_RADAR))
    z = 1.0 + 2.0 * res.pulse_times
    rd, rb = np.hypot(10.0, 5.0 - z), np.hypot(10.0, (5.0 - 0.5) + (z - 0.5))
    np.testing.assert_allclose(ranges[:, names.index("target0")], rd, rtol=0, atol=1e-9)
    np.testing.assert_allclose(ranges[:, names.index("target0~image")], rb, rtol=0, atol=1e-9)
    np.testing.assert_allclose(ranges[:, names.index("target0~bounce")], (rd + rb) / 2, atol=1e-9)
