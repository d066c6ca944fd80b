"""What accuracy costs in time: a fidelity ladder over three scenes, and the FMCW margin.

Scenes: the Boulic walk (``kind = "boulic"``, MuJoCo walker), the CMU run 09_06
(``examples/cmu_run.toml``) and the Kinect walk (``examples/kinect_utkinect_walk.toml``; skipped
with a note if it is missing or does not load); and, for the FMCW ladder alone, 1 s of
``examples/fmcw_walk.toml``. Each *ladder* varies one knob with every other knob at its default;
its reference is that knob's highest-fidelity setting (marked ``ref``), so each row's error is
the error of that knob alone:

- ``interpolation``: linear, pchip, akima, cubic (ref: cubic, C2 spline; physics.md 6.4);
- ``prf``: 800, 1200, 2400 (default), 4800 Hz (ref 4800), the STFT window, hop and FFT size
  scaled with the PRF so that they keep their durations and Hz resolution;
- ``scatterers``: isotropic points at the 17 joints (0.05 m^2 each), ``ellipsoid`` joints17
  (default) and chen16,
  ``mujoco_body`` (Boulic only), chen16 parts sampled with 8 and 32 surface points (ref: 32);
- ``receive``: analytic exact (default), sinc, phase_only, raw fast-time path (ref: raw);
- ``precision``: float64 (ref) vs float32 (default: the radar's arithmetic after a float64 phase
  reduction, and the STFT, in float32 / complex64);
- ``stft``: window/hop/nfft (default 256/32/1024; ref 256/8/4096, the densest);
- ``effects``: none (default), shadowing, multipath, both (ref: both);
- ``shadowing decimation``: shadowing on, rays cast on every 1st (ref, the option's default),
  4th, 16th, 64th pulse and held in between;
- ``multipath paths``: multipath on, single- and double-bounce paths with the bounced RCS at the
  image radar's aspect (ref, the options' defaults), at the direct aspect
  (``image_aspect = false``), or the double-bounce image alone (``paths = "image"``);
- ``sphere rcs``: the head sphere's optical RCS (default) or the exact Mie series (ref);
- ``scattering phase``: each part's echo phase from its centre (default, Chen's) or from its
  specular point (ref, the geometric-optics phase);
- ``analytic margin`` (FMCW scene only): range bins the analytic path keeps on each side of a
  scatterer, 1, 2, 8 (default), 32 and 240 (ref: every bin of the range profile).

Error measures (against the ladder's reference run of the same scene):

- ``spec_err_db``: mean absolute difference of the dB spectrograms (each normalised to its own
  peak, floor -60 dB) over the signature's support, the reference's time-velocity cells above
  -40 dB. The setting's spectrogram is linearly interpolated onto the reference's (time,
  velocity) grid first (cells outside its velocity span count as floor), so PRF and STFT settings
  are comparable. Why: it is what a user sees and what the features are read from, and limiting
  it to the support ignores differences deep in the floor that no feature uses.
- ``feat_err_mps``: the largest absolute change over the seven features of
  ``mdframework.features.spectrogram_features`` [m/s]. Why: they are the classifier's inputs; a
  change well below the velocity resolution (~0.1 m/s) cannot change a classification.
- ``map_err`` (FMCW): the largest difference of the range-Doppler maps relative to each
  frame's peak in the reference.

Time: CPU time of this process (BLAS held to one thread; on a shared machine wall time would
count the other jobs too) of the whole pipeline after loading the motion (resampling,
scatterers, effects, receive, STFT). A ladder's settings run alternately, ``--repeats`` rounds
(``--slow-repeats`` for the rungs that take 0.1 s or more), so that a change of load reaches
them alike; each row gives the median time and ``x default``, the median over the rounds of its
time over the default's time in the same round.

    .venv/bin/python benchmarks/bench_accuracy.py [--quick] [--out out/bench_accuracy] [--docs]

Writes ``results.json``, ``results.csv``, ``results.md`` (the tables of ``docs/accuracy.md``)
and ``time_vs_error.png`` under ``--out``; ``--docs`` also writes ``results.json`` to
``docs/data/accuracy_results.json``, the figure to ``docs/figures/`` and the tables into
``docs/accuracy.md`` between its generated markers (``tests/test_accuracy_page.py`` checks them).
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import copy  # noqa: E402
import csv  # noqa: E402
import json  # noqa: E402
import shutil  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
from scipy.interpolate import RegularGridInterpolator  # noqa: E402

from mdframework.config import read_config_file, validate_run_config  # noqa: E402
from mdframework.features import FEATURE_NAMES, spectrogram_features  # noqa: E402
from mdframework.figures import save, style  # noqa: E402
from mdframework.pipeline import RunResult, build_stages, load_motion, simulate_motion  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
FLOOR_DB = -60.0
SUPPORT_DB = -40.0
DOCS_PAGE = ROOT / "docs" / "accuracy.md"
DOCS_RESULTS = ROOT / "docs" / "data" / "accuracy_results.json"
DOCS_FIGURE = ROOT / "docs" / "figures" / "accuracy_time_vs_error.png"
BEGIN = "<!-- bench_accuracy tables: generated, do not edit -->"
END = "<!-- end of bench_accuracy tables -->"


@dataclass(frozen=True)
class Setting:
    """One rung of a ladder: a name and the config changes it makes."""

    ladder: str
    name: str
    changes: dict[str, Any]
    default: bool = False
    ref: bool = False
    slow: bool = False  # timed with fewer repeats (each run takes 0.1 s or more)


def ladders(scene: str, quick: bool) -> list[Setting]:
    """The settings run on one scene."""
    s: list[Setting] = []
    for m in ("linear", "pchip", "akima", "cubic"):
        s.append(
            Setting(
                "interpolation",
                m,
                {"processing": {"interpolation": m}},
                default=m == "cubic",
                ref=m == "cubic",
            )
        )
    for prf in (800.0, 1200.0, 2400.0, 4800.0):
        k = prf / 2400.0  # the STFT keeps its durations [s] and Hz resolution
        stft = {"window_length": round(256 * k), "hop": round(32 * k), "nfft": round(1024 * k)}
        s.append(
            Setting(
                "prf",
                f"{prf:g} Hz",
                {"radar": {"prf": prf}, "processing": stft},
                default=prf == 2400.0,
                ref=prf == 4800.0,
            )
        )
    models: list[tuple[str, dict[str, Any]]] = [
        ("points", {"kind": "points", "body": True, "rcs": 0.05}),
        ("joints17", {"kind": "ellipsoid", "placement": "joints17"}),
        ("chen16", {"kind": "ellipsoid", "placement": "chen16"}),
    ]
    if scene == "boulic":
        models.append(("mujoco_body", {"kind": "mujoco_body"}))
    models.append(
        ("chen16 x8 surface", {"kind": "ellipsoid", "placement": "chen16", "surface_points": 8})
    )
    models.append(
        ("chen16 x32 surface", {"kind": "ellipsoid", "placement": "chen16", "surface_points": 32})
    )
    for name, sc in models:
        s.append(
            Setting(
                "scatterers",
                name,
                {"scatterers": sc},
                default=name == "joints17",
                ref=name == "chen16 x32 surface",
                slow="surface" in name,
            )
        )
    for resp in ("exact", "sinc", "phase_only"):
        s.append(
            Setting(
                "receive",
                f"analytic {resp}",
                {"radar": {"gate_response": resp}},
                default=resp == "exact",
            )
        )
    s.append(Setting("receive", "raw fast time", {"radar": {"path": "raw"}}, ref=True, slow=True))
    f64 = {"radar": {"precision": "float64"}, "processing": {"precision": "float64"}}
    s.append(Setting("precision", "float64", f64, ref=True))
    s.append(Setting("precision", "float32", {}, default=True))
    stfts = [(256, 32, 1024), (256, 64, 512), (128, 16, 512), (512, 32, 2048), (256, 8, 4096)]
    for w, h, n in stfts:
        s.append(
            Setting(
                "stft",
                f"{w}/{h}/{n}",
                {"processing": {"window_length": w, "hop": h, "nfft": n}},
                default=(w, h, n) == (256, 32, 1024),
                ref=(w, h, n) == (256, 8, 4096),
            )
        )
    eff = {
        "none": [],
        "shadowing": [{"kind": "shadowing"}],
        "multipath": [{"kind": "multipath"}],
        "shadowing+multipath": [{"kind": "shadowing"}, {"kind": "multipath"}],
    }
    for name, e in eff.items():
        s.append(
            Setting(
                "effects",
                name,
                {"effects": e},
                default=name == "none",
                ref=name == "shadowing+multipath",
                slow="shadowing" in name,
            )
        )
    # shadowing on: rays cast on every k-th pulse, held in between (ref and default: k = 1)
    for k in (1, 4, 16, 64):
        s.append(
            Setting(
                "shadowing decimation",
                f"decimation {k}",
                {"effects": [{"kind": "shadowing", "decimation": k}]},
                default=k == 1,
                ref=k == 1,
                slow=k < 16,
            )
        )
    # multipath on: the bounced paths' RCS at the image radar's aspect (ref, default) or the
    # direct RCS; both single- and double-bounce paths (ref, default) or the image alone
    paths: dict[str, dict[str, Any]] = {
        "all, image aspect": {},
        "all, direct aspect": {"image_aspect": False},
        "image only": {"paths": "image"},
    }
    for name, extra in paths.items():
        s.append(
            Setting(
                "multipath paths",
                name,
                {"effects": [{"kind": "multipath", **extra}]},
                default=not extra,
                ref=not extra,
            )
        )
    # the head's sphere: optical pi r^2 (default) or the exact Mie series (ref)
    for rcs in ("optical", "mie"):
        sc = {"kind": "ellipsoid", "placement": "joints17", "sphere_rcs": rcs}
        s.append(
            Setting(
                "sphere rcs",
                rcs,
                {"scatterers": sc},
                default=rcs == "optical",
                ref=rcs == "mie",
            )
        )
    # each part's echo phase: from its centre (default, Chen's code) or from its specular point
    # (ref: the geometric-optics phase, h(u) nearer along the line of sight)
    for phase in ("centre", "specular"):
        sc = {"kind": "ellipsoid", "placement": "joints17", "scattering_phase": phase}
        s.append(
            Setting(
                "scattering phase",
                phase,
                {"scatterers": sc},
                default=phase == "centre",
                ref=phase == "specular",
            )
        )
    return s


def fmcw_ladder() -> list[Setting]:
    """The FMCW scene's ladder: range bins kept on each side of a scatterer by the analytic
    path (default 8; ref: every bin of the 240-sample range profile)."""
    return [
        Setting(
            "analytic margin",
            f"{m}",
            {"radar": {"analytic_margin": m}},
            default=m == 8,
            ref=m == 240,
            slow=m == 240,
        )
        for m in (1, 2, 8, 32, 240)
    ]


def scene_configs(quick: bool) -> tuple[dict[str, dict[str, Any]], list[str]]:
    """Base config dicts per scene, and notes about skipped scenes."""
    notes: list[str] = []
    boulic = read_config_file(EXAMPLES / "boulic_walk.toml")
    boulic["scatterers"] = {"kind": "ellipsoid", "placement": "joints17"}
    boulic["motion"]["duration"] = 2.0 if quick else 4.0
    scenes = {"boulic": boulic}
    run = read_config_file(EXAMPLES / "cmu_run.toml")
    run["processing"] = {}  # the ladder's defaults (256/32/1024)
    run["radar"] = {"kind": "lfm"}
    scenes["cmu_run_09_06"] = run
    kinect_path = EXAMPLES / "kinect_utkinect_walk.toml"
    if kinect_path.exists():
        try:
            kinect = read_config_file(kinect_path)
            validate_run_config(kinect, base_dir=EXAMPLES)
            scenes["kinect_walk"] = kinect
        except Exception as exc:  # the Kinect source is being added in parallel
            notes.append(f"kinect_walk skipped: {type(exc).__name__}: {exc}")
    else:
        notes.append("kinect_walk skipped: examples/kinect_utkinect_walk.toml does not exist")
    fmcw = read_config_file(EXAMPLES / "fmcw_walk.toml")
    fmcw["motion"]["duration"] = 1.0
    scenes["fmcw_walk"] = fmcw
    return scenes, notes


def merged(base: dict[str, Any], changes: dict[str, Any]) -> dict[str, Any]:
    out = copy.deepcopy(base)
    for key, value in changes.items():
        if isinstance(value, dict) and key != "scatterers" and isinstance(out.get(key), dict):
            out[key] = {**out[key], **value}
        else:
            out[key] = copy.deepcopy(value)
    return out


def prepare(cfg_dict: dict[str, Any]) -> tuple[Any, Any]:
    """The validated config and the loaded motion of one setting."""
    cfg = validate_run_config(cfg_dict, base_dir=EXAMPLES)
    with warnings.catch_warnings():  # the Kinect walk's glitches, reported by every load
        warnings.simplefilter("ignore")
        return cfg, load_motion(build_stages(cfg).source)


def run_once(cfg: Any, motion: Any) -> tuple[RunResult, float]:
    """One run of the pipeline after loading the motion, on fresh stages: the result and its
    CPU time [s] (this process; BLAS held to one thread)."""
    stages = build_stages(cfg)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.process_time()
        res = simulate_motion(cfg, stages, motion)
        seconds = time.process_time() - t0
    return res, seconds


def time_ladder(
    prepared: dict[str, tuple[Any, Any]], reps: dict[str, int]
) -> tuple[dict[str, RunResult], dict[str, list[float | None]]]:
    """Run a ladder's settings alternately: round r runs every setting that has fewer than its
    ``reps`` runs, the order rotated by one each round, so that a change of the machine's load
    reaches every setting alike. Returns the last result of each setting and its CPU time per
    round [s] (None in rounds it sat out)."""
    names = list(prepared)
    results: dict[str, RunResult] = {}
    times: dict[str, list[float | None]] = {n: [] for n in names}
    for r in range(max(reps.values())):
        order = names[r % len(names) :] + names[: r % len(names)]
        ran: dict[str, float] = {}
        for n in order:
            if r < reps[n]:
                results[n], ran[n] = run_once(*prepared[n])
        for n in names:
            times[n].append(ran.get(n))
    return results, times


def paired_ratio(times: list[float | None], base: list[float | None]) -> float:
    """Median over the rounds in which both ran of a setting's time over the default's."""
    ratios = [t / b for t, b in zip(times, base, strict=True) if t is not None and b]
    return float(statistics.median(ratios))


def db_on_grid(res: RunResult, t: np.ndarray, v: np.ndarray) -> np.ndarray:
    """A run's dB spectrogram interpolated onto (velocity v, time t); floor outside."""
    interp = RegularGridInterpolator(
        (res.velocity, res.spectrogram.time),
        res.spectrogram_db,
        bounds_error=False,
        fill_value=FLOOR_DB,
    )
    vv, tt = np.meshgrid(
        v, np.clip(t, res.spectrogram.time[0], res.spectrogram.time[-1]), indexing="ij"
    )
    return np.asarray(interp((vv, tt)))


