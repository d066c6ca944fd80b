"""Benchmark: the whole analytic pipeline against a minimal numpy floor, timed alternately.

The floor is the least numpy work that gives the same dB spectrogram from the scatterers'
ranges and RCS: the carrier phase reduced in float64, float32 cos/sin into complex64, range-
equation amplitudes and the exact LFM gate weights in float32, the sum over scatterers, a
complex64 STFT through scipy.fft on a strided windowed view, and float32 dB. Its inputs (ranges,
RCS, gate) come from a kept-scatterer run and are not timed; the pipeline is timed from the
loaded motion (placement, window, resampling, scatterers and RCS, ranges, receive, STFT, dB).

Before timing, the script checks that the floor reproduces the pipeline's dB map (maximum
difference above the floor, in dB). Then it times both alternately in one process and reports
the medians and the median of the paired ratios.

    .venv/bin/python benchmarks/bench_floor.py [--repeats 21] [--duration 6]
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
import scipy.fft as sfft  # noqa: E402
from bench_pipeline import walking_motion  # noqa: E402
from scipy.signal import get_window  # noqa: E402

from mdframework.config import validate_run_config  # noqa: E402
from mdframework.constants import SPEED_OF_LIGHT  # noqa: E402
from mdframework.pipeline import build_stages, simulate_motion  # noqa: E402


def floor_db(
    ranges: np.ndarray, rcs: np.ndarray, gate: np.ndarray, radar: Any, proc: Any
) -> np.ndarray:
    """The minimal numpy computation of the dB spectrogram (see the module docstring)."""
    fc, tau, bw = radar.carrier_frequency, radar.pulse_width, radar.bandwidth
    lam = SPEED_OF_LIGHT / fc
    cycles = (2.0 * fc / SPEED_OF_LIGHT) * ranges
    phase = ((-2.0 * np.pi) * (cycles - np.floor(cycles))).astype(np.float32)
    const = radar.transmit_power * lam**2 / (4.0 * np.pi) ** 3
    r32 = ranges.astype(np.float32)
    amp = np.sqrt(np.float32(const) * rcs.astype(np.float32)) / (r32 * r32)
    d = np.abs((2.0 / SPEED_OF_LIGHT) * (gate[:, None] - ranges)).astype(np.float32)
    rem = np.clip(np.float32(tau) - d, 0, None)
    amp *= rem * np.sinc(np.float32(bw / tau) * d * rem) / np.float32(tau)
    y = np.empty(ranges.shape[0], dtype=np.complex64)
    y.real = np.sum(amp * np.cos(phase), axis=1)
    y.imag = np.sum(amp * np.sin(phase), axis=1)
    w = get_window(proc.window, proc.window_length).astype(np.float32)
    frames = np.lib.stride_tricks.sliding_window_view(y, proc.window_length)[:: proc.hop]
    spec = sfft.fftshift(sfft.fft(frames * w, n=proc.nfft, axis=1), axes=1)
    power = (spec.real**2 + spec.imag**2).T
    p_max = power.max()
    out = np.maximum(power, p_max * np.float32(10.0 ** (proc.floor_db / 10.0))) / p_max
    return np.asarray(10.0 * np.log10(out), dtype=np.float32)


def main() -> None:
    """Check the floor, then time it against the pipeline and print a JSON summary."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=21)
    parser.add_argument("--duration", type=float, default=6.0)
    parser.add_argument("--block", type=int, default=None, help="processing.block_pulses")
    args = parser.parse_args()
    motion = walking_motion(duration=args.duration)
    base = {
        "motion": {"kind": "point_targets", "length": 1.0, "targets": [{"position": [1, 0, 0]}]},
        "scatterers": {"kind": "ellipsoid", "placement": "joints17", "height": 1.8},
        "radar": {"kind": "lfm"},
        "scene": {"radar_position": [12.0, 0.0, 1.5]},
    }
    if args.block:
        base["processing"] = {"block_pulses": args.block}
    cfg = validate_run_config(base)
    kept = validate_run_config(
        {**base, "processing": {**base.get("processing", {}), "keep_scatterers": True}}
    )
    stages = build_stages(cfg)
    ref = simulate_motion(kept, build_stages(kept), motion)
    assert ref.scatterers is not None
    radar_pos = np.asarray(cfg.scene.radar_position)
    ranges = ref.scatterers.ranges(radar_pos)
    rcs, gate = ref.scatterers.rcs, ref.gate_range
    radar_cfg: Any = cfg.radar
    proc = cfg.processing
    mine = simulate_motion(cfg, stages, motion).spectrogram_db
    fl = floor_db(ranges, rcs, gate, radar_cfg, proc)
    above = (mine > proc.floor_db + 1) | (fl > proc.floor_db + 1)
    reproduce_db = float(np.max(np.abs(mine[above] - fl[above])))

    pipe_t, floor_t, ratios = [], [], []
    for _ in range(args.repeats + 1):
        t0 = time.perf_counter()
        simulate_motion(cfg, stages, motion)
        t1 = time.perf_counter()
        floor_db(ranges, rcs, gate, radar_cfg, proc)
        t2 = time.perf_counter()
        pipe_t.append(t1 - t0)
        floor_t.append(t2 - t1)
        ratios.append((t1 - t0) / (t2 - t1))
    pipe_t, floor_t, ratios = pipe_t[1:], floor_t[1:], ratios[1:]  # first pair warms caches
    report = {
        "record_s": args.duration,
        "n_pulses": int(ranges.shape[0]),
        "n_scatterers": int(ranges.shape[1]),
        "floor_reproduces_pipeline_db": round(reproduce_db, 6),
        "pipeline_median_ms": round(1e3 * statistics.median(pipe_t), 2),
        "floor_median_ms": round(1e3 * statistics.median(floor_t), 2),
        "ratio_median": round(statistics.median(ratios), 2),
        "repeats": args.repeats,
        "stage_ms": {
            k: round(1e3 * v, 2)
            for k, v in simulate_motion(cfg, stages, motion).metadata["timings_s"].items()
        },
    }
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
