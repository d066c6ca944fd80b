"""Make the figures and the feature table of ``docs/validation.md``.

Boulic walker (corrected and Chen-compatible) and CMU trial 02_01 walking toward the same radar
(15 GHz, at (10, 0, 2) m, aspect 0), same processing, and the seven features of the paper's
Table 2 (``mdframework.features`` with its defaults) printed as a Markdown table.

    .venv/bin/python docs/make_validation_figures.py
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mdframework.config import load_run_config, validate_run_config
from mdframework.features import FEATURE_NAMES, spectrogram_features
from mdframework.figures import draw_spectrogram, save, style
from mdframework.pipeline import RunResult, simulate

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
FIGURES = ROOT / "docs" / "figures"
DURATION = 4.0
CAPTION = (
    "lfm 15 GHz, PRF 2400 Hz; radar at (10, 0, 2) m; aspect 0° (walking toward the radar); "
    "scatterers: Boulic mujoco_body chen16, CMU and Kinect ellipsoid joints17; effects: none"
)


def boulic(chen: bool) -> RunResult:
    cfg: dict[str, Any] = {
        "motion": {
            "kind": "boulic", "height": 1.8, "rv": 1.0, "duration": DURATION,
            "chen_compatible": chen,
        },
        "scatterers": {"kind": "mujoco_body", "placement": "chen16"},
        "radar": {"kind": "lfm"},
        "scene": {"radar_position": [10.0, 0.0, 2.0], "person": {"aspect_deg": 0.0}},
    }  # fmt: skip
    return simulate(validate_run_config(cfg))


def cmu() -> RunResult:
    return simulate(load_run_config(EXAMPLES / "cmu_walk.toml"))


def kinect() -> RunResult:
    """The UTKinect walk (conditioned) seen from the same radar and aspect as the others."""
    import tomllib

    cfg = tomllib.loads((EXAMPLES / "kinect_utkinect_walk.toml").read_text())
    cfg["scene"] = {"radar_position": [10.0, 0.0, 2.0], "person": {"aspect_deg": 0.0}}
    return simulate(validate_run_config(cfg, base_dir=EXAMPLES))


def features(res: RunResult) -> dict[str, float]:
    """The seven Table 2 features [m/s] of a run."""
    values = spectrogram_features(res.spectrogram.power, res.velocity)
    return {name: float(v) for name, v in zip(FEATURE_NAMES, values, strict=True)}


def main(figures: Path = FIGURES) -> None:
    """Write the figure into ``figures`` (docs/figures by default) and print the table."""
    figures.mkdir(parents=True, exist_ok=True)
    runs = {
        "Boulic (corrected)": boulic(False),
        "Boulic (chen_compatible)": boulic(True),
        "CMU 02_01 walk": cmu(),
        "Kinect UTKinect walk": kinect(),
    }
    out = figures / "validation_walk_spectrograms.png"
    with style() as plt:
        fig, axes = plt.subplots(1, len(runs), figsize=(19, 4.2), sharey=True, layout="constrained")
        image = None
        for ax, (name, res) in zip(axes, runs.items(), strict=True):
            t = res.spectrogram.time
            image = draw_spectrogram(ax, res.spectrogram_db, t, res.velocity, velocity_span="full")
            ax.set_title(name)
            ax.set_xlim(0, min(DURATION, float(t[-1])))
            ax.set_ylim(-3, 6)
            if ax is not axes[0]:
                ax.set_ylabel("")
        fig.colorbar(image, ax=axes, label="power [dB re peak]")
        save(fig, out, CAPTION)
    print(f"wrote {out}")
    print()
    print("| source | " + " | ".join(FEATURE_NAMES) + " |")
    print("|---" * (len(FEATURE_NAMES) + 1) + "|")
    for name, res in runs.items():
        f = features(res)
        print(f"| {name} | " + " | ".join(f"{f[k]:.3f}" for k in FEATURE_NAMES) + " |")


if __name__ == "__main__":
    main()
