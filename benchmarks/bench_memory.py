"""Benchmark: peak memory and time against record length (the streaming pipeline).

Each measurement runs in a fresh process (so its peak resident set is its own): a body walking on
a treadmill 12 m from the radar (17 ellipsoid scatterers, PRF 2400 Hz), simulated end to end for
a record of the given length on the analytic or the raw LFM path, or (``fmcw``) through the FMCW
sensor model (the IWR1443 preset, 6 m from the radar, with its range-Doppler maps and point
clouds, 30 frames a second). Reports the wall time, the CPU
time of the simulation, the peak RSS [MiB] and the time exponent between the shortest and the
longest record (``log(t_long / t_short) / log(len_long / len_short)``), of the wall time and of
the CPU time (the one to read on a shared machine, where other jobs stretch wall times).

``--effects`` adds ground clutter (on the FMCW path static clutter of 0.1 m^2 a range cell in
its IF samples: its maps and points take no other), multipath, a static scene of 10 reflectors
and (on the LFM paths; the FMCW preset adds its own receiver noise) noise; ``--motion walk``
replaces the treadmill by the Boulic walker walking straight away from the radar (10 m at the
start, 0.88 m/s), so the range span the tracking gate covers, and with it the clutter's patch
count, grows with the record.

``--effect NAME ...`` runs the named effects alone, in that order (instead of ``--effects``'
set); ``--paths cw`` adds a 24 GHz CW radar sampled at 2 kHz; ``--block N`` sets
``processing.block_pulses``; one length gives no exponent.

    .venv/bin/python benchmarks/bench_memory.py [--lengths 6 600] [--paths analytic raw cw fmcw]
        [--effects | --effect NAME ...] [--motion treadmill|walk] [--block N]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
from pathlib import Path

CHILD = r"""
import json, resource, sys, time
sys.path.insert(0, {bench!r})
from bench_pipeline import walking_motion
from mdframework.config import validate_run_config
from mdframework.pipeline import build_stages, load_motion, simulate_motion

NAMED = {{
    "noise": lambda path: {{"kind": "noise"}},
    "clutter": lambda path: (
        {{"kind": "clutter", "power": "rcs", "wind_fraction": 0.0}} if path == "fmcw"
        else {{"kind": "clutter", "range_resolution": 1.0}} if path == "cw"
        else {{"kind": "clutter"}}
    ),
    "multipath": lambda path: {{"kind": "multipath"}},
    "static_scene": lambda path: {{"kind": "static_scene", "count": 10}},
    "shadowing": lambda path: {{"kind": "shadowing", "decimation": 8}},
    "antenna": lambda path: {{"kind": "antenna", "beamwidth_az_deg": 30.0}},
    "attenuation": lambda path: {{"kind": "attenuation", "gas_db_per_km": 0.5}},
}}

length, path, effects, walk = float(sys.argv[1]), sys.argv[2], sys.argv[3] == "1", sys.argv[4]
named, block = json.loads(sys.argv[5]), int(sys.argv[6])
if path == "fmcw":  # the IWR1443 preset (maximum range 10.5 m): the radar 6 m away
    radar, where = {{"kind": "fmcw", "preset": "iwr1443_short_range_3d"}}, [6.0, 0.0, 1.0]
elif path == "cw":  # a 24 GHz CW radar sampled at 2 kHz
    radar, where = {{"kind": "cw", "carrier_frequency": 24.125e9}}, [12.0, 0.0, 1.5]
else:
    radar, where = {{"kind": "lfm", "path": path}}, [12.0, 0.0, 1.5]
spec = {{
    "motion": {{"kind": "point_targets", "length": 1.0, "targets": [{{"position": [1, 0, 0]}}],
               "duration": length}},
    "scatterers": {{"kind": "ellipsoid", "placement": "joints17", "height": 1.8}},
    "radar": radar,
    "scene": {{"radar_position": where, "person": {{"motion": "treadmill"}}}},
}}
if walk == "walk":  # aspect 180: walking straight away from the radar
    spec["motion"] = {{"kind": "boulic", "height": 1.8, "rv": 1.0, "duration": length}}
    spec["scatterers"] = {{"kind": "ellipsoid", "placement": "joints17"}}
    spec["scene"] = {{"radar_position": [10.0, 0.0, 2.0],
                     "person": {{"motion": "recorded", "position": [0.0, 0.0],
                                 "aspect_deg": 180.0}}}}
