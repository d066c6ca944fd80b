"""Figures of docs/figures.md: `mdf show` on the CMU walk, its stills and one animation frame.

.venv/bin/python docs/make_preview_figures.py
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from PIL import Image

from mdframework import cli

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"
FRAME = 8  # the animation frame shown: 8 / FPS = 1.33 s from the record's start
FPS = 6


def main(figures: Path = FIGURES) -> None:
    """Write the figures into ``figures`` (docs/figures by default)."""
    figures.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "walk"
        config = str(ROOT / "examples" / "cmu_walk.toml")
        argv = ["show", config, "--out", str(out), "--fps", str(FPS), "--at", "0.5", "1.4", "2.3"]
        if cli.main(argv) != 0:
            raise SystemExit(1)
        shutil.copyfile(out / "skeleton.png", figures / "cmu_walk_skeleton.png")
        with Image.open(out / "motion.gif") as gif:
            gif.seek(FRAME)
            gif.convert("RGB").save(figures / "cmu_walk_preview_frame.png")
    print(figures / "cmu_walk_skeleton.png", figures / "cmu_walk_preview_frame.png")


if __name__ == "__main__":
    main()
