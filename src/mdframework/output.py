"""Writing a run's results: all files appear together or not at all.

The folder rules (refusing other files, the lock, staging inside the folder, replacing an
earlier run's files only once every new one is complete) are those of
:mod:`mdframework.outdir`.

``DIR/result.npz`` arrays (all float64 unless noted):

- ``signal`` (n_pulses,) complex128: compressed slow-time return at the gate [sqrt(W)]
- ``pulse_time_s`` (n_pulses,): pulse times from the first pulse [s]
- ``gate_range_m`` (n_pulses,): range gate [m]
- ``spectrogram_db`` (n_doppler, n_frames) float32: power in dB re its peak, floored
- ``doppler_hz`` (n_doppler,), ``velocity_mps`` (n_doppler,): axes (+ approaching)
- ``time_s`` (n_frames,): STFT window centres [s from the first pulse]
- ``body_time_s`` (n_body,), ``body_positions_m`` (n_body, n_joints, 3) float32: the placed
  body at the source's own n_body frame times within the record (not the STFT's n_frames) [s
  from the first pulse, m]; ``body_joints`` (n_joints,) str
- with ``processing.keep_scatterers`` only: ``scatterer_range_m`` (n_pulses, n_scatterers),
  ``scatterer_rcs_m2`` (same) float32
- raw path only: ``range_time_db`` (n_slow, n_range) float32, |compressed output| in dB re peak,
  decimated in slow time to at most 2000 rows; ``range_time_time_s`` (n_slow,) [s];
  ``range_m`` (n_range,) [m]
- ``envelope_upper_mps``, ``envelope_lower_mps``, ``torso_velocity_mps`` (n_frames,): the
  spectrogram's upper and lower envelopes and torso track [m/s] (NaN in silent frames), and
  ``features_mps`` (7,): the seven features of Erol & Gurbuz in
  :data:`mdframework.features.FEATURE_NAMES` order (NaN if the spectrogram is silent); both
  with the default feature settings (threshold method, -20 dB below each column's peak, floor
  -40 dB, median torso), as datasets use them
- waveform products (e.g. range-Doppler maps, point clouds), under their own names

plus ``spectrogram.png``, ``range_time.png`` (raw path), ``features.json`` (the seven
features by name and the three tracks, ``null`` in silent frames), ``config.resolved.json``
and ``metadata.json``.
"""

from __future__ import annotations

import json
import warnings
from contextlib import AbstractContextManager
from pathlib import Path
from typing import Any

import numpy as np

from .features import (
    FEATURE_NAMES,
    Envelopes,
    band_edge_frames,
    envelopes,
    features_from_envelopes,
)
from .figures import (
    plot_point_cloud,
    plot_range_doppler,
    plot_range_time,
    plot_spectrogram,
    run_caption,
)
from .outdir import OutputFolder, output_folder
from .physics.spectrogram import power_to_db
from .pipeline import RunResult
from .plugins import versions
from .progress import QUIET, Progress

#: Range-time rows saved to result.npz (``range_time_db``) and drawn in range_time.png: the
#: record's kept rows (``pipeline.MAX_KEPT_RANGE_TIME_ROWS``) decimated to at most this many.
MAX_SAVED_RANGE_TIME_ROWS = 2000
#: every file a run may write
OUTPUTS = (
    "result.npz",
    "spectrogram.png",
    "range_time.png",
    "features.json",
    "points.csv",
    "range_doppler.png",
    "point_cloud.png",
    "config.resolved.json",
    "metadata.json",
    # written by `mdf show` beside the run's files (mdframework.preview)
    "motion.gif",
    "motion.mp4",
    "skeleton.png",
)

#: Envelope and feature settings of ``mdf run`` (the defaults of datasets' ``features``).
FEATURE_SETTINGS: dict[str, Any] = {
    "method": "threshold",
    "threshold_db": -20.0,
    "floor_db": -40.0,
    "torso": "median",
}


class FeatureWarning(UserWarning):
    """A run's features that describe the spectrogram's band, not the body."""


def band_edge_message(env: Envelopes, velocity: np.ndarray) -> str | None:
    """The warning for envelopes (each (n_frames,) [m/s], NaN when silent) that reach the first
    or last bin of ``velocity`` (n_doppler,) [m/s] (:func:`~mdframework.features.band_edge_frames`),
    or None when no frame does."""
    edge = band_edge_frames(env, velocity)
    if not edge:
        return None
    return (
        f"features: the {FEATURE_SETTINGS['threshold_db']:g} dB envelope reaches the edge of "
        f"the Doppler band ({velocity[0]:+.2f} to {velocity[-1]:+.2f} m/s) in "
        f"{edge} of {int(np.sum(np.isfinite(env.upper)))} frames, so upper_max, lower_min and "
        "the bandwidths there are the band's, not the body's: the body's Doppler aliases, or "
        f"the spectrogram's columns stand less than {-FEATURE_SETTINGS['threshold_db']:g} dB "
        "above the noise (raise the pulse rate or the signal-to-noise ratio)"
    )


