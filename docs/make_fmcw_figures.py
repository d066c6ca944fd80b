"""Figures of docs/fmcw.md: a range-Doppler frame and a point-cloud frame of the 77 GHz walk
(``examples/fmcw_walk.toml``) and the LFM and FMCW spectrograms of the same walk side by side
(``examples/walk_side_by_side_{lfm,fmcw}.toml``).

    .venv/bin/python docs/make_fmcw_figures.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mdframework.config import load_run_config
from mdframework.figures import plot_point_cloud, plot_range_doppler, plot_spectrogram_panels
from mdframework.output import result_arrays
from mdframework.pipeline import simulate

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"


def main(figures: Path = FIGURES) -> None:
    """Run the three examples and save the figures into ``figures`` (docs/figures by default)."""
    walk = result_arrays(simulate(load_run_config(ROOT / "examples" / "fmcw_walk.toml")))
    points = walk["points"]
    frame = int(np.argmax(np.bincount(points[:, 0].astype(np.int64))))
    title = f"CMU walk, IWR1443 preset, frame {frame}"
    plot_range_doppler(
        figures / "fmcw_walk_range_doppler.png",
        walk["range_doppler"][frame],
        walk["range_doppler_range_m"],
        walk["range_doppler_velocity_mps"],
        title=title,
    )
    plot_point_cloud(
        figures / "fmcw_walk_point_cloud.png", points[points[:, 0] == frame], title=title
    )
    panels = []
    for name, label in (("lfm", "LFM pulse-Doppler"), ("fmcw", "chirp-sequence FMCW")):
        run = result_arrays(
            simulate(load_run_config(ROOT / "examples" / f"walk_side_by_side_{name}.toml"))
        )
        panels.append((run["spectrogram_db"], run["time_s"], run["velocity_mps"], label))
    plot_spectrogram_panels(figures / "fmcw_lfm_side_by_side.png", panels)


if __name__ == "__main__":
    main()
