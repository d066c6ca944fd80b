"""Draw the LFM and FMCW spectrograms of the same walk next to each other.

Run after ``mdf run examples/walk_side_by_side_lfm.toml --out OUT/walk_side_by_side_lfm`` and the
same for ``walk_side_by_side_fmcw`` (``make demo`` does both):

    .venv/bin/python examples/side_by_side.py OUT

writes ``OUT/walk_side_by_side.png``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from mdframework.figures import plot_spectrogram_panels


def main(out: Path) -> Path:
    """Read both runs' ``result.npz`` under ``out`` and save the figure; returns its path."""
    panels = []
    for name, title in (("lfm", "LFM pulse-Doppler"), ("fmcw", "chirp-sequence FMCW")):
        with np.load(out / f"walk_side_by_side_{name}" / "result.npz") as r:
            panels.append((r["spectrogram_db"], r["time_s"], r["velocity_mps"], title))
    path = out / "walk_side_by_side.png"
    plot_spectrogram_panels(path, panels)
    return path


if __name__ == "__main__":
    print(main(Path(sys.argv[1] if len(sys.argv) > 1 else "out/demo")))
