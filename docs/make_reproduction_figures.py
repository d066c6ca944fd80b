"""Run the two paper experiments on the shipped data and copy their figures into docs/figures.

.venv/bin/python docs/make_reproduction_figures.py      (about a minute)
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from mdframework.cli import main

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"

COPIES = {
    "experiment_cmu": {
        "within_cmu_confusion.png": "repro_cmu_confusion.png",
        "scatter_torso_mean_upper_max.png": "repro_cmu_scatter.png",
    },
    "experiment_cross_source": {
        "cross_confusion.png": "repro_cross_confusion.png",
        "within_kinect_confusion.png": "repro_kinect_confusion.png",
        "scatter_torso_mean_upper_max.png": "repro_cross_scatter.png",
    },
}

if __name__ == "__main__":
    FIGURES.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for name, files in COPIES.items():
            out = Path(tmp) / name
            code = main(
                [
                    "experiment",
                    str(ROOT / "examples" / f"{name}.toml"),
                    "--out",
                    str(out),
                    "--no-progress",
                ]
            )
            if code != 0:
                raise SystemExit(code)
            for src, dst in files.items():
                shutil.copyfile(out / src, FIGURES / dst)
            shutil.copyfile(out / "report.md", Path(tmp) / f"{name}.md")
            print((Path(tmp) / f"{name}.md").read_text())