def feature_arrays(result: RunResult) -> dict[str, np.ndarray]:
    """Envelope tracks (n_frames,) and the seven features (7,) [m/s] of a run's spectrogram
    (:data:`FEATURE_SETTINGS`); NaN where a frame, or the whole spectrogram, is silent. Warns
    (:class:`FeatureWarning`) when an envelope reaches the edge of the Doppler band."""
    env = envelopes(
        result.spectrogram.power,
        result.velocity,
        method=FEATURE_SETTINGS["method"],
        threshold_db=FEATURE_SETTINGS["threshold_db"],
        floor_db=FEATURE_SETTINGS["floor_db"],
        torso_method=FEATURE_SETTINGS["torso"],
    )
    try:
        feats = features_from_envelopes(env)
    except ValueError:  # silent spectrogram
        feats = np.full(len(FEATURE_NAMES), np.nan)
    message = band_edge_message(env, np.asarray(result.velocity))
    if message is not None:
        warnings.warn(message, FeatureWarning, stacklevel=2)
    return {
        "envelope_upper_mps": env.upper,
        "envelope_lower_mps": env.lower,
        "torso_velocity_mps": env.torso,
        "features_mps": feats,
    }


def features_document(arrays: dict[str, np.ndarray]) -> dict[str, Any]:
    """The contents of ``features.json`` from :func:`result_arrays`' output."""

    def listed(a: np.ndarray) -> list[float | None]:
        return [None if not np.isfinite(v) else float(v) for v in a]

    feats = arrays["features_mps"]
    return {
        "units": "m/s (positive = approaching)",
        "settings": FEATURE_SETTINGS,
        "features": {
            n: (None if not np.isfinite(v) else float(v))
            for n, v in zip(FEATURE_NAMES, feats, strict=True)
        },
        "time_s": listed(arrays["time_s"]),
        "envelope_upper_mps": listed(arrays["envelope_upper_mps"]),
        "envelope_lower_mps": listed(arrays["envelope_lower_mps"]),
        "torso_velocity_mps": listed(arrays["torso_velocity_mps"]),
    }


def result_arrays(result: RunResult) -> dict[str, np.ndarray]:
    """The arrays stored in ``result.npz``."""
    arrays: dict[str, np.ndarray] = {
        "signal": result.received.signal,
        "pulse_time_s": result.pulse_times,
        "gate_range_m": result.gate_range,
        "spectrogram_db": result.spectrogram_db.astype(np.float32),
        "doppler_hz": result.spectrogram.doppler,
        "velocity_mps": result.velocity,
        "time_s": result.spectrogram.time,
        "body_time_s": result.body.time,
        "body_positions_m": result.body.positions.astype(np.float32),
        "body_joints": np.array(result.body.joint_names),
    }
    arrays.update(feature_arrays(result))
    if result.scatterers is not None:
        radar_position = np.asarray(result.metadata["radar_position_m"])
        arrays["scatterer_range_m"] = result.scatterers.ranges(radar_position)
        arrays["scatterer_rcs_m2"] = result.scatterers.rcs.astype(np.float32)
    rec = result.received
    if rec.range_time is not None and rec.range_axis is not None:
        rows = rec.range_time_pulses
        if rows is None:
            rows = np.arange(rec.range_time.shape[0])
        step = max(1, int(np.ceil(rec.range_time.shape[0] / MAX_SAVED_RANGE_TIME_ROWS)))
        power = np.abs(rec.range_time[::step]) ** 2
        arrays["range_time_db"] = power_to_db(power, -80.0).astype(np.float32)
        arrays["range_time_time_s"] = result.pulse_times[rows[::step]]
        arrays["range_m"] = rec.range_axis
    for name, value in rec.products.items():
        arrays.setdefault(name, value)
    return arrays


def write_run(
    result: RunResult,
    resolved_config: dict[str, Any],
    out: Path | OutputFolder,
    *,
    force: bool = False,
    progress: Progress = QUIET,
) -> list[Path]:
    """Write a run's files into ``out`` (a folder path, or a folder already opened with
    :func:`run_folder`): staged inside it, then moved in. Returns the written paths.
    ``progress`` reports the files that take more than a second."""
    if not isinstance(out, OutputFolder):
        with run_folder(out, force=force) as folder:
            return write_run(result, resolved_config, folder, progress=progress)
    stage = out.stage()
    stage_run(result, resolved_config, stage, progress)
    return out.commit(stage)


def stage_run(
    result: RunResult, resolved_config: dict[str, Any], stage: Path, progress: Progress = QUIET
) -> None:
    """Write a run's files into the staging folder ``stage`` (see :func:`write_run`); the
    figures only when ``[figures] enabled``."""
    try:
        _stage_run(result, resolved_config, stage, progress)
    finally:
        progress.end()


