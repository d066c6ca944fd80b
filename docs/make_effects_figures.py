"""Figures of docs/effects.md: the Boulic walk's spectrogram without effects, with ground
clutter plus receiver noise, with ground-bounce multipath, and on a treadmill.

.venv/bin/python docs/make_effects_figures.py
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from mdframework.config import read_config_file, validate_run_config
from mdframework.pipeline import simulate

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"

PANELS: list[tuple[str, dict[str, Any]]] = [
    ("no effects", {}),
    (
        "noise (SNR 20 dB) + clutter (CSR 0 dB, 30 % wind, 0.2 m/s)",
        {
            "effects": [
                {"kind": "noise", "snr_db": 20.0},
                {"kind": "clutter", "csr_db": 0.0, "wind_fraction": 0.3, "spread_mps": 0.2},
            ]
        },
    ),
    ("multipath (|Gamma| = 0.6, 180 deg)", {"effects": [{"kind": "multipath"}]}),
    ("treadmill (no translation)", {"scene": {"person": {"motion": "treadmill"}}}),
]


def main() -> None:
    base = read_config_file(ROOT / "examples" / "boulic_walk.toml")
    base["scatterers"] = {"kind": "ellipsoid"}
    fig, axes = plt.subplots(1, len(PANELS), figsize=(4.2 * len(PANELS), 3.6), sharey=True)
    for ax, (title, change) in zip(axes, PANELS, strict=True):
        cfg = copy.deepcopy(base)
        for key, value in change.items():
            cfg[key] = {**cfg.get(key, {}), **value} if key == "scene" else value
        if "scene" in change:
            cfg["scene"]["person"] = {**base["scene"]["person"], **change["scene"]["person"]}
        res = simulate(validate_run_config(cfg, base_dir=ROOT / "examples"))
        ax.pcolormesh(
            res.spectrogram.time,
            res.velocity,
            res.spectrogram_db,
            vmin=-50,
            vmax=0,
            shading="auto",
            cmap="jet",
        )
        ax.set_ylim(-3, 5)
        ax.set_title(title, fontsize=8)
        ax.set_xlabel("time [s]")
    axes[0].set_ylabel("radial velocity [m/s] (+ approaching)")
    fig.tight_layout()
    FIGURES.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURES / "effects_spectrograms.png", dpi=110)
    print(FIGURES / "effects_spectrograms.png")


if __name__ == "__main__":
    main()