def errors(res: RunResult, ref: RunResult) -> tuple[float, float]:
    """(spectrogram error over the support [dB], largest feature change [m/s])."""
    ref_db = ref.spectrogram_db
    got = db_on_grid(res, ref.spectrogram.time, ref.velocity)
    support = ref_db > SUPPORT_DB
    spec_err = float(np.mean(np.abs(got - ref_db)[support]))
    f_res = spectrogram_features(res.spectrogram.power, res.velocity)
    f_ref = spectrogram_features(ref.spectrogram.power, ref.velocity)
    return spec_err, float(np.max(np.abs(f_res - f_ref)))


def map_error(res: RunResult, ref: RunResult) -> float | None:
    """Largest difference of two runs' range-Doppler maps relative to each frame's peak in the
    reference; None for runs without maps."""
    maps = res.received.products.get("range_doppler")
    ref_maps = ref.received.products.get("range_doppler")
    if maps is None or ref_maps is None:
        return None
    a, b = maps.astype(np.float64), ref_maps.astype(np.float64)
    peak = b.max(axis=(1, 2), keepdims=True)
    return float(np.max(np.abs(a - b) / peak))


def run_benchmark(
    quick: bool, repeats: int, slow_repeats: int
) -> tuple[list[dict[str, Any]], list[str], dict[str, float]]:
    """Every scene's ladders: the rows of the results, notes, and each scene's record [s]."""
    scenes, notes = scene_configs(quick)
    rows: list[dict[str, Any]] = []
    durations: dict[str, float] = {}
    for scene, base in scenes.items():
        settings = fmcw_ladder() if scene == "fmcw_walk" else ladders(scene, quick)
        if quick:
            settings = [
                s for s in settings if s.name not in ("akima", "512/32/2048", "decimation 16")
            ]
        for ladder in dict.fromkeys(s.ladder for s in settings):
            rungs = [s for s in settings if s.ladder == ladder]
            prepared: dict[str, tuple[Any, Any]] = {}
            for s in rungs:
                try:
                    prepared[s.name] = prepare(merged(base, s.changes))
                except Exception as exc:
                    notes.append(f"{scene} {ladder}={s.name} failed: {type(exc).__name__}: {exc}")
            reps = {s.name: slow_repeats if s.slow else repeats for s in rungs}
            results, times = time_ladder(prepared, {n: reps[n] for n in prepared})
            print(f"{scene:14s} {ladder:21s} done", flush=True)
            default = next(s for s in rungs if s.default)
            ref_s = next(s for s in rungs if s.ref)
            if default.name not in results or ref_s.name not in results:
                continue
            ref = results[ref_s.name]
            for s in rungs:
                if s.name not in results:
                    continue
                res = results[s.name]
                spec_err, feat_err = errors(res, ref)
                done = [t for t in times[s.name] if t is not None]
                rows.append(
                    {
                        "scene": scene,
                        "ladder": ladder,
                        "setting": s.name,
                        "default": s.default,
                        "reference": s.ref,
                        "time_s": statistics.median(done),
                        "runs": len(done),
                        "x_default": paired_ratio(times[s.name], times[default.name]),
                        "spec_err_db": spec_err,
                        "feat_err_mps": feat_err,
                        "map_err": map_error(res, ref),
                        "n_pulses": res.metadata["n_pulses"],
                        "n_scatterers": len(res.metadata["scatterers"]),
                    }
                )
            meta = results[default.name].metadata  # the record: its set duration, else
            # its pulses over the PRF (FMCW frames have gaps: its duration is always set)
            durations[scene] = float(
                base["motion"].get("duration") or meta["n_pulses"] / meta["prf_hz"]
            )
    return rows, notes, durations


