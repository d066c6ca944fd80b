"""The Kinect page's figure: the UTKinect walk (examples/kinect_utkinect_walk.toml) simulated
without and with skeleton conditioning, side by side, plus the measured foot speeds.

.venv/bin/python docs/make_kinect_figure.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mdframework.conditioning import speeds
from mdframework.config import load_run_config
from mdframework.figures import draw_spectrogram, save, style
from mdframework.pipeline import build_stages, simulate_motion

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "examples" / "kinect_utkinect_walk.toml"
CAPTION = (
    "kinect joints_s01_e01.txt (UTKinect, walk): lfm 15 GHz, PRF 2400 Hz; radar at (0, 0, 1) m; "
    "aspect 0°, from 2.3 m; scatterers ellipsoid joints17; effects: none"
)
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


def main(target: Path = TARGET) -> None:
    """Write the figure to ``target`` (docs/figures/kinect_walk_conditioning.png by default)."""
    target.parent.mkdir(parents=True, exist_ok=True)
    with style() as plt:
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), sharey=True, layout="constrained")
        for ax, enabled in zip(axes, (False, True), strict=True):
            res, peak = run(enabled)
            im = draw_spectrogram(
                ax,
                res.spectrogram_db,  # type: ignore[attr-defined]
                res.spectrogram.time,  # type: ignore[attr-defined]
                res.velocity,  # type: ignore[attr-defined]
            )
            ax.set_ylim(-6, 6)
            state = "with conditioning" if enabled else "raw Kinect joints"
            feet = ", ".join(f"{k} {s:.1f} m/s" for k, s in peak.items())
            ax.set_title(f"UTKinect walk, {state}\npeak foot speed: {feet}", fontsize=9)
            if enabled:
                ax.set_ylabel("")
            print(state, peak)
        fig.colorbar(im, ax=axes, label="power [dB re peak]")
        save(fig, target, CAPTION)
    print(target)


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