if effects:
    spec["effects"] = [
        {{"kind": "clutter"}}, {{"kind": "multipath"}}, {{"kind": "static_scene", "count": 10}}
    ] + ([] if path == "fmcw" else [{{"kind": "noise"}}])
    if path == "fmcw":  # static clutter of a given RCS, in the IF samples (maps and points)
        spec["effects"][0] = {{"kind": "clutter", "power": "rcs", "wind_fraction": 0.0}}
if named:  # effects by name, in the order given (with their defaults, a few set)
    spec["effects"] = [NAMED[k](path) for k in named]
spec["processing"] = {{"block_pulses": block}}
cfg = validate_run_config(spec)
stages = build_stages(cfg)
motion = load_motion(stages.source) if walk == "walk" else walking_motion(duration=length + 0.5)
t0, c0 = time.perf_counter(), time.process_time()
res = simulate_motion(cfg, stages, motion)
wall, cpu = time.perf_counter() - t0, time.process_time() - c0
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
clutter = [e for e in res.metadata["effects"] if e.get("kind") == "clutter"]
print(json.dumps({{"wall_s": wall, "cpu_s": cpu, "peak_rss_mib": rss,
                  "n_pulses": int(res.pulse_times.size),
                  "n_patches": clutter[0]["n_patches"] if clutter else 0}}))
"""


def measure(
    length: float,
    path: str,
    effects: bool = False,
    motion: str = "treadmill",
    named: list[str] | None = None,
    block: int = 4096,
) -> dict[str, float]:
    """Wall time and peak RSS of one record in a fresh process (``named``: effects by name,
    instead of ``effects``' set; ``block``: ``processing.block_pulses``)."""
    bench = str(Path(__file__).resolve().parent)
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    argv = [str(length), path, str(int(effects)), motion, json.dumps(named or []), str(block)]
    out = subprocess.run(
        [sys.executable, "-c", CHILD.format(bench=bench), *argv],
        check=False,
        capture_output=True,
        text=True,
        env=env,
    )
    if out.returncode != 0:
        sys.exit(f"{path} {length:g} s failed:\n{out.stderr[-2000:]}")
    return dict(json.loads(out.stdout.strip().splitlines()[-1]))


def main() -> None:
    """Measure every (path, length) and print a JSON summary."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lengths", type=float, nargs="+", default=[6.0, 600.0])
    parser.add_argument("--paths", nargs="+", default=["analytic", "raw"])
    parser.add_argument("--effects", action="store_true", help="clutter, multipath, ... too")
    parser.add_argument("--motion", choices=["treadmill", "walk"], default="treadmill")
    parser.add_argument(
        "--effect",
        nargs="+",
        default=[],
        choices=[
            "noise",
            "clutter",
            "multipath",
            "static_scene",
            "shadowing",
            "antenna",
            "attenuation",
        ],
        help="these effects, in this order (instead of --effects' set)",
    )
    parser.add_argument("--block", type=int, default=4096, help="processing.block_pulses")
    args = parser.parse_args()
    report: dict[str, object] = {}
    for path in args.paths:
        rows = {
            f"{length:g}s": measure(
                length, path, args.effects, args.motion, args.effect, args.block
            )
            for length in args.lengths
        }
        report[path] = {"records": rows}
        first, last = rows[f"{args.lengths[0]:g}s"], rows[f"{args.lengths[-1]:g}s"]
        ratio = args.lengths[-1] / args.lengths[0]
        if ratio != 1.0:  # one length: no exponent
            exponent = math.log(last["wall_s"] / first["wall_s"]) / math.log(ratio)
            cpu_exponent = math.log(last["cpu_s"] / first["cpu_s"]) / math.log(ratio)
            report[path] |= {
                "time_exponent": round(exponent, 3),
                "cpu_time_exponent": round(cpu_exponent, 3),
            }
        print(json.dumps({path: report[path]}), flush=True)
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
