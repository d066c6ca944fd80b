"""Trained on simulation, tested on real radar: the sim-to-real result and its ablation.

The data: ``examples/datasets/sim2real.toml``, group ``radhar``: the shipped RadHAR recordings
(12 recordings per activity, boxing, jump, walk, 2 s records of per-frame Doppler histograms);
group ``sim``: CMU motions through the FMCW sensor model with the IWR1443 preset, point clouds,
per-record random draws. It is built once per seed and per variant: ``full`` is the shipped
config, every other variant changes one modelling choice of it (the real records are the same in
all).

For every variant, seed, classifier input (the seven features, the histogram vector) and
classifier, a classifier is trained on ALL simulated records and tested on ALL real records:
balanced accuracy and per-class rates, then mean and std over the seeds. The real-to-real
reference uses the same input and classifier, trained on real recordings and tested on held-out
real recordings (``--repeats`` random splits holding out 5 of the 12 recordings of every class).

    .venv/bin/python benchmarks/bench_sim2real.py [--seeds 0 1 ... 9] [--variants full,...]
        [--workers N] [--out out/bench_sim2real] [--docs]

Writes ``results.json`` and ``results.md`` (the tables of ``docs/sim-to-real.md``, with the
build times and the load average) and ``histograms.png`` (mean real and simulated per-frame
histograms per class) under ``--out``; ``--docs`` also copies ``results.json`` to
``docs/data/sim2real_results.json`` and the figure to ``docs/figures/``
(``tests/test_sim2real_page.py`` checks the page against that file).
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import copy  # noqa: E402
import json  # noqa: E402
import shutil  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

from mdframework.classify import balanced_accuracy, confusion_matrix  # noqa: E402
from mdframework.config import read_config_file  # noqa: E402
from mdframework.dataset import DatasetConfig, build_dataset, load_dataset  # noqa: E402
from mdframework.errors import MdfError  # noqa: E402
from mdframework.experiment import (  # noqa: E402
    ExperimentConfig,
    classifier_factory,
    classifier_inputs,
    recording_splits,
    recordings_held_out,
)

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "examples" / "datasets" / "sim2real.toml"
DOCS_RESULTS = ROOT / "docs" / "data" / "sim2real_results.json"
DOCS_FIGURE = ROOT / "docs" / "figures" / "sim2real_histograms.png"
SIM, REAL = "sim", "radhar"
#: The real-to-real splits' test fraction, and the real recordings of each activity the
#: repository ships (a split holds ``recordings_held_out(12, 0.4)`` = 5 of them out).
TEST_FRACTION, REAL_RECORDINGS = 0.4, 12
CLASSIFIERS: dict[str, dict[str, Any]] = {
    "knn": {"kind": "knn", "k": 5},
    "forest": {
        "kind": "sklearn",
        "estimator": "sklearn.ensemble.RandomForestClassifier",
        "params": {"n_estimators": 200, "random_state": 0},
    },
}
INPUTS = ("features", "histogram")


def _effect_index(cfg: dict[str, Any], kind: str) -> int:
    return [e.get("kind") for e in cfg["base"]["effects"]].index(kind)


def _drop_effect(kind: str) -> Callable[[dict[str, Any]], None]:
    """Remove one effect and the draws of its fields (the later effects' draws renumbered)."""

    def change(cfg: dict[str, Any]) -> None:
        gone = _effect_index(cfg, kind)
        cfg["base"]["effects"].pop(gone)
        params = cfg.get("randomize", {}).get("params", {})
        moved: dict[str, Any] = {}
        for key, value in params.items():
            parts = key.split(".")
            if parts[0] == "effects":
                n = int(parts[1])
                if n == gone:
                    continue
                parts[1] = str(n - 1 if n > gone else n)
            moved[".".join(parts)] = value
        cfg["randomize"]["params"] = moved

    return change


def _no_draw(*names: str) -> Callable[[dict[str, Any]], None]:
    """Remove draws of the dataset and of every source (scene names or params paths)."""

    def change(cfg: dict[str, Any]) -> None:
        for table in [cfg.get("randomize", {})] + [
            s.get("randomize") or {} for s in cfg["sources"]
        ]:
            for name in names:
                table.pop(name, None)
                table.get("params", {}).pop(name, None)

    return change


def _middle(*names: str) -> Callable[[dict[str, Any]], None]:
    """Fix uniform draws of the dataset and of every source at the middle of their range (so a
    source keeps its own typical value: walks still walk away or toward, slowly)."""

    def change(cfg: dict[str, Any]) -> None:
        for table in [cfg.get("randomize", {})] + [
            s.get("randomize") or {} for s in cfg["sources"]
        ]:
            for name in names:
                if name in table:
                    lo, hi = table[name]["uniform"]
                    table[name] = {"uniform": [(lo + hi) / 2, (lo + hi) / 2]}

    return change


def _no_augmentation(cfg: dict[str, Any]) -> None:
    _middle("speed")(cfg)
    _no_draw("body_scale", "mirror", "time_warp")(cfg)


def _fixed_height(cfg: dict[str, Any]) -> None:
    _no_draw("radar_height")(cfg)
    cfg["base"]["scene"]["radar_position"][2] = 0.8


def _wide_elevation(cfg: dict[str, Any]) -> None:
    """The antenna's elevation beam 120 deg wide (azimuth still drawn)."""
    n = _effect_index(cfg, "antenna")
    cfg["randomize"]["params"].pop(f"effects.{n}.beamwidth_el_deg")
    cfg["base"]["effects"][n]["beamwidth_el_deg"] = 120.0


def _fixed_sensor(cfg: dict[str, Any]) -> None:
    """The preset's detection threshold and noise figure, one noise seed."""
    params = cfg["randomize"]["params"]
    for key in [k for k in params if k.startswith("radar.")]:
        params.pop(key)
    cfg["base"]["radar"]["noise_seed"] = 0  # else each record's own seed


def _source_draws_as(label: str, **draws: Any) -> Callable[[dict[str, Any]], None]:
    """Replace the given draws of every source of one activity (None: remove the draw, so the
    dataset's applies)."""

    def change(cfg: dict[str, Any]) -> None:
        for s in cfg["sources"]:
            if s.get("label") == label and "motion" in s:
                table = s.setdefault("randomize", {})
                for name, value in draws.items():
                    if value is None:
                        table.pop(name, None)
                    else:
                        table[name] = value

    return change


def _one_gate(cfg: dict[str, Any]) -> None:
    """The project before the sensor model: a 77 GHz pulse-Doppler radar, one range gate, the
    spectrogram and its features (no point clouds, so no histogram input)."""
    _drop_effect("static_scene")(cfg)
    cfg["representation"] = "spectrogram"
    cfg["base"]["radar"] = {"kind": "lfm", "carrier_frequency": 77e9, "prf": 6000.0}
    params = cfg["randomize"]["params"]
    for key in [k for k in params if k.startswith("radar.")]:
        params.pop(key)


#: variant name -> (what it changes, how)
VARIANTS: dict[str, tuple[str, Callable[[dict[str, Any]], None]]] = {
    "full": ("the shipped config", lambda cfg: None),
    "no_static_scene": ("no static reflectors (room)", _drop_effect("static_scene")),
    "wide_elevation_beam": ("elevation beam 120 deg instead of 20-60 deg", _wide_elevation),
    "fixed_aspect": ("aspect fixed at the middle of each source's range", _middle("aspect_deg")),
    "radar_at_0.8m": ("radar height fixed at 0.8 m", _fixed_height),
    "fixed_sensor": ("no CFAR threshold, noise figure or noise draws", _fixed_sensor),
    "no_augmentation": (
        "speed fixed at the middle of each source's range; no body-size, mirror or time-warp draws",
        _no_augmentation,
    ),
    "lively_jumps": (
        "jumps at the dataset's speeds (0.8-1.25) instead of 0.3-0.6",
        _source_draws_as("jump", speed=None),
    ),
    "one_gate_spectrogram": (
        "no sensor model and no room: 77 GHz one-gate spectrogram",
        _one_gate,
    ),
}


def _dataset(config: dict[str, Any], base: Path, out: Path, workers: int | None) -> Path:
    cfg = DatasetConfig.model_validate(config)
    build_dataset(cfg, base, out, workers=workers, progress=False)
    return out


def _inputs(path: Path, kind: str, group: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Input (n, n_columns), labels and recordings of one group's records."""
    exp = ExperimentConfig.model_validate(
        {"dataset": {"path": str(path)}, "input": kind, "selection": {"method": "none"}}
    )
    data, x, _ = classifier_inputs(exp, path)
    mask = data.groups == group
    return x[mask], data.labels[mask], data.table["file"][mask]


def _rates(y: np.ndarray, pred: np.ndarray, classes: list[str]) -> dict[str, float]:
    cm = confusion_matrix(y, pred, classes)
    return {c: float(cm[i, i]) for i, c in enumerate(classes)}


def real_to_real(path: Path, kind: str, clf: dict[str, Any], repeats: int) -> dict[str, Any]:
    """Held-out real recordings: mean and std over ``repeats`` splits."""
    x, y, files = _inputs(path, kind, REAL)
    classes = sorted(set(y.tolist()))
    factory = classifier_factory(clf, "bench")
    scores, rates = [], []
    for train, test in recording_splits(y, files, repeats, TEST_FRACTION, 0):
        pred = factory().fit(x[train], y[train]).predict(x[test])
        scores.append(balanced_accuracy(y[test], pred))
        rates.append(_rates(y[test], pred, classes))
    return {
        "mean": float(np.mean(scores)),
        "std": float(np.std(scores)),
        "per_class": {c: float(np.mean([r[c] for r in rates])) for c in classes},
    }


def sim_to_real(path: Path, kind: str, clf: dict[str, Any]) -> dict[str, Any] | None:
    """Train on every simulated record, test on every real record (None when the simulated
    records lack this input: histograms of a radar without point clouds)."""
    try:
        xs, ys, _ = _inputs(path, kind, SIM)
    except MdfError:
        return None
    xr, yr, _ = _inputs(path, kind, REAL)
    classes = sorted(set(yr.tolist()))
    pred = classifier_factory(clf, "bench")().fit(xs, ys).predict(xr)
    return {
        "score": balanced_accuracy(yr, pred),
        "per_class": _rates(yr, pred, classes),
        "confusion": confusion_matrix(yr, pred, classes).tolist(),
    }


def point_stats(path: Path, group: str) -> dict[str, dict[str, float]]:
    """Per class, over one group's records: points per frame within the histogram's range
    gate, moving points per frame (outside the 0 m/s bin) and the share of points at 0 m/s."""
    data = load_dataset(path, spectrograms=False, histograms=True)
    out = {}
    for label in sorted(set(data.labels.tolist())):
        pick = (data.labels == label) & (data.groups == group)
        hs = [h for h, p in zip(data.histograms or [], pick, strict=True) if p and h is not None]
        if not hs:  # records without point clouds (a one-gate spectrogram)
            continue
        h = np.concatenate(hs)
        centre = h.shape[1] // 2
        total = h.sum(axis=1)
        out[label] = {
            "points": float(total.mean()),
            "moving": float((total - h[:, centre]).mean()),
            "static_share": float(h[:, centre].sum() / max(total.sum(), 1.0)),
        }
    return out


def mean_histograms(path: Path, group: str) -> dict[str, np.ndarray]:
    """Per class, the mean over one group's records of the mean per-frame histogram shares
    (n_bins,)."""
    data = load_dataset(path, spectrograms=False, histograms=True)
    out = {}
    for label in sorted(set(data.labels.tolist())):
        pick = (data.labels == label) & (data.groups == group)
        hs = [h for h, p in zip(data.histograms or [], pick, strict=True) if p]
        vecs = []
        for h in hs:
            assert h is not None
            tot = h.sum(axis=1)
            live = tot > 0
            vecs.append((h[live] / tot[live, None]).mean(axis=0) if live.any() else 0 * h[0])
        out[label] = np.mean(vecs, axis=0)
    return out


def plot_histograms(path: Path, out: Path) -> None:
    """Mean per-frame histograms per class, real beside simulated (log scale), in the
    project's figure style."""
    from mdframework.figures import save, style

    r, s = mean_histograms(path, REAL), mean_histograms(path, SIM)
    velocity = load_dataset(path, spectrograms=False, histograms=True).velocity
    assert velocity is not None
    with style() as plt:
        fig, axes = plt.subplots(
            1, len(r), figsize=(4 * len(r), 3.4), sharey=True, layout="constrained"
        )
        for ax, label in zip(np.atleast_1d(axes), sorted(r), strict=True):
            w = 0.4 * (velocity[1] - velocity[0])
            ax.bar(velocity - w / 2, r[label], width=w, label="real (RadHAR)")
            ax.bar(velocity + w / 2, s.get(label, 0 * velocity), width=w, label="simulated")
            ax.set_yscale("log")
            ax.set_ylim(1e-4, 1.5)
            ax.set_title(label)
            ax.set_xlabel("radial velocity [m/s] (+ approaching)")
        np.atleast_1d(axes)[0].set_ylabel("mean share of a frame's points")
        np.atleast_1d(axes)[0].legend()
        caption = (
            f"dataset {path.name}: per class, the mean over records of each frame's share of "
            "points in each radial-velocity bin; real RadHAR recordings beside simulated records"
        )
        save(fig, out, caption)


def _summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Mean and population std over seeds of the scores, mean per-class rates and confusion."""
    return {
        "mean": float(np.mean([r["score"] for r in runs])),
        "std": float(np.std([r["score"] for r in runs])),
        "scores": [r["score"] for r in runs],
        "per_class": {
            c: float(np.mean([r["per_class"][c] for r in runs])) for c in runs[0]["per_class"]
        },
        "confusion": np.mean([r["confusion"] for r in runs], axis=0).tolist(),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=list(range(10)))
    parser.add_argument("--variants", default=",".join(VARIANTS))
    parser.add_argument("--classifiers", default=",".join(CLASSIFIERS))
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--repeats", type=int, default=10, help="real-to-real splits")
    parser.add_argument("--out", type=Path, default=Path("out/bench_sim2real"))
    parser.add_argument(
        "--docs",
        action="store_true",
        help=f"also copy results.json and the figure to {DOCS_RESULTS.relative_to(ROOT)} and "
        f"{DOCS_FIGURE.relative_to(ROOT)} (the numbers of docs/sim-to-real.md)",
    )
    args = parser.parse_args()
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    clock = time.perf_counter()
    base = read_config_file(CONFIG)
    classifiers = {k: CLASSIFIERS[k] for k in args.classifiers.split(",")}
    results: dict[str, Any] = {
        "command": "benchmarks/bench_sim2real.py " + " ".join(sys.argv[1:]),
        "seeds": args.seeds,
        "repeats": args.repeats,
        "load_average_start": list(os.getloadavg()),
        "real_to_real": {},
        "sim_to_real": {},
        "build_s": {},
    }
    for variant in args.variants.split(","):
        what, change = VARIANTS[variant]
        per: dict[str, list[dict[str, Any]]] = {}
        stats: list[dict[str, dict[str, float]]] = []
        results["build_s"][variant] = []
        for seed in args.seeds:
            cfg = copy.deepcopy(base)
            change(cfg)
            cfg["seed"] = seed
            tick = time.perf_counter()
            folder = out / f"{variant}_{seed}"
            before = {p.name for p in (folder / "records").glob("*.npz")}
            path = _dataset(cfg, CONFIG.parent, folder, args.workers)
            # a dataset complete in --out from the same command is reused, not timed; one
            # whose records changed (another version's seeds or code) is rebuilt and timed
            if {p.name for p in (folder / "records").glob("*.npz")} - before:
                results["build_s"][variant].append(time.perf_counter() - tick)
            for name, clf in classifiers.items():  # the same real records in every dataset
                for kind in INPUTS:
                    key = f"{name}/{kind}"
                    if key not in results["real_to_real"]:
                        try:
                            results["real_to_real"][key] = real_to_real(
                                path, kind, clf, args.repeats
                            )
                        except MdfError:  # simulated records without histograms
                            pass
            if variant == "full" and seed == args.seeds[0]:
                plot_histograms(path, out / "histograms.png")
            if "points" not in results:
                results["points"] = {"real": point_stats(path, REAL)}
            stats.append(point_stats(path, SIM))
            for name, clf in classifiers.items():
                for kind in INPUTS:
                    res = sim_to_real(path, kind, clf)
                    if res is not None:
                        per.setdefault(f"{name}/{kind}", []).append(res)
            print(
                time.strftime("%H:%M:%S ")
                + f"{variant} seed {seed}: "
                + ", ".join(f"{k} {v[-1]['score']:.3f}" for k, v in per.items()),
                flush=True,
            )
        results["sim_to_real"][variant] = {
            "what": what,
            **{key: _summary(runs) for key, runs in per.items()},
        }
        if stats[0]:
            results["points"][variant] = {
                label: {q: float(np.mean([st[label][q] for st in stats])) for q in stats[0][label]}
                for label in stats[0]
            }
        (out / "partial.json").write_text(json.dumps(results, indent=2) + "\n")
    results["wall_s"] = time.perf_counter() - clock
    results["load_average_end"] = list(os.getloadavg())
    (out / "results.json").write_text(json.dumps(results, indent=2) + "\n")
    (out / "results.md").write_text(markdown(results))
    if args.docs:
        DOCS_RESULTS.parent.mkdir(parents=True, exist_ok=True)
        DOCS_RESULTS.write_text(json.dumps(results, indent=2) + "\n")
        if (out / "histograms.png").exists():
            shutil.copyfile(out / "histograms.png", DOCS_FIGURE)
    print(markdown(results))


def goal(results: dict[str, Any]) -> dict[str, bool]:
    """Per input/classifier: is the goal met by ``full``, its mean balanced accuracy on the real
    recordings at least 0.80 and at most 10 points below the real-to-real mean?"""
    full = results["sim_to_real"].get("full", {})
    return {
        k: full[k]["mean"] >= 0.80 and ref["mean"] - full[k]["mean"] <= 0.10
        for k, ref in results["real_to_real"].items()
        if k in full
    }


def _bound(results: dict[str, Any], key: str) -> float:
    """The goal's bound for one input/classifier: the larger of 0.80 and 10 points below the
    real-to-real mean."""
    return max(0.80, results["real_to_real"][key]["mean"] - 0.10)


def _standard_error(values: list[float]) -> float | None:
    """Standard error of the mean of independent values (sample std / sqrt(n)); None for
    fewer than two."""
    if len(values) < 2:
        return None
    return float(np.std(values, ddof=1) / np.sqrt(len(values)))


def goal_margins(results: dict[str, Any]) -> dict[str, tuple[float, float | None]]:
    """Per input/classifier: by how much ``full``'s mean clears the goal's bound (negative: it
    misses it) and the standard error of that mean over the seeds, both in points of balanced
    accuracy (the real-to-real mean is taken as exact: its splits share recordings)."""
    full = results["sim_to_real"].get("full", {})
    out = {}
    for k in results["real_to_real"]:
        if k in full:
            se = _standard_error(full[k]["scores"])
            out[k] = (
                100 * (full[k]["mean"] - _bound(results, k)),
                None if se is None else 100 * se,
            )
    return out


def _points(value: float, se: float | None) -> str:
    """A difference in points with its standard error: '+1.4 ± 1.3' ('+1.4' without one)."""
    return f"{value:+.1f}" + ("" if se is None else f" ± {se:.1f}")


def margins_line(results: dict[str, Any]) -> str:
    """One sentence: each goal margin with its standard error over the seeds."""
    margins = goal_margins(results)
    cells = ", ".join(f"`{k}` {_points(m, se)}" for k, (m, se) in margins.items())
    return (
        "Margin to the goal (the simulated mean minus the larger of 0.80 and real-to-real minus "
        "10 points, in points; ± the standard error of the mean over the seeds): "
        f"{cells}."
    )


def paired_difference(runs: dict[str, Any], full: dict[str, Any]) -> tuple[float, float | None]:
    """A variant's difference to ``full`` in points: the mean over seeds of each seed's
    difference (the variants of one seed share most of their draws: the record seeds, places
    and aspects, as far as the variant leaves them), and its standard error over the seeds."""
    diffs = [100 * (a - b) for a, b in zip(runs["scores"], full["scores"], strict=True)]
    return float(np.mean(diffs)), _standard_error(diffs)


def goal_line(results: dict[str, Any]) -> str:
    """One sentence: for which inputs and classifiers the goal is met."""
    met = goal(results)
    yes = [f"`{k}`" for k, v in met.items() if v]
    no = [f"`{k}`" for k, v in met.items() if not v]
    return (
        "Goal (at least 0.80, and at most 10 points below real-to-real): "
        f"met for {', '.join(yes) or 'none'}; not met for {', '.join(no) or 'none'}."
    )


def _table(caption: str, columns: list[str]) -> list[str]:
    """A blank line, the caption, a blank line and a Markdown table's head."""
    return ["", caption, "", "| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]


def _cell(res: dict[str, Any] | None) -> str:
    return "" if res is None else f"{res['mean']:.3f} ± {res['std']:.3f}"


def markdown(results: dict[str, Any]) -> str:
    """The tables of docs/sim-to-real.md: the result, the ablation (every variant, mean ± std
    over the seeds) and the per-class rates."""
    keys = list(results["real_to_real"])
    seeds = results["seeds"]
    head = ["| training data | " + " | ".join(keys) + " |", "|---|" + "---|" * len(keys)]
    full = results["sim_to_real"].get("full", {})
    lines = [
        f"Balanced accuracy on the real recordings; simulated: mean ± std over dataset seeds "
        f"{', '.join(map(str, seeds))}; real-to-real: mean ± std over {results['repeats']} "
        f"splits holding out {recordings_held_out(REAL_RECORDINGS, TEST_FRACTION)} of the "
        f"{REAL_RECORDINGS} recordings of every class.",
        "",
        *head,
        "| real (held-out recordings) | "
        + " | ".join(_cell(results["real_to_real"][k]) for k in keys)
        + " |",
        "| simulated (`full`) | " + " | ".join(_cell(full.get(k)) for k in keys) + " |",
        "",
        goal_line(results),
        "",
        margins_line(results),
        *_table(
            "Ablation: each variant changes one modelling choice of the shipped config (mean ± "
            "std over the same seeds; in brackets: the difference to `full` in points of "
            "balanced accuracy, taken seed by seed since the variants of one seed share most of "
            "their draws, ± its standard error over the seeds).",
            ["variant", "what it changes", *keys],
        ),
    ]
    for variant, res in results["sim_to_real"].items():
        cells = []
        for k in keys:
            if k not in res:
                cells.append("(no histograms)" if k.endswith("histogram") else "")
                continue
            extra = ""
            if variant != "full" and k in full:
                extra = f" ({_points(*paired_difference(res[k], full[k]))})"
            cells.append(_cell(res[k]) + extra)
        lines.append(f"| `{variant}` | {res['what']} | " + " | ".join(cells) + " |")
    lines += _table(
        "Per-class rates (boxing / jump / walk), simulated `full` (mean over seeds) and "
        "real-to-real:",
        ["input", "simulated `full`", "real-to-real"],
    )
    for k in keys:
        sim = full.get(k)
        ref = results["real_to_real"][k]["per_class"]
        sim_cell = " / ".join(f"{v:.2f}" for v in sim["per_class"].values()) if sim else ""
        lines.append(f"| {k} | {sim_cell} | " + " / ".join(f"{v:.2f}" for v in ref.values()) + " |")
    shown = [v for v in ("real", "full", "lively_jumps") if v in results.get("points", {})]
    if shown:
        lines += _table(
            "Points per frame within 0.5-3 m: all / moving (outside the 0 m/s bin) / share at "
            "0 m/s; simulated: mean over the seeds.",
            ["activity", *shown],
        )
        for label in results["points"]["real"]:
            cells = []
            for v in shown:
                st = results["points"][v].get(label)
                cells.append(
                    f"{st['points']:.1f} / {st['moving']:.2f} / {st['static_share']:.2f}"
                    if st
                    else ""
                )
            lines.append(f"| {label} | " + " | ".join(cells) + " |")
    builds = [t for ts in results["build_s"].values() for t in ts]
    n_sets = len(results["sim_to_real"]) * len(seeds)
    timing = (
        f"{len(builds)} of the {n_sets} datasets built in this run, median "
        f"{np.median(builds):.0f} s each (the others were complete in --out from an "
        "earlier run of the same command and were reused); "
        if builds and len(builds) < n_sets
        else f"{len(builds)} datasets built, median {np.median(builds):.0f} s each; "
        if builds
        else f"all {n_sets} datasets reused from an earlier run of the same command; "
    )
    lines += [
        "",
        timing + f"{results['wall_s'] / 60:.0f} min in all; load average (5 min) "
        f"{results['load_average_start'][1]:.1f} at the start, "
        f"{results['load_average_end'][1]:.1f} at the end (2 cores shared).",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
