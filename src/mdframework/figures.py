"""Figures of a run: the spectrogram (velocity and Doppler axes) and the range-time map."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_spectrogram(
    path: Path,
    spectrogram_db: NDArray[np.floating[Any]],
    time: NDArray[np.float64],
    velocity: NDArray[np.float64],
    doppler: NDArray[np.float64],
    *,
    title: str = "",
    dynamic_range_db: float = 50.0,
) -> None:
    """Save a spectrogram image: time [s] across, radial velocity [m/s] up (positive =
    approaching) with Doppler [Hz] on the right-hand axis."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5), dpi=110)
    dt = time[1] - time[0] if time.size > 1 else 1.0
    dv = velocity[1] - velocity[0]
    extent = (time[0] - dt / 2, time[-1] + dt / 2, velocity[0] - dv / 2, velocity[-1] + dv / 2)
    im = ax.imshow(
        spectrogram_db,
        origin="lower",
        aspect="auto",
        extent=extent,
        cmap="jet",
        vmin=-dynamic_range_db,
        vmax=0.0,
        interpolation="nearest",
    )
    ax.set_xlabel("time [s]")
    ax.set_ylabel("radial velocity [m/s] (+ approaching)")
    ratio = float(doppler[-1] / velocity[-1]) if velocity[-1] != 0 else 1.0
    sec = ax.secondary_yaxis("right", functions=(lambda v: v * ratio, lambda f: f / ratio))
    sec.set_ylabel("Doppler [Hz]")
    fig.colorbar(im, ax=ax, pad=0.12, label="power [dB re peak]")
    if title:
        ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def plot_range_time(
    path: Path,
    range_time_db: NDArray[np.floating[Any]],
    time: NDArray[np.float64],
    ranges: NDArray[np.float64],
    *,
    title: str = "",
    dynamic_range_db: float = 40.0,
) -> None:
    """Save a range-time map: time [s] across, range [m] up, |compressed output| in dB."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4), dpi=110)
    extent = (time[0], time[-1], ranges[0], ranges[-1])
    im = ax.imshow(
        range_time_db.T,
        origin="lower",
        aspect="auto",
        extent=extent,
        cmap="viridis",
        vmin=-dynamic_range_db,
        vmax=0.0,
        interpolation="nearest",
    )
    ax.set_xlabel("time [s]")
    ax.set_ylabel("range [m]")
    fig.colorbar(im, ax=ax, label="compressed power [dB re peak]")
    if title:
        ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
