"""Writing a run's results: all files appear together or not at all.

``DIR/result.npz`` arrays (all float64 unless noted):

- ``signal`` (n_pulses,) complex128: compressed slow-time return at the gate [sqrt(W)]
- ``pulse_time_s`` (n_pulses,): pulse times from the first pulse [s]
- ``gate_range_m`` (n_pulses,): range gate [m]
- ``spectrogram_db`` (n_doppler, n_frames) float32: power in dB re its peak, floored
- ``doppler_hz`` (n_doppler,), ``velocity_mps`` (n_doppler,): axes (+ approaching)
- ``time_s`` (n_frames,): STFT window centres [s from the first pulse]
- ``body_time_s`` (n_frames,), ``body_positions_m`` (n_frames, n_joints, 3) float32: the placed
  body at the source's frame times within the record [s from the first pulse, m]; ``body_joints``
  (n_joints,) str
- with ``processing.keep_scatterers`` only: ``scatterer_range_m`` (n_pulses, n_scatterers),
  ``scatterer_rcs_m2`` (same) float32
- raw path only: ``range_time_db`` (n_slow, n_range) float32, |compressed output| in dB re peak,
  decimated in slow time to at most 2000 rows; ``range_time_time_s`` (n_slow,);
  ``range_m`` (n_range,)
- waveform products (e.g. range-Doppler maps, point clouds), under their own names

plus ``spectrogram.png``, ``range_time.png`` (raw path), ``config.resolved.json`` and
``metadata.json``.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from .figures import plot_range_time, plot_spectrogram
from .physics.spectrogram import power_to_db
from .pipeline import RunResult

MAX_RANGE_TIME_ROWS = 2000
#: every file a run may write
OUTPUTS = (
    "result.npz",
    "spectrogram.png",
    "range_time.png",
    "config.resolved.json",
    "metadata.json",
)


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
    if result.scatterers is not None:
        radar_position = np.asarray(result.metadata["radar_position_m"])
        arrays["scatterer_range_m"] = result.scatterers.ranges(radar_position)
        arrays["scatterer_rcs_m2"] = result.scatterers.rcs.astype(np.float32)
    rec = result.received
    if rec.range_time is not None and rec.range_axis is not None:
        rows = rec.range_time_pulses
        if rows is None:
            rows = np.arange(rec.range_time.shape[0])
        step = max(1, int(np.ceil(rec.range_time.shape[0] / MAX_RANGE_TIME_ROWS)))
        power = np.abs(rec.range_time[::step]) ** 2
        arrays["range_time_db"] = power_to_db(power, -80.0).astype(np.float32)
        arrays["range_time_time_s"] = result.pulse_times[rows[::step]]
        arrays["range_m"] = rec.range_axis
    for name, value in rec.products.items():
        arrays.setdefault(name, value)
    return arrays


def write_run(result: RunResult, resolved_config: dict[str, Any], out_dir: Path) -> list[Path]:
    """Write a run's files into ``out_dir`` atomically (staged in a temporary folder beside it,
    then moved in). Returns the written paths."""
    out_dir = Path(out_dir)
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", dir=out_dir.parent))
    try:
        arrays = result_arrays(result)
        np.savez_compressed(stage / "result.npz", **arrays)  # type: ignore[arg-type]
        title = str(result.metadata.get("motion", {}).get("activity", ""))
        plot_spectrogram(
            stage / "spectrogram.png",
            arrays["spectrogram_db"],
            arrays["time_s"],
            arrays["velocity_mps"],
            arrays["doppler_hz"],
            title=title,
        )
        if "range_time_db" in arrays:
            plot_range_time(
                stage / "range_time.png",
                arrays["range_time_db"],
                arrays["range_time_time_s"],
                arrays["range_m"],
                title=title,
            )
        (stage / "config.resolved.json").write_text(json.dumps(resolved_config, indent=2) + "\n")
        (stage / "metadata.json").write_text(
            json.dumps(result.metadata, indent=2, default=_jsonable) + "\n"
        )
        out_dir.mkdir(parents=True, exist_ok=True)
        for name in OUTPUTS:  # an earlier run's file this run does not make (range_time.png)
            if not (stage / name).exists():
                (out_dir / name).unlink(missing_ok=True)
        written = []
        for f in sorted(stage.iterdir()):
            os.replace(f, out_dir / f.name)
            written.append(out_dir / f.name)
        return written
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _jsonable(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"not JSON-serialisable: {type(value).__name__}")
