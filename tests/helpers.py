"""Small helpers shared by tests (not fixtures)."""

from __future__ import annotations

from typing import Any

import numpy as np

from mdframework.config import validate_run_config
from mdframework.pipeline import RunResult, simulate


def point_run(
    targets: list[dict[str, Any]],
    *,
    duration: float = 2.0,
    radar: dict[str, Any] | None = None,
    processing: dict[str, Any] | None = None,
    scene: dict[str, Any] | None = None,
) -> RunResult:
    """Simulate point targets with a radar at the origin."""
    cfg = {
        "motion": {"kind": "point_targets", "length": duration, "targets": targets},
        "scatterers": {"kind": "points"},
        "radar": {"kind": "lfm", "precision": "float64", **(radar or {})},
        "scene": {"radar_position": [0.0, 0.0, 0.0], **(scene or {})},
        "processing": {"keep_scatterers": True, **(processing or {})},
    }
    return simulate(validate_run_config(cfg))


def peak_frequency_per_frame(result: RunResult) -> np.ndarray:
    """Doppler [Hz] of the strongest bin in each spectrogram frame."""
    return result.spectrogram.doppler[np.argmax(result.spectrogram.power, axis=0)]


def phase_increment_doppler(signal: np.ndarray, prf: float) -> float:
    """Mean Doppler [Hz] from the average pulse-to-pulse phase increment."""
    return float(np.angle(np.sum(signal[1:] * np.conj(signal[:-1]))) * prf / (2 * np.pi))
