"""Run the two paper experiments on the shipped data and copy their figures into docs/figures;
then the CMU experiment holding out whole recordings (``split = "recording"``) on the CMU dataset
without its jump class, which has one recording only. Prints the three reports.

.venv/bin/python docs/make_reproduction_figures.py      (about two minutes)
"""

from __future__ import annotations

import json
import shutil
import tempfile
import tomllib
from pathlib import Path

from mdframework import cli

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


def held_out_recordings(tmp: Path) -> str:
    """The report of the CMU experiment with whole recordings held out, on the shipped CMU
    dataset less its jump source (walk, run and boxing have two recordings each)."""
    datasets = ROOT / "examples" / "datasets"
    dataset = tomllib.loads((datasets / "cmu.toml").read_text())
    dataset["sources"] = [s for s in dataset["sources"] if s["label"] != "jump"]
    del dataset["record_lengths"]["jump"]
    for source in dataset["sources"]:
        source["motion"]["file"] = str((datasets / source["motion"]["file"]).resolve())
    (tmp / "cmu_no_jump.json").write_text(json.dumps(dataset))
    experiment = tomllib.loads((ROOT / "examples" / "experiment_cmu.toml").read_text())
    experiment["dataset"]["config"] = str(tmp / "cmu_no_jump.json")
    experiment["evaluation"]["split"] = "recording"
    (tmp / "held_out.json").write_text(json.dumps(experiment))
    out = tmp / "held_out"
    code = cli.main(["experiment", str(tmp / "held_out.json"), "--out", str(out), "--no-progress"])
    if code != 0:
        raise SystemExit(code)
    return (out / "report.md").read_text()


def main(figures: Path = FIGURES) -> None:
    """Copy the figures into ``figures`` (docs/figures by default); print the reports."""
    figures.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for name, files in COPIES.items():
            out = Path(tmp) / name
            code = cli.main(
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
                shutil.copyfile(out / src, figures / dst)
            shutil.copyfile(out / "report.md", Path(tmp) / f"{name}.md")
            print((Path(tmp) / f"{name}.md").read_text())
        print(held_out_recordings(Path(tmp)))


if __name__ == "__main__":
    main()
