"""Empty results: the pure check on named hard cases, and real runs that warn or stop."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mdframework import cli
from mdframework.emptiness import LOST_GAIN, MIN_POWER_W, Losses, count_losses, empty_result
from mdframework.settings import ProcessingConfig

POINT = """
[motion]
kind = "point_targets"
length = 1.0
targets = [{{ position = [{x}, 0.0, 0.0], velocity = [1.0, 0.0, 0.0], rcs = 1.0 }}]
[scatterers]
kind = "points"
[scene]
radar_position = [0.0, 0.0, 0.0]
gate = {gate}
[processing]
empty = "{empty}"
"""


def losses(total: int, gated: int, cut: int = 0) -> Losses:
    return Losses(total, gated, cut, (8.0, 10.0), (30.0, 30.0))


def test_count_losses_by_hand() -> None:
    ranges = np.array([[10.0, 11.0, 12.0], [10.0, 11.0, 12.0]])
    gain = np.array([[1.0, LOST_GAIN, 0.5], [0.0, 0.2, 1.0]])  # at the limit counts as lost
    rcs_model = np.array([[1.0, 1.0, 1.0], [1.0, 1.0, 2.0]])
    rcs = np.array([[1.0, 0.0, 0.01], [1.0, 0.5, 0.019]])  # 0.01 of 1: cut; 0.019 of 2: cut
    got = count_losses(ranges, np.array([10.0, 10.5]), rcs_model, rcs, gain)
    # gated: (0,1), (1,0); cut and not gated: (0,2), (1,2)
    assert (got.total, got.gated, got.cut) == (6, 2, 2)
    assert got.range_m == (10.0, 12.0) and got.gate_m == (10.0, 10.5)
    # without a gate model nothing is gated; without a comparable model RCS nothing is cut
    assert count_losses(ranges, np.array([10.0, 10.5]), None, rcs, None).gated == 0
    assert count_losses(ranges, np.array([10.0, 10.5]), rcs_model[:, :2], rcs, None).cut == 0
    # blocks add up
    both = got + got
    assert (both.total, both.gated, both.cut) == (12, 4, 4)


def test_all_zeros_names_the_fixed_gate() -> None:
    why = empty_result(np.zeros(8, complex), losses(16, 16), max_lost_fraction=0.5, fixed_gate=True)
    assert why is not None and "all zeros" in why
    assert "fixed range gate at 30 m" in why and "8-10 m" in why and "scene.gate" in why


def test_all_zeros_from_effects_and_from_underflow() -> None:
    zeros = np.zeros(8, complex)
    why = empty_result(zeros, losses(16, 4, 12), max_lost_fraction=0.5, fixed_gate=False)
    assert why is not None and "scene effects" in why
    why = empty_result(zeros, losses(16, 0, 0), max_lost_fraction=0.5, fixed_gate=False)
    assert why is not None and "underflow" in why


def test_no_power_is_an_underflowed_echo() -> None:
    tiny = np.full(8, 1e-160 + 0j)  # |y|^2 = 1e-320: a subnormal power
    assert 0 < np.abs(tiny[0]) ** 2 < MIN_POWER_W
    why = empty_result(tiny, losses(16, 0), max_lost_fraction=0.5, fixed_gate=False)
    assert why is not None and "no power in the record" in why
    weak = np.full(8, 1e-150 + 0j)  # 1e-300 W: small but representable, not empty
    assert empty_result(weak, losses(16, 0), max_lost_fraction=0.5, fixed_gate=False) is None


@pytest.mark.parametrize(
    ("gated", "cut", "limit", "empty"),
    [(9, 0, 0.5, True), (8, 0, 0.5, False), (5, 4, 0.5, True), (1, 2, 0.2, False)],
)
def test_lost_fraction_threshold(gated: int, cut: int, limit: float, empty: bool) -> None:
    # 16 returns: more than the limit lost (strictly) is empty; 1 + 2 = 3/16 = 0.19 <= 0.2
    why = empty_result(np.ones(4, complex), losses(16, gated, cut), max_lost_fraction=limit,
                       fixed_gate=True)  # fmt: skip
    assert (why is not None) == empty
    if why is not None:
        assert "max_lost_fraction" in why
        assert ("range gate" in why) == (gated >= cut) and ("scene effects" in why) == (cut > gated)


def run(tmp_path: Path, text: str, capsys: pytest.CaptureFixture[str]) -> tuple[int, str, Path]:
    cfg = tmp_path / "c.toml"
    cfg.write_text(text)
    out = tmp_path / "out"
    code = cli.main(["run", str(cfg), "--out", str(out)])
    return code, capsys.readouterr().err, out


def test_target_outside_a_fixed_gate_warns(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, err, out = run(tmp_path, POINT.format(x=100.0, gate=30.0, empty="warn"), capsys)
    assert code == 0 and (out / "result.npz").exists()
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("mdf: warning: nearly empty result: 100 %")
    assert "fixed range gate at 30 m" in lines[0] and "scene.gate = 'track'" in lines[0]
    assert "processing.empty = 'error'" in lines[0]


def test_a_target_in_the_gate_does_not_warn(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, err, _ = run(tmp_path, POINT.format(x=100.0, gate=100.0, empty="error"), capsys)
    assert code == 0 and err == ""


def test_empty_error_stops_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, err, out = run(tmp_path, POINT.format(x=100.0, gate=30.0, empty="error"), capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"mdf: error: {tmp_path / 'c.toml'}: nearly")
    assert not out.exists()


def test_attenuation_underflow_with_snr_noise_is_all_zeros(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = POINT.format(x=10000.0, gate='"track"', empty="warn") + (
        '[[effects]]\nkind = "attenuation"\ngas_db_per_km = 100.0\n'
        '[[effects]]\nkind = "noise"\nmode = "snr"\nsnr_db = 10.0\n'
    )
    code, err, out = run(tmp_path, text, capsys)
    assert code == 0
    assert "empty result: the received signal is all zeros: the scene effects" in err
    with np.load(out / "result.npz") as d:
        assert not np.any(d["signal"])  # the noise in SNR mode is zero too: truly empty
    # the getting-started page quotes this very warning, and the limits it states
    from conftest import ROOT

    page = (ROOT / "docs" / "getting-started.md").read_text()
    quoted = page.split("```text\n", 1)[1].split("```", 1)[0]
    assert " ".join(quoted.split()) == err.strip()
    assert "(below 2.2e-308 W)" in page and f"{MIN_POWER_W:.2g}" == "2.2e-308"
    assert "(default 0.5)" in page and ProcessingConfig().max_lost_fraction == 0.5
    assert "-20 dB" in page and LOST_GAIN == 10 ** (-20 / 10)


@pytest.mark.parametrize("radar", ['kind = "lfm"', 'kind = "fmcw"\nboresight_azimuth_deg = 0.0'])
def test_static_reflectors_away_from_the_gate_are_no_target_lost(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], radar: str
) -> None:
    """A point target in the gate beside a room of 40 static reflectors 15-18 m away (a
    sensor's lab): the reflectors are outside the gate, as meant, and are no target lost.
    They counted as lost returns (40 of 41), so every such run warned 'nearly empty result'
    and a dataset build with processing.empty = 'error' stopped."""
    room = (
        '[[effects]]\nkind = "static_scene"\ncount = 40\ndistance_m = [15.0, 18.0]\n'
        "azimuth_deg = 0.0\nspread_deg = 20.0\n"
    )
    point = POINT.format(x=5.0, gate=5.0, empty="error").replace(
        "velocity = [1.0,", "velocity = [-1.0,"
    )
    text = f"{point}[radar]\n{radar}\n{room}"
    if "fmcw" in radar:
        text = text.replace("[radar]\n", "[radar]\nsample_rate = 10e6\n")  # 50 m maximum range
    code, err, _ = run(tmp_path, text, capsys)
    assert code == 0 and err == "", err


@pytest.mark.parametrize("max_range", [None, 62.46e3, 12.49])
def test_the_tracking_gate_advice_names_the_maximum_range_only_when_the_body_reaches_it(
    max_range: float | None,
) -> None:
    """Three point targets at 2.5-8 m with the gate tracking the first: two of three returns
    are outside the gate. The advice said 'or beyond the radar's maximum range ... bring the
    body within the maximum range' on every such run, an LFM radar's (62.46 km away) and a
    CW-like radar's (none) alike; it names the maximum range only when the body reaches it
    (an FMCW radar that lets ranges alias, maximum range 12.49 m, with the body at 13.5-14 m),
    and then not the gate's width."""
    echo = np.ones(10, np.complex128)
    near = Losses(300, 200, 0, (2.5, 8.0), (2.5, 3.0))
    why = empty_result(echo, near, max_lost_fraction=0.5, fixed_gate=False, max_range=max_range)
    assert why is not None and "67 % are outside the range gate" in why
    assert "maximum range" not in why
    assert why.endswith(
        "narrower than the body's spread in range (2.5-8 m): lengthen the radar's pulse, "
        "or choose a wider gate response or gate (an FMCW radar's radar.gate_width)"
    )
    far = Losses(300, 300, 0, (13.5, 14.0), (13.5, 14.0))
    why = empty_result(echo, far, max_lost_fraction=0.5, fixed_gate=False, max_range=max_range)
    assert why is not None
    reaches = (
        "the body (at 13.5-14 m) reaches beyond the radar's maximum range 12.49 m, where its "
        "range bins fold back and the tracking gate cannot follow it: bring the body within "
        "the maximum range"
    )
    assert why.endswith(reaches) == (max_range == 12.49), why
    # a body that only reaches past it (12-14 m) reaches it too
    spread = Losses(300, 300, 0, (12.0, 14.0), (12.0, 14.0))
    why = empty_result(echo, spread, max_lost_fraction=0.5, fixed_gate=False, max_range=max_range)
    assert why is not None and ("reaches beyond" in why) == (max_range == 12.49), why


@pytest.mark.parametrize("prf", [1e6, 1e5])
def test_a_pulse_radars_spread_body_beyond_c_over_2_prf_is_told_of_its_spread(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], prf: float
) -> None:
    """Three point targets at 200-240 m, a 50 MHz LFM radar's tracking gate on one: two of
    three returns are lost to the gate's width, at PRF 1 MHz (c / (2 prf) = 149.9 m, nearer
    than the body) as at 100 kHz (1.5 km). The advice blamed the maximum range at 1 MHz ('its
    range bins fold back ... bring the body within the maximum range'), but the LFM radar's
    simulation gates every echo at its true range (its own warning says so): nearer, the same
    two returns are lost. The advice names the gate's width at either PRF."""
    targets = ", ".join(
        f"{{ position = [{x}, 0.0, 0.0], velocity = [1.0, 0.0, 0.0], rcs = 1.0 }}"
        for x in (200.0, 220.0, 240.0)
    )
    text = (
        f'[motion]\nkind = "point_targets"\nlength = 0.2\ntargets = [{targets}]\n'
        '[scatterers]\nkind = "points"\n[scene]\nradar_position = [0.0, 0.0, 0.0]\n'
        f'[radar]\nkind = "lfm"\nprf = {prf}\nbandwidth = 50e6\npulse_width = 1e-7\n'
    )
    code, err, _ = run(tmp_path, text, capsys)
    assert code == 0
    assert "67 % are outside the range gate: the range gate (tracking the body) is narrower" in err
    assert "maximum range" not in err, err


def test_an_fmcw_body_beyond_the_maximum_range_is_told_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An FMCW radar of maximum range 49.97 m that lets ranges alias, its gate tracking a
    target at 60-61 m: the target's beat frequency folds to 10 m, away from the gate, and the
    run's advice names the maximum range (the radar's range FFT folds there)."""
    point = POINT.format(x=60.0, gate='"track"', empty="warn")
    radar = '[radar]\nkind = "fmcw"\nsample_rate = 10e6\nbeyond_max_range = "alias"\n'
    code, err, _ = run(tmp_path, point + radar, capsys)
    assert code == 0
    assert "reaches beyond the radar's maximum range 49.97 m, where its range bins fold" in err
