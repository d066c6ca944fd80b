"""Figures of docs/effects.md: the Boulic walk's spectrogram without effects, with ground
clutter plus receiver noise, with ground-bounce multipath, and on a treadmill.

.venv/bin/python docs/make_effects_figures.py
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

from mdframework.config import read_config_file, validate_run_config
from mdframework.figures import draw_spectrogram, save, style
from mdframework.pipeline import simulate

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"

CAPTION = (
    "Boulic walker (examples/boulic_walk.toml, ellipsoid scatterers): lfm 15 GHz, PRF 2400 Hz; "
    "radar at (10, 0, 2) m; aspect 0°; effects as titled"
)

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


def main(figures: Path = FIGURES) -> None:
    """Write the figure into ``figures`` (docs/figures by default)."""
    base = read_config_file(ROOT / "examples" / "boulic_walk.toml")
    base["scatterers"] = {"kind": "ellipsoid"}
    with style() as plt:
        fig, axes = plt.subplots(
            1, len(PANELS), figsize=(4.2 * len(PANELS), 3.8), sharey=True, layout="constrained"
        )
        draw(axes, base)
        figures.mkdir(parents=True, exist_ok=True)
        save(fig, figures / "effects_spectrograms.png", CAPTION)
    print(figures / "effects_spectrograms.png")


def draw(axes: Any, base: dict[str, Any]) -> None:
    """One panel per entry of PANELS."""
    image = None
    for ax, (title, change) in zip(axes, PANELS, strict=True):
        cfg = copy.deepcopy(base)
        for key, value in change.items():
            cfg[key] = {**cfg.get(key, {}), **value} if key == "scene" else value
        if "scene" in change:
            cfg["scene"]["person"] = {**base["scene"]["person"], **change["scene"]["person"]}
        res = simulate(validate_run_config(cfg, base_dir=ROOT / "examples"))
        image = draw_spectrogram(ax, res.spectrogram_db, res.spectrogram.time, res.velocity)
        ax.set_ylim(-3, 5)
        ax.set_title(title, fontsize=8)
        if ax is not axes[0]:
            ax.set_ylabel("")
    axes[-1].figure.colorbar(image, ax=axes, label="power [dB re peak]")


if __name__ == "__main__":
    main()
