"""Scene effects on the FMCW radar's IF samples: the ``clutter`` and ``noise`` effects reach its
range-Doppler maps, its points and its spectrogram alike (docs/fmcw.md, docs/effects.md)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from mdf_fmcw.waveform import FmcwConfig, FmcwRadar

from mdframework.config import validate_run_config
from mdframework.constants import SPEED_OF_LIGHT as C
from mdframework.errors import SceneError
from mdframework.physics import fmcw, radar
from mdframework.pipeline import simulate

#: the IWR1443 preset along +x, without the receiver's own noise
RADAR = {
    "kind": "fmcw",
    "preset": "iwr1443_short_range_3d",
    "boresight_azimuth_deg": 0.0,
    "receiver_noise": False,
}
#: a target too faint to matter (1e-12 m^2), 3 m away, approaching at 1 m/s
FAINT = [{"position": [3.0, 0.0, 0.0], "velocity": [-1.0, 0.0, 0.0], "rcs": 1e-12}]
#: one clutter patch of 0.2 m^2 per range cell (before its Rayleigh draw), somewhere in
#: 5.0-5.5 m: the gate fixed at 5 m, no margin, patches 0.5 m apart
CLUTTER = {
    "kind": "clutter",
    "power": "rcs",
    "rcs_m2": 0.2,
    "wind_fraction": 0.0,
    "patch_spacing_m": 0.5,
    "margin_m": 0.0,
}


def run(
    radar_: dict[str, Any],
    effects: list[dict[str, Any]],
    *,
    length: float = 0.2,
    seed: int = 0,
    processing: dict[str, Any] | None = None,
) -> Any:
    """A faint point target seen by ``radar_`` at the origin, the gate fixed at 5 m."""
    cfg = {
        "motion": {"kind": "point_targets", "length": length, "targets": FAINT},
        "scatterers": {"kind": "points"},
        "radar": radar_,
        "scene": {"radar_position": [0.0, 0.0, 0.0], "gate": 5.0},
        "effects": effects,
        "processing": processing or {},
        "seed": seed,
    }
    return simulate(validate_run_config(cfg))


@pytest.mark.parametrize("path", ["analytic", "raw"])
def test_a_clutter_patch_is_in_the_maps_at_its_range_bin_and_zero_doppler(path: str) -> None:
    """A static clutter patch (power 'rcs', no wind) goes into the IF samples: its peak is in
    the range bin of its range, in the zero-Doppler row, at the power the range equation gives
    through the range window's response at its offset from the bin (to 0.1 %), summed over the
    12 virtual antennas; the CFAR turns it into points there at 0 m/s; the spectrogram's
    slow-time signal carries the same patch at its amplitude, constant over the frame's loops
    (zero Doppler); clutter_removal removes it from the maps and the points. Both paths."""
    fields = {**RADAR, "clutter_removal": False, "path": path}
    res = run(fields, [CLUTTER])
    clean = run(fields, [])
    [effect] = res.metadata["effects"]
    lo, hi = effect["patch_range_m"]
    assert effect["n_patches"] == 1 and lo == hi and 5.0 <= lo < 5.5
    r, rcs = lo, effect["clutter_rcs_m2"]
    wf = FmcwRadar(FmcwConfig(**fields))
    seq = wf.sequence
    amp = float(wf.config.amplitudes(np.array([rcs]), np.array([r]), seq.wavelength)[0])
    rd = res.received.products["range_doppler"]  # (n_frames, 16, 240) [W]
    n_dop, n_rng = rd.shape[1:]
    zero = (n_dop - 1) // 2
    assert res.received.products["range_doppler_velocity_mps"][zero] == 0.0
    k = round(2 * seq.slope * r / C / seq.sample_rate * n_rng)
    for frame in rd:
        peak = np.unravel_index(np.argmax(frame), frame.shape)
        assert peak == (zero, k)
    # the range window's response at the patch's offset from bin k (stop-and-hop delay 2 r / c)
    w = fmcw.window("hann", seq.n_samples)
    nu = k / n_rng - 2 * seq.slope * r / C / seq.sample_rate
    gain = abs(np.sum(w * np.exp(2j * np.pi * nu * np.arange(seq.n_samples)))) / np.sum(w)
    expected = 12 * amp**2 * gain**2
    assert rd[:, zero, k] == pytest.approx(expected, rel=1e-3, abs=0)
    assert amp**2 == pytest.approx(
        radar.scatterer_amplitudes(
            np.array([rcs]),
            np.array([r]),
            model="range_equation",
            wavelength=seq.wavelength,
            transmit_power=wf.config.transmit_power,
        )[0]
        ** 2,
        abs=0,
    )
    # points at the patch's range at 0 m/s (clutter removal off, as the preset has it)
    pts = res.received.products["points"]
    near = np.abs(np.linalg.norm(pts[:, 2:5], axis=1) - r) < 2 * seq.range_resolution
    assert near.any() and np.all(pts[near, 5] == 0.0)
    # and nothing else: without noise in the IF the CFAR floor is the receiver's mean noise,
    # above the patch's window sidelobes
    assert near.all()
    assert np.all(pts[near, 3] > 0.95 * r)  # on the boresight (sensor y), as the patch is
    assert not (
        np.abs(np.linalg.norm(clean.received.products["points"][:, 2:5], axis=1) - r) < 0.1
    ).any()
    # the spectrogram's signal: the patch at its amplitude (gate 5 m, 2 m wide), the same in
    # every loop of a TDM slot
    diff = res.received.signal - clean.received.signal
    slot0 = diff[:: seq.n_tx]
    assert np.abs(slot0) == pytest.approx(amp, rel=1e-2, abs=0)
    assert np.ptp(slot0.real) < 1e-6 * amp and np.ptp(slot0.imag) < 1e-6 * amp
    # clutter removal: the static patch is gone from the maps and the points
    removed = run({**fields, "clutter_removal": True}, [CLUTTER])
    assert removed.received.products["range_doppler"][:, :, k].max() < 1e-9 * expected
    pts = removed.received.products["points"]
    assert not (np.abs(np.linalg.norm(pts[:, 2:5], axis=1) - r) < 2 * seq.range_resolution).any()


def test_the_noise_effect_fills_the_map_cells_with_the_analytic_mean_noise() -> None:
    """The noise effect (mode 'thermal') goes into the IF samples: k T F fs per complex sample
    (10 dB, 290 K), so each map cell holds on average 12 x that x the range and Doppler window
    gains (sum w^2 / (sum w)^2), to 2 % over 30 frames; the slow-time signal carries noise of
    the same draws (it differs from the noise-free run's); a record cut in small blocks gives
    the same maps, points and signal; the seed sets the draws."""
    noise = {"kind": "noise", "mode": "thermal", "noise_figure_db": 10.0}
    res = run(RADAR, [noise], length=1.0)
    rd = res.received.products["range_doppler"]
    wf = FmcwRadar(FmcwConfig(**RADAR))
    sigma2 = 1.380649e-23 * 290.0 * 10.0 * wf.config.sample_rate
    assert res.metadata["effects"][0]["noise_power_w"] == pytest.approx(sigma2, rel=1e-12, abs=0)
    assert res.metadata["effects"][0]["in_receiver"] is True
    expected = fmcw.map_noise_power(sigma2, 12, "hann", 240, "hann", 16)
    assert rd.shape[0] == 30
    assert float(np.mean(rd)) == pytest.approx(expected, rel=0.02, abs=0)
    clean = run(RADAR, [], length=1.0)
    gated = np.mean(np.abs(res.received.signal - clean.received.signal) ** 2)
    assert gated > 0.1 * sigma2
    blocks = run(RADAR, [noise], length=1.0, processing={"block_pulses": 48})
    assert np.array_equal(blocks.received.products["range_doppler"], rd)
    assert np.array_equal(blocks.received.products["points"], res.received.products["points"])
    assert np.array_equal(blocks.received.signal, res.received.signal)
    other = run(RADAR, [noise], length=1.0, seed=1)
    assert not np.array_equal(other.received.products["range_doppler"], rd)


def test_cfar_false_points_on_noise_alone_match_the_threshold() -> None:
    """Noise alone (the noise effect in the IF, rectangular range window so that range cells
    are independent): the power summed over 12 virtual antennas is Gamma(12)-distributed, so a
    cell-averaging CFAR over N = 16 training cells at threshold t (2 dB) passes a cell with
    probability P(X > t S / N), X ~ Gamma(12), S ~ Gamma(12 N): the Beta(12, 12 N) tail at
    c / (1 + c), c = t / N (4.09 %). The points on the range bins with all their training
    cells, over 30 frames, come to that rate within 5 %."""
    from scipy.stats import beta

    fields = {
        **RADAR,
        "range_window": "rect",
        "peak_grouping": [],
        "multi_object_threshold": None,
        "cfar_range": {"mode": "ca", "train": 8, "guard": 2, "threshold_db": 2.0},
    }
    noise = {"kind": "noise", "mode": "thermal", "noise_figure_db": 10.0}
    res = run(fields, [noise], length=1.0)
    pts = res.received.products["points"]
    n_frames, n_dop, n_rng = res.received.products["range_doppler"].shape
    bins = np.rint(
        np.linalg.norm(pts[:, 2:5], axis=1)
        / FmcwRadar(FmcwConfig(**fields)).sequence.range_resolution
    )
    interior = (bins >= 10) & (bins < n_rng - 10)
    c = 10**0.2 / 16
    p_fa = beta.sf(c / (1 + c), 12, 12 * 16)
    assert p_fa == pytest.approx(0.0409, abs=5e-4)
    rate = interior.sum() / (n_frames * n_dop * (n_rng - 20))
    assert rate == pytest.approx(p_fa, rel=0.05)


@pytest.mark.parametrize(
    ("effect", "field"),
    [
        ({"kind": "noise", "snr_db": 20.0}, "effects.noise.mode"),
        ({**CLUTTER, "power": "csr"}, "effects.clutter.power"),
        ({**CLUTTER, "wind_fraction": 0.3}, "effects.clutter.wind_fraction"),
    ],
)
def test_effects_that_cannot_reach_the_maps_are_refused(effect: dict[str, Any], field: str) -> None:
    """A noise level or a clutter power set from the record's mean echo, and wind-blown clutter,
    cannot go into the IF samples the maps are made from: one error naming the field. Without
    maps and points the effect acts on the spectrogram's signal as with every radar."""
    with pytest.raises(SceneError, match=rf"^{field}: "):
        run(RADAR, [effect])
    alone = {**RADAR, "points": False, "save_range_doppler": False}
    assert not np.array_equal(run(alone, [effect]).received.signal, run(alone, []).received.signal)


def test_the_fmcw_page_quotes_these_tests() -> None:
    """docs/fmcw.md's section on effects in the IF samples quotes the analytic false-point
    rate and the tolerances the tests above hold (0.1 % for a patch's peak, 2 % for the noise
    per cell over 30 frames, 5 % for the CFAR rate)."""
    from pathlib import Path

    from scipy.stats import beta

    page = " ".join((Path(__file__).parents[1] / "docs" / "fmcw.md").read_text().split())
    c = 10**0.2 / 16
    assert f"{100 * beta.sf(c / (1 + c), 12, 12 * 16):.2f} % at 2 dB" in page
    assert "(measured to 2 % over 30 frames)" in page
    assert "that rate within 5 %" in page
    assert "to 0.1 %), gives points there at 0 m/s" in page


def test_two_noise_effects_add_up_in_the_maps() -> None:
    """Two noise effects (10 and 13 dB) are independent draws added in the IF samples: the
    map cells hold on average the sum of their powers (to 3 % over 15 frames), not the last
    one's."""
    effects = [{"kind": "noise", "mode": "thermal", "noise_figure_db": nf} for nf in (10, 13)]
    res = run(RADAR, effects, length=0.5)
    both = sum(e["noise_power_w"] for e in res.metadata["effects"])
    expected = fmcw.map_noise_power(both, 12, "hann", 240, "hann", 16)
    rd = res.received.products["range_doppler"]
    assert float(np.mean(rd)) == pytest.approx(expected, rel=0.03, abs=0)


def test_the_clutter_patches_rcs_have_a_rayleigh_amplitude_of_unit_mean_power() -> None:
    """The static patches the clutter effect hands the radar: RCS rcs_m2 (spacing /
    resolution) |alpha|^2, |alpha|^2 exponential of mean 1: over 4000 patches 0.1 m apart
    (resolution 0.2 m, rcs_m2 = 2) the mean RCS is 1 m^2 to 5 %, and 1 - 1/e of them lie
    below it (to 0.03)."""
    from types import SimpleNamespace

    from mdf_clutter.clutter import GroundClutter

    config = {**CLUTTER, "rcs_m2": 2.0, "patch_spacing_m": 0.1, "range_resolution": 0.2}
    effect = GroundClutter(GroundClutter.Config(**{**config, "margin_m": 200.0}))
    context: Any = SimpleNamespace(
        gate_range=np.array([300.0]),
        rng=np.random.default_rng(0),
        waveform=SimpleNamespace(max_static_range=None),
    )
    got = effect.receiver_input(context)
    assert got is not None and got.static_rcs.size == 4000
    assert float(np.mean(got.static_rcs)) == pytest.approx(1.0, rel=0.05)
    assert float(np.mean(got.static_rcs < 1.0)) == pytest.approx(1 - np.exp(-1), abs=0.03)


def test_the_clutter_patches_in_the_if_samples_are_attenuated_as_the_target() -> None:
    """With ``attenuation`` in the scene the static patches handed to the IF samples carry
    the two-way loss of their own ranges, as the slow-time clutter of the other radars does:
    the summed RCS of the patches (the same draws) drops by that factor, patch by patch."""
    gamma = 300.0  # dB/km one way
    att = {"kind": "attenuation", "gas_db_per_km": gamma}
    plain = run(RADAR, [CLUTTER], length=0.05).metadata["effects"][0]
    lossy = run(RADAR, [CLUTTER, att], length=0.05).metadata["effects"]
    got = next(e for e in lossy if e["kind"] == "clutter")
    assert got["n_patches"] == plain["n_patches"] == 1
    r = got["patch_range_m"][0]
    assert got["clutter_rcs_m2"] == pytest.approx(
        plain["clutter_rcs_m2"] * 10 ** (-2 * gamma * r / 1e4), rel=1e-9
    )


@pytest.mark.parametrize("beyond", [0.0, 1.0])
def test_static_scatterers_beyond_the_maximum_range_are_left_out_unless_aliased(
    beyond: float,
) -> None:
    """A receiver input's static scatterer at the maximum range, or 1 m beyond it, adds
    nothing to the range profiles (as a moving one there is refused), unless
    beyond_max_range = "alias", when it folds back into them."""
    from mdframework import ReceiverInput

    profiles = {}
    for mode in ("error", "alias"):
        wf = FmcwRadar(FmcwConfig(**RADAR, beyond_max_range=mode))
        far = np.array([wf.sequence.max_range + beyond])
        wf.set_receiver_inputs([ReceiverInput("far", static_ranges=far, static_rcs=np.ones(1))])
        origin = np.zeros(3)
        profiles[mode] = wf._static_profiles(origin, wf.sensor_axes(origin))
    assert profiles["error"] is None
    assert profiles["alias"] is not None and np.abs(profiles["alias"]).max() > 0


def test_the_clutter_metadata_counts_only_the_patches_within_the_maximum_range() -> None:
    """Clutter patches at or beyond the maximum range are left out of the IF samples, so the
    effect's metadata counts the patches simulated (``n_patches``, their ``patch_range_m`` and
    ``clutter_rcs_m2`` all below the maximum range) and those left out apart
    (``n_patches_beyond_max_range``); with beyond_max_range = "alias" every patch is simulated,
    from the same draws (the run's seed), so the counts and RCS add up to its own."""
    max_range = FmcwRadar(FmcwConfig(**RADAR)).sequence.max_range
    far = {**CLUTTER, "margin_m": max_range}  # patches from 0.5 m to 5 m + max_range
    effects = {}
    for mode in ("error", "alias"):
        res = run({**RADAR, "beyond_max_range": mode}, [far], length=0.05)
        [effects[mode]] = res.metadata["effects"]
    kept, every = effects["error"], effects["alias"]
    assert every["n_patches_beyond_max_range"] == 0
    n_all = every["n_patches"]  # 0.5 m apart from 0.5 m to 5 m + max_range
    assert n_all == int(np.ceil((5.0 + max_range - 0.5) / 0.5))
    assert every["patch_range_m"][1] > max_range
    assert 0 < kept["n_patches_beyond_max_range"] < n_all
    assert kept["n_patches"] + kept["n_patches_beyond_max_range"] == n_all
    # patch k lies in [0.5 (k + 1), 0.5 (k + 2)) m: those below max_range are kept
    assert int(np.ceil(max_range / 0.5)) - 2 <= kept["n_patches"] <= int(max_range / 0.5)
    assert kept["patch_range_m"][0] == every["patch_range_m"][0]
    assert kept["patch_range_m"][1] < max_range
    assert 0 < kept["clutter_rcs_m2"] < every["clutter_rcs_m2"]
