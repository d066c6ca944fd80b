"""Regenerate the figures of the concepts and motion-formats pages from the shipped examples.

.venv/bin/python docs/make_figures.py
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from mdframework import cli

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"


def run_example(name: str, figure: str, target: str, figures: Path = FIGURES) -> None:
    """Run ``examples/<name>.toml`` and copy one of its figures into ``figures``."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / name
        code = cli.main(["run", str(ROOT / "examples" / f"{name}.toml"), "--out", str(out)])
        if code != 0:
            raise SystemExit(code)
        shutil.copyfile(out / figure, figures / target)


def main(figures: Path = FIGURES) -> None:
    """Write the figures into ``figures`` (docs/figures by default)."""
    figures.mkdir(parents=True, exist_ok=True)
    run_example("cmu_walk", "spectrogram.png", "cmu_walk_spectrogram.png", figures)
    run_example("cmu_walk_raw", "range_time.png", "cmu_walk_range_time.png", figures)
    run_example("deepmimic_walk", "spectrogram.png", "deepmimic_walk_spectrogram.png", figures)
    run_example("trc_walk", "spectrogram.png", "trc_walk_spectrogram.png", figures)


if __name__ == "__main__":
    main()
