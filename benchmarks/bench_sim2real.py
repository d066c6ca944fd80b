"""Trained on simulation, tested on real radar: the sim-to-real result and its ablation.

The data: ``examples/datasets/sim2real.toml``, group ``radhar``: the shipped RadHAR recordings
(12 recordings per activity, boxing, jump, walk, 2 s records of per-frame Doppler histograms);
group ``sim``: CMU motions through the FMCW sensor model with the IWR1443 preset, point clouds,
per-record random draws. It is built once per seed and per ablation variant, each variant
changing one modelling choice of that config (the real records are the same in all).

The ``full`` variant is built for every seed, the other variants for the first seed only.
For every variant, seed, classifier input (the seven features, the histogram vector) and
classifier, a classifier is trained on ALL simulated records and tested on ALL real records:
balanced accuracy and per-class rates. The real-to-real reference uses the same input and
classifier, trained on real recordings and tested on held-out real recordings (10 random splits
holding out 40 % of the recordings of every class).

    .venv/bin/python benchmarks/bench_sim2real.py [--seeds 0 1 2] [--variants full,...]
        [--workers N] [--out out/bench_sim2real]

Writes ``results.json`` and ``results.md`` (the tables of ``docs/sim-to-real.md``) and
``histograms.png`` (mean real and simulated per-frame histograms per class) under ``--out``.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import copy  # noqa: E402
import json  # noqa: E402
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
)

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "examples" / "datasets" / "sim2real.toml"
SIM, REAL = "sim", "radhar"
CLASSIFIERS: dict[str, dict[str, Any]] = {
    "knn": {"kind": "knn", "k": 5},
    "forest": {
        "kind": "sklearn",
        "estimator": "sklearn.ensemble.RandomForestClassifier",
        "params": {"n_estimators": 200, "random_state": 0},
    },
}
INPUTS = ("features", "histogram")


def _drop_effect(kind: str) -> Callable[[dict[str, Any]], None]:
    def change(cfg: dict[str, Any]) -> None:
        effects = cfg["base"].get("effects", [])
        cfg["base"]["effects"] = [e for e in effects if e.get("kind") != kind]

    return change


def _no_draw(*names: str) -> Callable[[dict[str, Any]], None]:
    def change(cfg: dict[str, Any]) -> None:
        for table in [cfg.get("randomize", {})] + [
            s.get("randomize") or {} for s in cfg["sources"]
        ]:
            for name in names:
                table.pop(name, None)
                table.get("params", {}).pop(name, None)

    return change


def _fixed_height(cfg: dict[str, Any]) -> None:
    _no_draw("radar_height")(cfg)
    cfg["base"]["scene"]["radar_position"][2] = 0.8


def _one_gate(cfg: dict[str, Any]) -> None:
    """The project before the sensor model: a 77 GHz pulse-Doppler radar, one range gate, the
    spectrogram and its features (no point clouds, so no histogram input)."""
    cfg["representation"] = "spectrogram"
    cfg["base"]["radar"] = {"kind": "lfm", "carrier_frequency": 77e9, "prf": 6000.0}
    cfg["base"]["effects"] = [e for e in cfg["base"]["effects"] if e["kind"] == "antenna"]
    params = cfg["randomize"]["params"]
    for key in list(params):
        if not key.startswith("effects.1."):
            params.pop(key)
    cfg["randomize"]["params"] = {
        k.replace("effects.1.", "effects.0."): v for k, v in params.items()
    }


#: variant name -> (what it changes, how)
VARIANTS: dict[str, tuple[str, Callable[[dict[str, Any]], None]]] = {
    "full": ("the shipped config", lambda cfg: None),
    "no_static_scene": ("no static reflectors (room)", _drop_effect("static_scene")),
    "no_augmentation": (
        "no speed, body-size, mirror or time-warp augmentation",
        _no_draw("speed", "body_scale", "mirror", "time_warp"),
    ),
    "fixed_aspect": ("aspect fixed at the base scene's", _no_draw("aspect_deg")),
    "radar_at_0.8m": ("radar height fixed at 0.8 m", _fixed_height),
    "one_gate_spectrogram": ("no sensor model: 77 GHz one-gate spectrogram", _one_gate),
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
    for train, test in recording_splits(y, files, repeats, 0.4, 0):
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--variants", default=",".join(VARIANTS))
    parser.add_argument("--classifiers", default=",".join(CLASSIFIERS))
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--repeats", type=int, default=10, help="real-to-real splits")
    parser.add_argument("--out", type=Path, default=Path("out/bench_sim2real"))
    args = parser.parse_args()
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    clock = time.perf_counter()
    base = read_config_file(CONFIG)
    classifiers = {k: CLASSIFIERS[k] for k in args.classifiers.split(",")}
    results: dict[str, Any] = {"real_to_real": {}, "sim_to_real": {}, "seeds": args.seeds}
    for variant in args.variants.split(","):
        what, change = VARIANTS[variant]
        per: dict[str, list[dict[str, Any]]] = {}
        for seed in args.seeds if variant == "full" else args.seeds[:1]:
            cfg = copy.deepcopy(base)
            change(cfg)
            cfg["seed"] = seed
            path = _dataset(cfg, CONFIG.parent, out / f"{variant}_{seed}", args.workers)
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
            for name, clf in classifiers.items():
                for kind in INPUTS:
                    res = sim_to_real(path, kind, clf)
                    if res is not None:
                        per.setdefault(f"{name}/{kind}", []).append(res)
        results["sim_to_real"][variant] = {
            "what": what,
            **{
                key: {
                    "mean": float(np.mean([r["score"] for r in runs])),
                    "std": float(np.std([r["score"] for r in runs])),
                    "scores": [r["score"] for r in runs],
                    "per_class": {
                        c: float(np.mean([r["per_class"][c] for r in runs]))
                        for c in runs[0]["per_class"]
                    },
                    "confusion": np.mean([r["confusion"] for r in runs], axis=0).tolist(),
                }
                for key, runs in per.items()
            },
        }
    results["wall_s"] = time.perf_counter() - clock
    (out / "results.json").write_text(json.dumps(results, indent=2) + "\n")
    (out / "results.md").write_text(markdown(results))
    print(markdown(results))


def markdown(results: dict[str, Any]) -> str:
    """The result tables: real-to-real, then every variant, mean +- std over seeds."""
    keys = list(results["real_to_real"])
    lines = [
        f"Balanced accuracy on the real recordings, mean ± std over seeds {results['seeds']} "
        "(other variants: the first seed; real-to-real: over 10 held-out-recording splits).",
        "",
        "| training data | " + " | ".join(keys) + " |",
        "|---|" + "---|" * len(keys),
        "| real (held-out recordings) | "
        + " | ".join(
            f"{results['real_to_real'][k]['mean']:.3f} ± {results['real_to_real'][k]['std']:.3f}"
            for k in keys
        )
        + " |",
    ]
    for variant, res in results["sim_to_real"].items():
        cells = [f"{res[k]['mean']:.3f} ± {res[k]['std']:.3f}" if k in res else "" for k in keys]
        lines.append(f"| simulated: {variant} ({res['what']}) | " + " | ".join(cells) + " |")
    lines += ["", "Per-class rates (boxing / jump / walk), simulated `full` and real-to-real:", ""]
    lines += ["| input | simulated full | real-to-real |", "|---|---|---|"]
    for k in keys:
        full = results["sim_to_real"].get("full", {}).get(k)
        ref = results["real_to_real"][k]["per_class"]
        sim_cell = " / ".join(f"{v:.2f}" for v in full["per_class"].values()) if full else ""
        lines.append(f"| {k} | {sim_cell} | " + " / ".join(f"{v:.2f}" for v in ref.values()) + " |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
