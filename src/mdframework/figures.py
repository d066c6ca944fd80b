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


def plot_confusion(
    path: Path,
    classes: list[str],
    mean: NDArray[np.float64],
    std: NDArray[np.float64] | None,
    *,
    title: str = "",
) -> None:
    """Save a row-normalised confusion matrix (true class down, predicted across)."""
    plt = _pyplot()
    n = len(classes)
    fig, ax = plt.subplots(figsize=(1.3 * n + 2.5, 1.1 * n + 1.8), dpi=110)
    im = ax.imshow(mean, cmap="Blues", vmin=0.0, vmax=1.0)
    for i in range(n):
        for j in range(n):
            text = f"{mean[i, j]:.2f}" + (f"\n±{std[i, j]:.2f}" if std is not None else "")
            ax.text(
                j,
                i,
                text,
                ha="center",
                va="center",
                color="white" if mean[i, j] > 0.6 else "black",
                fontsize=9,
            )
    ax.set_xticks(range(n), classes, rotation=30, ha="right")
    ax.set_yticks(range(n), classes)
    ax.set_xlabel("predicted")
    ax.set_ylabel("true")
    fig.colorbar(im, ax=ax, label="rate")
    if title:
        ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def plot_feature_scatter(
    path: Path,
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    labels: NDArray[Any],
    groups: NDArray[Any],
    x_name: str,
    y_name: str,
) -> None:
    """Scatter plot of two features [m/s], colour = activity, marker = source group."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.5), dpi=110)
    markers = "o^sDvP*X"
    for gi, group in enumerate(sorted(set(groups.tolist()))):
        for li, label in enumerate(sorted(set(labels.tolist()))):
            sel = (groups == group) & (labels == label)
            if np.any(sel):
                ax.scatter(
                    x[sel],
                    y[sel],
                    s=14,
                    marker=markers[gi % len(markers)],
                    color=f"C{li}",
                    alpha=0.7,
                    label=f"{label} ({group})",
                )
    ax.set_xlabel(f"{x_name} [m/s]")
    ax.set_ylabel(f"{y_name} [m/s]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def plot_range_doppler(
    path: Path,
    power: NDArray[np.floating[Any]],
    range_m: NDArray[np.float64],
    velocity: NDArray[np.float64],
    *,
    title: str = "",
    dynamic_range_db: float = 50.0,
) -> None:
    """Save one range-Doppler map: ``power`` (n_doppler, n_range) linear [W], range [m] across,
    radial velocity [m/s] up (positive = approaching), in dB re the map's peak."""
    from .physics.spectrogram import power_to_db

    plt = _pyplot()
    db = power_to_db(np.asarray(power, np.float64), -dynamic_range_db)
    fig, ax = plt.subplots(figsize=(7, 4), dpi=110)
    dr = range_m[1] - range_m[0] if range_m.size > 1 else 1.0
    dv = velocity[1] - velocity[0] if velocity.size > 1 else 1.0
    extent = (
        range_m[0] - dr / 2,
        range_m[-1] + dr / 2,
        velocity[0] - dv / 2,
        velocity[-1] + dv / 2,
    )
    im = ax.imshow(
        db, origin="lower", aspect="auto", extent=extent, cmap="viridis", interpolation="nearest"
    )
    ax.set_xlabel("range [m]")
    ax.set_ylabel("radial velocity [m/s] (+ approaching)")
    fig.colorbar(im, ax=ax, label="power [dB re peak]")
    if title:
        ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def plot_point_cloud(
    path: Path, points: NDArray[np.float64], *, title: str = "", v_limit: float | None = None
) -> None:
    """Save a point cloud, ``points`` (n, 7) with columns frame, t, x, y, z, v, intensity: a top
    view (x across, y = boresight up) and a side view (y across, z up) in the sensor frame [m],
    coloured by radial velocity [m/s] (+ approaching), marker area by intensity."""
    plt = _pyplot()
    fig, (top, side) = plt.subplots(1, 2, figsize=(9, 4.2), dpi=110)
    x, y, z, v, snr = (points[:, k] for k in range(2, 7))
    lim = v_limit or max(float(np.max(np.abs(v))) if v.size else 1.0, 0.1)
    size = 6 + 2 * np.clip(snr, 0, 40) if snr.size else 6
    kw = dict(c=v, s=size, cmap="coolwarm", vmin=-lim, vmax=lim, edgecolors="none")
    top.scatter(x, y, **kw)
    sc = side.scatter(y, z, **kw)
    top.set_xlabel("x [m] (right)")
    top.set_ylabel("y [m] (boresight)")
    side.set_xlabel("y [m] (boresight)")
    side.set_ylabel("z [m] (up)")
    for ax in (top, side):
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    fig.colorbar(sc, ax=[top, side], label="radial velocity [m/s] (+ approaching)")
    if title:
        fig.suptitle(title)
    fig.savefig(path)
    plt.close(fig)


def plot_spectrogram_panels(
    path: Path,
    panels: list[tuple[NDArray[np.floating[Any]], NDArray[np.float64], NDArray[np.float64], str]],
    *,
    dynamic_range_db: float = 50.0,
) -> None:
    """Save spectrograms side by side, each panel ``(spectrogram_db (n_doppler, n_frames),
    time [s], velocity [m/s] (+ approaching), title)``, on a common colour scale."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(panels), figsize=(5 * len(panels), 4), dpi=110, sharey=True)
    axes = np.atleast_1d(axes)
    im = None
    for ax, (db, time, velocity, title) in zip(axes, panels, strict=True):
        dt = time[1] - time[0] if time.size > 1 else 1.0
        dv = velocity[1] - velocity[0]
        extent = (time[0] - dt / 2, time[-1] + dt / 2, velocity[0] - dv / 2, velocity[-1] + dv / 2)
        im = ax.imshow(
            db,
            origin="lower",
            aspect="auto",
            extent=extent,
            cmap="jet",
            vmin=-dynamic_range_db,
            vmax=0.0,
            interpolation="nearest",
        )
        ax.set_xlabel("time [s]")
        ax.set_title(title)
    axes[0].set_ylabel("radial velocity [m/s] (+ approaching)")
    fig.colorbar(im, ax=list(axes), label="power [dB re peak]")
    fig.savefig(path)
    plt.close(fig)