def _stage_run(
    result: RunResult, resolved_config: dict[str, Any], stage: Path, progress: Progress
) -> None:
    progress.stage("writing result.npz")
    arrays = result_arrays(result)
    np.savez_compressed(stage / "result.npz", **arrays)  # type: ignore[arg-type]
    look = dict(resolved_config.get("figures", {}))
    if look.pop("enabled", True):
        gate = (float(result.gate_range[0]), float(result.gate_range[-1]))
        title, caption = run_caption(result.metadata, resolved_config, gate)
        _plot_run(stage, arrays, title, caption, look, progress)
    products = "points" in arrays
    progress.stage("writing features.json" + (" and points.csv" if products else ""))
    (stage / "features.json").write_text(
        json.dumps(features_document(arrays), indent=2) + "\n", encoding="utf-8"
    )
    if products:
        write_points_csv(stage / "points.csv", arrays["points"])
    (stage / "config.resolved.json").write_text(
        json.dumps(resolved_config, indent=2) + "\n", encoding="utf-8"
    )
    (stage / "metadata.json").write_text(
        json.dumps({**result.metadata, "versions": versions()}, indent=2, default=_jsonable) + "\n",
        encoding="utf-8",
    )


def _plot_run(
    stage: Path,
    arrays: dict[str, np.ndarray],
    title: str,
    caption: str,
    look: dict[str, Any],
    progress: Progress,
) -> None:
    """A run's figures; ``look``: the ``[figures]`` options but ``enabled``."""
    progress.stage("drawing spectrogram.png")
    plot_spectrogram(
        stage / "spectrogram.png",
        arrays["spectrogram_db"],
        arrays["time_s"],
        arrays["velocity_mps"],
        arrays["doppler_hz"],
        title=title,
        caption=caption,
        **look,
    )
    if "range_time_db" in arrays:
        progress.stage("drawing range_time.png")
        plot_range_time(
            stage / "range_time.png",
            arrays["range_time_db"],
            arrays["range_time_time_s"],
            arrays["range_m"],
            title=title,
            caption=caption,
            dynamic_range_db=look.get("dynamic_range_db", 40.0),
            colormap=look.get("colormap", "viridis"),
        )
    if "points" in arrays or "range_doppler" in arrays:
        progress.stage("drawing the radar's products")
        plot_point_products(
            stage,
            arrays,
            title,
            caption=caption,
            dynamic_range_db=look.get("dynamic_range_db", 40.0),
            colormap=look.get("colormap", "viridis"),
        )


def run_folder(
    out: str | Path, *, force: bool = False, staging_dir: str | Path | None = None
) -> AbstractContextManager[OutputFolder]:
    """Open ``out`` for a run's files (a context manager yielding an
    :class:`~mdframework.outdir.OutputFolder`); see :func:`mdframework.outdir.output_folder`."""
    return output_folder(out, "run", OUTPUTS, force=force, staging_dir=staging_dir)


#: Header of ``points.csv``: the columns of a waveform's ``points`` product.
POINTS_HEADER = "frame,t,x,y,z,v,intensity"


def write_points_csv(path: Path, points: np.ndarray) -> None:
    """``points`` (n_points, 7) as CSV with :data:`POINTS_HEADER`: frame index, t [s from the
    first pulse], x, y, z [m, sensor frame], v [m/s, + approaching], intensity [dB]. Six
    significant digits, but ten for ``t``: a microsecond up to 10^4 s into the record (2.8 h),
    10 us in a day-long one."""
    with open(path, "w", encoding="utf-8") as f:
        f.write(POINTS_HEADER + "\n")
        for row in points:
            rest = ",".join(f"{v:.6g}" for v in row[2:])
            f.write(f"{int(row[0])},{row[1]:.10g},{rest}\n")


def plot_point_products(
    stage: Path,
    arrays: dict[str, np.ndarray],
    title: str,
    *,
    caption: str = "",
    dynamic_range_db: float = 40.0,
    colormap: str = "viridis",
) -> None:
    """Figures of a waveform's range-Doppler maps and point clouds, when it made them:
    ``range_doppler.png`` / ``point_cloud.png`` of the frame with the most points (the strongest
    map when there are none), with the run's ``caption``; the map in ``colormap``, the top
    ``dynamic_range_db`` in colour (the ``[figures]`` options)."""
    points = arrays.get("points")
    maps = arrays.get("range_doppler")
    frame = None
    if points is not None and len(points):
        counts = np.bincount(points[:, 0].astype(np.int64))
        frame = int(np.argmax(counts))
    if maps is not None and len(maps) and "range_doppler_range_m" in arrays:
        if frame is None or frame >= len(maps):
            frame = int(np.argmax(maps.reshape(len(maps), -1).max(axis=1)))
        plot_range_doppler(
            stage / "range_doppler.png",
            maps[frame],
            arrays["range_doppler_range_m"],
            arrays["range_doppler_velocity_mps"],
            title=f"{title} frame {frame}".strip(),
            caption=caption,
            dynamic_range_db=dynamic_range_db,
            colormap=colormap,
        )
    if points is not None and len(points) and frame is not None:
        plot_point_cloud(
            stage / "point_cloud.png",
            points[points[:, 0] == frame],
            title=f"{title} frame {frame}".strip(),
            caption=caption,
        )


def _jsonable(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"not JSON-serialisable: {type(value).__name__}")
