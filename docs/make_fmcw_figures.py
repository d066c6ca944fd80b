"""Figures of docs/fmcw.md: the range-Doppler map and the point cloud that
``mdf run examples/fmcw_walk.toml`` draws (the 77 GHz walk's frame with the most points, with the
run's title and caption) and the LFM and FMCW spectrograms of the same walk side by side
(``examples/walk_side_by_side_{lfm,fmcw}.toml``).

    .venv/bin/python docs/make_fmcw_figures.py
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from mdframework import cli
from mdframework.config import load_run_config
from mdframework.figures import plot_spectrogram_panels
from mdframework.output import result_arrays
from mdframework.pipeline import simulate

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"
SIDE_BY_SIDE_CAPTION = (
    "cmu 02_01.amc (walk), 2.5 s: 15 GHz band centre, 150 MHz, slow time 2400 Hz, amplitudes "
    "sqrt(rcs); radar at (10, 0, 2) m; aspect 0°; scatterers ellipsoid joints17; effects: none"
)


def main(figures: Path = FIGURES) -> None:
    """Run the three examples and save the figures into ``figures`` (docs/figures by default)."""
    figures.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "fmcw_walk"
        if cli.main(["run", str(ROOT / "examples" / "fmcw_walk.toml"), "--out", str(out)]) != 0:
            raise SystemExit(1)
        shutil.copyfile(out / "range_doppler.png", figures / "fmcw_walk_range_doppler.png")
        shutil.copyfile(out / "point_cloud.png", figures / "fmcw_walk_point_cloud.png")
    panels = []
    for name, label in (("lfm", "LFM pulse-Doppler"), ("fmcw", "chirp-sequence FMCW")):
        run = result_arrays(
            simulate(load_run_config(ROOT / "examples" / f"walk_side_by_side_{name}.toml"))
        )
        panels.append((run["spectrogram_db"], run["time_s"], run["velocity_mps"], label))
    plot_spectrogram_panels(
        figures / "fmcw_lfm_side_by_side.png", panels, caption=SIDE_BY_SIDE_CAPTION
    )


if __name__ == "__main__":
    main()
