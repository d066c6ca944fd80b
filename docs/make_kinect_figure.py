"""The Kinect page's figure: the UTKinect walk (examples/kinect_utkinect_walk.toml) simulated
without and with skeleton conditioning, side by side, plus the measured foot speeds.

.venv/bin/python docs/make_kinect_figure.py
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from mdframework.conditioning import speeds
from mdframework.config import load_run_config
from mdframework.pipeline import build_stages, simulate_motion

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "examples" / "kinect_utkinect_walk.toml"
TARGET = ROOT / "docs" / "figures" / "kinect_walk_conditioning.png"


def run(enabled: bool) -> tuple[object, dict[str, float]]:
    """Simulate the example with conditioning on or off; the feet's peak speeds [m/s]."""
    config = load_run_config(CONFIG)
    config = config.model_copy(
        update={"conditioning": config.conditioning.model_copy(update={"enabled": enabled})}
    )
    stages = build_stages(config)
    motion = stages.source.load()
    result = simulate_motion(config, stages, motion)
    from mdframework.conditioning import condition

    sk = motion.canonical()
    if enabled:
        sk, _ = condition(sk, config.conditioning)
    peak = {j: float(speeds(sk.time, sk.joint(j)).max()) for j in ("l_toe", "r_toe")}
    return result, peak


def main() -> None:
    TARGET.parent.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), dpi=110, sharey=True)
    for ax, enabled in zip(axes, (False, True), strict=True):
        res, peak = run(enabled)
        t = res.spectrogram.time  # type: ignore[attr-defined]
        v = res.velocity  # type: ignore[attr-defined]
        im = ax.imshow(
            res.spectrogram_db,  # type: ignore[attr-defined]
            origin="lower",
            aspect="auto",
            extent=(t[0], t[-1], v[0], v[-1]),
            cmap="jet",
            vmin=-50,
            vmax=0,
        )
        ax.set_ylim(-6, 6)
        ax.set_xlabel("time [s]")
        state = "with conditioning" if enabled else "raw Kinect joints"
        feet = ", ".join(f"{k} {s:.1f} m/s" for k, s in peak.items())
        ax.set_title(f"UTKinect walk, {state}\npeak foot speed: {feet}", fontsize=9)
        print(state, peak)
    axes[0].set_ylabel("radial velocity [m/s] (+ approaching)")
    fig.colorbar(im, ax=axes, label="power [dB re peak]")
    fig.savefig(TARGET)
    print(TARGET)


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