def _git(*args: str) -> str:
    out = subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=False)
    return out.stdout.strip()


def _db(value: float) -> str:
    """A spectrogram error [dB]: two decimals, ``<0.001`` for a change that rounding hides,
    ``0`` for none."""
    return "0" if value == 0 else "<0.001" if value < 1e-3 else f"{value:.2f}"


def _range(values: list[float], fmt: str) -> str:
    """``low-high`` of values, or one value where they print alike; ``db``: as :func:`_db`."""
    lo, hi = (_db(v) if fmt == "db" else format(v, fmt) for v in (min(values), max(values)))
    return lo if lo == hi else f"{lo}-{hi}"


def markdown(results: dict[str, Any]) -> str:
    """The tables of docs/accuracy.md: each rung over the scenes, every row, and the FMCW
    margins, with the run's commit, date and load."""
    rows = results["rows"]
    spectro = [r for r in rows if r["map_err"] is None]
    scenes = list(dict.fromkeys(r["scene"] for r in spectro))
    lines = [
        "Each rung over the scenes (range from the lowest to the highest scene): CPU time "
        "relative to the ladder's default (`x default`, the median of the ratios of runs made "
        "alternately), spectrogram error [dB] and feature error [m/s] against the ladder's "
        "reference.",
        "",
        "| ladder | setting | | x default | spec err [dB] | feat err [m/s] |",
        "|---|---|---|---:|---:|---:|",
    ]
    rungs = list(dict.fromkeys((r["ladder"], r["setting"]) for r in spectro))
    for ladder, setting in rungs:
        got = [r for r in spectro if (r["ladder"], r["setting"]) == (ladder, setting)]
        tag = _tag(got[0])
        lines.append(
            f"| {ladder} | {setting} | {tag} | {_range([r['x_default'] for r in got], '.2f')} | "
            f"{_range([r['spec_err_db'] for r in got], 'db')} | "
            f"{_range([r['feat_err_mps'] for r in got], '.3f')} |"
        )
    lines += [
        "",
        "Every row: median CPU time [ms] of `runs` runs, `x default` as above.",
        "",
        "| scene | ladder | setting | | time [ms] | runs | x default | spec err [dB] | "
        "feat err [m/s] |",
        "|---|---|---|---|---:|---:|---:|---:|---:|",
    ]
    for r in spectro:
        lines.append(
            f"| {r['scene']} | {r['ladder']} | {r['setting']} | {_tag(r)} | "
            f"{1e3 * r['time_s']:.1f} | {r['runs']} | {r['x_default']:.2f} | "
            f"{_db(r['spec_err_db'])} | {r['feat_err_mps']:.3f} |"
        )
    fmcw_rows = [r for r in rows if r["map_err"] is not None]
    if fmcw_rows:
        lines += [
            "",
            "FMCW (`fmcw_walk`): range bins the analytic path keeps on each side of a "
            "scatterer; map err: the largest difference of the range-Doppler maps relative to "
            "each frame's peak.",
            "",
            "| analytic_margin | | time [ms] | runs | x default | map err | spec err [dB] |",
            "|---|---|---:|---:|---:|---:|---:|",
        ]
        for r in fmcw_rows:
            lines.append(
                f"| {r['setting']} | {_tag(r)} | {1e3 * r['time_s']:.1f} | {r['runs']} | "
                f"{r['x_default']:.2f} | {r['map_err']:.1e} | {_db(r['spec_err_db'])} |"
            )
    records = ", ".join(f"{s} {results['durations'][s]:.2f} s" for s in results["durations"])
    lines += [
        "",
        f"Records: {records}. Commit {results['commit']}, {results['date']}; "
        f"{results['repeats']} runs of each setting ({results['slow_repeats']} of the slow "
        f"ones: raw, surface points, shadowing with decimation below 16, the FMCW margin "
        f"240); {results['wall_s'] / 60:.1f} min in all; load average (1 min) "
        f"{results['load_average_start'][0]:.1f} at the start, "
        f"{results['load_average_end'][0]:.1f} at the end (2 cores shared).",
    ]
    if results["notes"]:
        lines += ["", "Notes:", "", *(f"- {n}" for n in results["notes"])]
    assert set(scenes) <= set(results["durations"])
    return "\n".join(lines) + "\n"


