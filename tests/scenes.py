"""Random valid scenes for property tests (``tests/test_random_scenes.py``) and the fuzzing
benchmark (``benchmarks/fuzz_scenes.py``).

A scene is a run config drawn from the documented ranges: point targets or a real recording
(CMU BVH and ASF/AMC, UTKinect), every scatterer model that fits the motion, a radar (LFM:
carrier, bandwidth, PRF, pulse width, gains, gate response, precision; FMCW: the chirp timing,
antennas, FFTs, noise, detection, both paths, the presets; CW: carrier and I/Q rate), any
subset of the effects (noise, clutter, multipath, antenna, attenuation), the scene geometry,
conditioning and the STFT. :func:`run_scene` simulates one and reports what happened:
``"ok"`` (every output finite), ``"refused: ..."`` (a one-line :class:`~mdframework.MdfError`,
e.g. a target inside ``min_range`` or a record shorter than the STFT window), or raises for
anything else (an internal error, a numerical warning, a non-finite output).
"""

from __future__ import annotations

import warnings
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import assume
from hypothesis import strategies as st
from mdf_fmcw.presets import PRESETS

from mdframework import MdfError, Motion
from mdframework.config import validate_run_config
from mdframework.pipeline import build_stages, load_motion, simulate_motion

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "examples" / "data"
RECORDINGS = {
    "cmu-bvh": {"kind": "cmu", "file": str(DATA / "cmu" / "bvh" / "16_21.bvh")},
    "cmu-amc": {"kind": "cmu", "file": str(DATA / "cmu" / "asf-amc" / "09_06.amc")},
    "utkinect": {
        "kind": "kinect",
        "format": "utkinect",
        "file": str(DATA / "kinect" / "utkinect" / "joints_s01_e01.txt"),
    },
}
#: Most pulses in one drawn scene (keeps each example to tens of milliseconds).
MAX_SCENE_PULSES = 6000


def load_project_modules() -> int:
    """Import every module of the core and of the plugins this repository ships (a fraction of
    a second: their heavy dependencies load only when used); the number of modules.

    Hypothesis (6.131 and later) also draws, now and then, constants written in the project's
    loaded modules, so the scenes a seed gives depended on which modules the tests before (and
    the earlier scenes' lazy imports) had loaded: the same seed drew other scenes from run to
    run, at 12 to 63 s of CPU for one class of 50. With every module loaded first a seed draws
    the same scenes whatever ran before. Call it before drawing."""
    import importlib
    import pkgutil

    packages = [ROOT / "src" / "mdframework", *sorted(ROOT.glob("plugins/*/src/*"))]
    names = []
    for package in packages:
        if (package / "__init__.py").exists():
            names.append(package.name)
            for info in pkgutil.walk_packages([str(package)], prefix=f"{package.name}."):
                if not info.name.endswith(".__main__"):  # that one runs the CLI
                    names.append(info.name)
    for name in names:
        importlib.import_module(name)
    return len(names)