def _tag(r: dict[str, Any]) -> str:
    return " ".join(x for x, on in (("default", r["default"]), ("ref", r["reference"])) if on)


def write_outputs(results: dict[str, Any], out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    rows = results["rows"]
    with open(out / "results.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    (out / "results.json").write_text(json.dumps(results, indent=2) + "\n")
    (out / "results.md").write_text(markdown(results))
    plot([r for r in rows if r["map_err"] is None], out / "time_vs_error.png")


def write_page(results: dict[str, Any], page: Path = DOCS_PAGE) -> None:
    """Replace the generated block of ``page`` by :func:`markdown` of ``results``."""
    text = page.read_text()
    start, end = text.index(BEGIN), text.index(END)
    page.write_text(text[: start + len(BEGIN)] + "\n" + markdown(results) + text[end:])


def plot(rows: list[dict[str, Any]], path: Path) -> None:
    """Error against run time, one panel per scene, in the project's figure style."""
    with style() as plt:
        _plot(plt, rows, path)


def _plot(plt: Any, rows: list[dict[str, Any]], path: Path) -> None:
    scenes = sorted({r["scene"] for r in rows})
    ladder_names = sorted({r["ladder"] for r in rows})
    colours = {name: f"C{i}" for i, name in enumerate(ladder_names)}
    fig, axes = plt.subplots(
        1, len(scenes), figsize=(5.2 * len(scenes), 4.4), squeeze=False, layout="constrained"
    )
    for ax, scene in zip(axes[0], scenes, strict=True):
        for r in (x for x in rows if x["scene"] == scene):
            err = max(r["spec_err_db"], 1e-3)
            marker = "*" if r["default"] else ("s" if r["reference"] else "o")
            size = 160 if r["default"] else 40
            ax.scatter(
                r["time_s"],
                err,
                color=colours[r["ladder"]],
                marker=marker,
                s=size,
                edgecolor="k" if r["default"] else "none",
                zorder=3,
            )
            if not r["default"] and not r["reference"]:
                ax.annotate(
                    r["setting"],
                    (r["time_s"], err),
                    fontsize=6,
                    xytext=(3, 2),
                    textcoords="offset points",
                )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("median CPU time [s]")
        ax.set_ylabel("spectrogram error over support [dB]")
        ax.set_title(scene)
        ax.grid(True, which="both", alpha=0.3)
    handles = [plt.Line2D([], [], color=c, marker="o", ls="", label=n) for n, c in colours.items()]
    handles.append(
        plt.Line2D([], [], color="grey", marker="*", ms=12, ls="", mec="k", label="default")
    )
    handles.append(plt.Line2D([], [], color="grey", marker="s", ls="", label="reference (0 dB)"))
    axes[0][-1].legend(handles=handles, fontsize=7, loc="upper right")
    save(
        fig,
        path,
        "spectrogram error over the support against median CPU time; star: the "
        "default setting, square: the reference",
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="short records, fewer rungs (< 1 min)")
    ap.add_argument("--repeats", type=int, default=None, help="timing runs (default 21; 3)")
    ap.add_argument(
        "--slow-repeats", type=int, default=None, help="timing runs of slow rungs (default 3; 1)"
    )
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "bench_accuracy")
    ap.add_argument(
        "--docs",
        action="store_true",
        help=f"also write {DOCS_RESULTS.relative_to(ROOT)}, the figure and the tables of "
        f"{DOCS_PAGE.relative_to(ROOT)}",
    )
    args = ap.parse_args()
    repeats = args.repeats or (3 if args.quick else 21)
    slow_repeats = args.slow_repeats or (1 if args.quick else 3)
    clock = time.perf_counter()
    load_start = list(os.getloadavg())
    dirty = _git("status", "--porcelain", "--untracked-files=no")
    commit = _git("rev-parse", "--short", "HEAD") + (" (with changes)" if dirty else "")
    rows, notes, durations = run_benchmark(args.quick, repeats, slow_repeats)
    results: dict[str, Any] = {
        "command": "benchmarks/bench_accuracy.py " + " ".join(sys.argv[1:]),
        "commit": commit,
        "date": time.strftime("%d %B %Y", time.gmtime()).lstrip("0"),
        "repeats": repeats,
        "slow_repeats": slow_repeats,
        "load_average_start": load_start,
        "load_average_end": list(os.getloadavg()),
        "wall_s": time.perf_counter() - clock,
        "durations": durations,
        "notes": notes,
        "rows": rows,
    }
    write_outputs(results, args.out)
    if args.docs:
        DOCS_RESULTS.parent.mkdir(parents=True, exist_ok=True)
        DOCS_RESULTS.write_text(json.dumps(results, indent=2) + "\n")
        shutil.copyfile(args.out / "time_vs_error.png", DOCS_FIGURE)
        write_page(results)
    print(markdown(results))
    print(f"features: {', '.join(FEATURE_NAMES)}")


if __name__ == "__main__":
    main()