def _log_uniform(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(np.log10(lo), np.log10(hi)).map(lambda e: float(10.0**e))


def radar_sections() -> st.SearchStrategy[dict[str, Any]]:
    """Any radar: LFM pulse-Doppler, FMCW chirp sequence or CW Doppler."""
    return st.one_of(lfm_sections(), fmcw_sections(), cw_sections())


def pulse_rate(radar: dict[str, Any]) -> float:
    """Pulses per second of a drawn radar (chirps for FMCW, I/Q samples for CW) [Hz]."""
    if radar["kind"] == "fmcw":
        radar = {**PRESETS.get(radar.get("preset") or "", {}), **radar}
        return float(len(radar["tdm_order"]) * radar["n_loops"] / radar["frame_period"])
    if radar["kind"] == "cw":
        return float(radar["sample_rate"])
    return float(radar["prf"])


def slow_time_rate(radar: dict[str, Any]) -> float:
    """Slow-time samples per second of a drawn radar (the STFT's input) [Hz]."""
    if radar["kind"] == "fmcw":
        radar = {**PRESETS.get(radar.get("preset") or "", {}), **radar}
        return float(radar["n_loops"] / radar["frame_period"])
    return pulse_rate(radar)


def _power(draw: st.DrawFn) -> dict[str, Any]:
    return {
        "transmit_power": draw(_log_uniform(1e-3, 1e4)),
        "gain_dbi": draw(st.floats(-10.0, 45.0)),
        "system_loss_db": draw(st.floats(0.0, 20.0)),
        "amplitude": draw(st.sampled_from(["range_equation", "sqrt_rcs"])),
    }


@st.composite
def cw_sections(draw: st.DrawFn) -> dict[str, Any]:
    """A CW Doppler radar: any carrier of the documented range that radars use, I/Q rate."""
    return {
        "kind": "cw",
        "carrier_frequency": draw(_log_uniform(1e9, 1e11)),
        "sample_rate": draw(_log_uniform(200.0, 20_000.0)),
        **_power(draw),
    }


@st.composite
def fmcw_sections(draw: st.DrawFn) -> dict[str, Any]:
    """An FMCW chirp sequence that fits its frame (or a sensor preset), drawn from the
    documented ranges: the ADC within the ramp, the sweep within the bandwidth, the chirps
    within the frame; antennas, windows, FFT sizes, noise, CFAR and the two paths."""
    common = {
        "path": draw(st.sampled_from(["analytic", "raw"])),
        "points": draw(st.booleans()),
        "save_range_doppler": draw(st.booleans()),
        "beyond_max_range": draw(st.sampled_from(["error", "alias"])),
        **_power(draw),
    }
    if draw(st.integers(0, 3)) == 0:
        preset = draw(st.sampled_from(["iwr1443_short_range_3d", "iwr6843isk_people_counting_6m"]))
        return {"kind": "fmcw", "preset": preset, "n_loops": draw(st.integers(2, 16)), **common}
    n_samples = draw(st.integers(8, 256))
    sample_rate = draw(_log_uniform(1e6, 2e7))
    adc_start = draw(st.floats(0.0, 10e-6))
    ramp = adc_start + n_samples / sample_rate * draw(st.floats(1.0, 1.5))
    max_bandwidth = draw(_log_uniform(2e8, 4e9))
    slope = draw(_log_uniform(1e11, max(1e11, min(1e15, max_bandwidth / ramp))))
    assume(slope * ramp <= max_bandwidth)
    idle = draw(st.floats(2e-6, 100e-6))
    n_tx = draw(st.integers(1, 3))
    tdm = draw(st.permutations(list(range(1, n_tx + 1))))
    n_loops = draw(st.integers(2, 32))
    busy = n_loops * n_tx * (idle + ramp)
    frame_period = busy * draw(st.sampled_from([1.0, 1.0, 1.5, 3.0]))
    assume(frame_period <= 1.0)
    n_rx = draw(st.integers(1, 4))
    return {
        "kind": "fmcw",
        "start_frequency": draw(_log_uniform(1e9, 1.2e11)),
        "slope": slope,
        "idle_time": idle,
        "adc_start_time": adc_start,
        "ramp_end_time": ramp,
        "sample_rate": sample_rate,
        "n_samples": n_samples,
        "n_loops": n_loops,
        "tdm_order": tdm,
        "frame_period": frame_period,
        "max_bandwidth": max_bandwidth,
        "tx_positions": [[2.0 * i, float(i % 2)] for i in range(n_tx)],
        "rx_positions": [[float(i), 0.0] for i in range(n_rx)],
        "range_window": draw(st.sampled_from(["rect", "hann", "hamming", "blackman"])),
        "doppler_window": draw(st.sampled_from(["rect", "hann", "hamming", "blackman"])),
        "range_fft_size": draw(st.one_of(st.none(), st.integers(n_samples, 2 * n_samples))),
        "receiver_noise": draw(st.booleans()),
        "noise_figure_db": draw(st.floats(0.0, 30.0)),
        "clutter_removal": draw(st.booleans()),
        "cfar_doppler": draw(st.one_of(st.none(), st.just({"mode": "ca", "train": 2}))),
        "gate_width": draw(st.floats(0.1, 10.0)),
        **common,
    }


@st.composite
def lfm_sections(draw: st.DrawFn) -> dict[str, Any]:
    """An LFM radar within the documented limits (B x tau >= 1, tau <= 1/PRF)."""
    carrier = draw(_log_uniform(3e8, 1e11))
    bandwidth = draw(_log_uniform(1e6, min(2e9, carrier)))
    prf = draw(_log_uniform(100.0, 20_000.0))
    lo, hi = 1.0 / bandwidth, min(1.0 / prf, 1e-3)
    assume(lo <= hi)
    return {
        "kind": "lfm",
        "carrier_frequency": carrier,
        "bandwidth": bandwidth,
        "prf": prf,
        "pulse_width": draw(st.floats(lo, hi)),
        "transmit_power": draw(_log_uniform(1e-3, 1e4)),
        "gain_dbi": draw(st.floats(-10.0, 45.0)),
        "system_loss_db": draw(st.floats(0.0, 20.0)),
        "gate_response": draw(st.sampled_from(["exact", "sinc", "phase_only"])),
        "precision": draw(st.sampled_from(["float64", "float32"])),
    }


@st.composite
def effect_sections(draw: st.DrawFn) -> list[dict[str, Any]]:
    """Any subset of the effects that work on any motion, with drawn parameters."""
    out: list[dict[str, Any]] = []
    if draw(st.booleans()):
        out.append({"kind": "noise", "snr_db": draw(st.floats(-20.0, 80.0))})
    if draw(st.booleans()):
        out.append(
            {
                "kind": "clutter",
                "csr_db": draw(st.floats(-30.0, 30.0)),
                "wind_fraction": draw(st.floats(0.0, 1.0)),
                "spread_mps": draw(st.floats(0.01, 2.0)),
                # radars without a bandwidth (CW, FMCW) need it
                "range_resolution": draw(st.one_of(st.none(), st.floats(0.05, 20.0))),
            }
        )
    if draw(st.booleans()):
        out.append(
            {
                "kind": "multipath",
                "ground_height": draw(st.floats(-1.0, 0.0)),
                "reflection_magnitude": draw(st.floats(0.0, 1.0)),
                "reflection_phase_deg": draw(st.floats(-180.0, 180.0)),
                "paths": draw(st.sampled_from(["all", "image"])),
            }
        )
    if draw(st.booleans()):
        out.append(
            {
                "kind": "antenna",
                "pattern": draw(st.sampled_from(["gaussian", "uniform"])),
                "beamwidth_az_deg": draw(st.floats(1.0, 170.0)),
                "steering": draw(st.sampled_from(["fixed", "track"])),
            }
        )
    if draw(st.booleans()):
        out.append({"kind": "attenuation", "gas_db_per_km": draw(st.floats(0.0, 50.0))})
    order = draw(st.permutations(list(range(len(out)))))
    effects = [out[i] for i in order]
    kinds = [e["kind"] for e in effects]
    if "multipath" in kinds:  # antenna and attenuation after multipath, else refused
        effects.insert(0, effects.pop(kinds.index("multipath")))
    return effects


@st.composite
def processing_sections(draw: st.DrawFn, n_pulses: float) -> dict[str, Any]:
    """STFT settings; the window mostly fits the record (``n_pulses``), sometimes not."""
    window_length = draw(st.integers(8, max(8, min(512, int(n_pulses * 1.2)))))
    return {
        "interpolation": draw(st.sampled_from(["cubic", "pchip", "akima", "linear"])),
        "window": draw(st.sampled_from(["hann", "hamming", "boxcar", "blackman"])),
        "window_length": window_length,
        "hop": draw(st.integers(1, window_length)),
        "nfft": draw(st.integers(window_length, 2048)),
        "floor_db": draw(st.floats(-150.0, -5.0)),
    }


def _coordinate(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


@st.composite
def point_scenes(draw: st.DrawFn) -> dict[str, Any]:
    """Point targets moving at constant velocity."""
    radar = draw(radar_sections())
    length = draw(st.floats(0.05, 3.0))
    assume(length * pulse_rate(radar) <= MAX_SCENE_PULSES)
    targets = [
        {
            "position": [draw(_coordinate(-300.0, 300.0)) for _ in range(3)],
            "velocity": [draw(_coordinate(-30.0, 30.0)) for _ in range(3)],
            "rcs": draw(st.floats(0.0, 100.0)),
        }
        for _ in range(draw(st.integers(1, 4)))
    ]
    return {
        "seed": draw(st.integers(0, 2**32)),
        "motion": {
            "kind": "point_targets",
            "length": length,
            "frame_rate": draw(st.floats(5.0, 1000.0)),
            "targets": targets,
        },
        "scatterers": {"kind": "points"},
        "radar": radar,
        "effects": draw(effect_sections()),
        "scene": {
            "radar_position": [draw(_coordinate(-50.0, 50.0)) for _ in range(3)],
            "gate": draw(st.one_of(st.just("track"), st.floats(1.0, 500.0))),
            "min_range": draw(st.floats(0.1, 2.0)),
        },
        "processing": draw(processing_sections(length * slow_time_rate(radar))),
    }


def _radar_near(
    draw: st.DrawFn, centre: list[float], r_min: float, r_max: float, z: tuple[float, float]
) -> list[float]:
    """A radar position ``r_min .. r_max`` horizontally from ``centre`` (x, y), at height z."""
    r = draw(st.floats(r_min, r_max))
    bearing = np.deg2rad(draw(st.floats(-180.0, 180.0)))
    return [centre[0] + r * np.cos(bearing), centre[1] + r * np.sin(bearing), draw(st.floats(*z))]


@st.composite
def body_scenes(draw: st.DrawFn) -> dict[str, Any]:
    """A real recording placed in the scene, seen by any body model."""
    name = draw(st.sampled_from(sorted(RECORDINGS)))
    radar = draw(radar_sections())
    duration = draw(st.floats(0.1, 1.0))
    assume(duration * pulse_rate(radar) <= MAX_SCENE_PULSES)
    motion = {**RECORDINGS[name], "start": draw(st.floats(0.0, 0.1)), "duration": duration}
    mode = draw(st.sampled_from(["recorded", "treadmill", "straight"]))
    person: dict[str, Any] = {
        "motion": mode,
        "position": [draw(_coordinate(-20.0, 20.0)) for _ in range(2)],
        "aspect_deg": draw(st.floats(-180.0, 180.0)),
    }
    if mode == "straight":
        person["speed"] = draw(st.floats(0.0, 8.0))
    scatterers = draw(
        st.one_of(
            st.fixed_dictionaries(
                {
                    "kind": st.just("ellipsoid"),
                    "placement": st.sampled_from(["joints17", "chen16"]),
                    "head": st.sampled_from(["sphere", "spheroid"]),
                    "sphere_rcs": st.sampled_from(["optical", "mie"]),
                    "surface_points": st.integers(0, 3),
                    "scattering_phase": st.sampled_from(["centre", "specular"]),
                }
            ),
            st.fixed_dictionaries({"kind": st.just("points"), "body": st.just(True)}),
        )
    )
    conditioning = {"enabled": draw(st.booleans()), "max_speed_mps": draw(st.floats(3.0, 20.0))}
    return {
        "seed": draw(st.integers(0, 2**32)),
        "motion": motion,
        "scatterers": scatterers,
        "radar": radar,
        "effects": draw(effect_sections()),
        "scene": {
            "radar_position": _radar_near(draw, person["position"], 3.0, 40.0, (0.0, 10.0)),
            "person": person,
            "gate": draw(st.one_of(st.just("track"), st.floats(1.0, 60.0))),
        },
        "processing": draw(processing_sections(duration * slow_time_rate(radar))),
        "conditioning": conditioning,
    }


def scenes() -> st.SearchStrategy[dict[str, Any]]:
    """Point-target and body scenes."""
    return st.one_of(point_scenes(), body_scenes())


@lru_cache(maxsize=8)
def _motion(section_json: str) -> Motion:
    import json

    config = validate_run_config({"motion": json.loads(section_json)})
    return load_motion(build_stages(config).source)


def run_scene(cfg: dict[str, Any]) -> str:
    """Simulate a drawn scene; ``"ok"`` or ``"refused: <the error>"``, else raise (see the
    module doc).

    Numerical warnings (``RuntimeWarning``: overflow, invalid values, division by zero) are
    errors; the aliasing and motion-sanity warnings are part of a valid run."""
    import json

    with warnings.catch_warnings():
        # numerical warnings are failures; the physics' and data's own warnings (aliasing,
        # motion sanity) are part of a valid run
        warnings.simplefilter("ignore")
        warnings.simplefilter("error", RuntimeWarning)
        try:
            config = validate_run_config(cfg)
            stages = build_stages(config)
            whole = {k: v for k, v in cfg["motion"].items() if k not in ("start", "duration")}
            if whole["kind"] == "point_targets":
                motion = load_motion(stages.source)
            else:
                motion = _motion(json.dumps(whole, sort_keys=True))
            result = simulate_motion(config, stages, motion)
        except MdfError as exc:
            return f"refused: {exc}"
    for name, array in (
        ("pulse_times", result.pulse_times),
        ("signal", result.received.signal),
        ("spectrogram power", result.spectrogram.power),
        ("spectrogram_db", result.spectrogram_db),
        ("velocity", result.velocity),
    ):
        if not np.all(np.isfinite(array)):
            raise AssertionError(f"non-finite {name} for {cfg}")
    for name, array in result.received.products.items():
        if not np.all(np.isfinite(array)):
            raise AssertionError(f"non-finite product {name} for {cfg}")
    return "ok"
