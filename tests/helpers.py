"""Small helpers shared by tests (not fixtures)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from mdframework import DataFileError
from mdframework.config import validate_run_config
from mdframework.pipeline import RunResult, simulate

T = TypeVar("T")


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


# --------------------------------------------------------------------------- C3D files

#: Plug-in Gait markers: name -> (canonical joint, offset from it [m]); the joint is the mean
#: of its markers (offsets cancel), LUPA is a marker no joint uses.
PIG = {
    "LFHD": ("head", (0.05, 0.06, 0.0)),
    "RFHD": ("head", (0.05, -0.06, 0.0)),
    "LBHD": ("head", (-0.05, 0.06, 0.0)),
    "RBHD": ("head", (-0.05, -0.06, 0.0)),
    "C7": ("neck", (-0.06, 0.0, 0.0)),
    "CLAV": ("neck", (0.06, 0.0, 0.0)),
    "LASI": ("l_hip", (0.07, 0.0, 0.0)),
    "LPSI": ("l_hip", (-0.07, 0.0, 0.0)),
    "RASI": ("r_hip", (0.07, 0.0, 0.0)),
    "RPSI": ("r_hip", (-0.07, 0.0, 0.0)),
    "LWRA": ("l_hand", (0.0, 0.02, 0.0)),
    "LWRB": ("l_hand", (0.0, -0.02, 0.0)),
    "RWRA": ("r_hand", (0.0, 0.02, 0.0)),
    "RWRB": ("r_hand", (0.0, -0.02, 0.0)),
    **{
        f"{s}{m}": (f"{s.lower()}_{j}", (0.0, 0.0, 0.0))
        for s in "LR"
        for m, j in (("SHO", "shoulder"), ("ELB", "elbow"), ("KNE", "knee"))
    },
    **{f"{s}ANK": (f"{s.lower()}_ankle", (0.0, 0.0, 0.0)) for s in "LR"},
    **{f"{s}TOE": (f"{s.lower()}_toe", (0.0, 0.0, 0.0)) for s in "LR"},
    "LUPA": ("l_elbow", (0.0, 0.05, 0.1)),
}


def write_c3d(
    path: Path, markers: dict[str, np.ndarray], rate: float, units: str, scale: float
) -> None:
    """A C3D file of the given marker tracks [m], written through ezc3d in ``units``."""
    import ezc3d

    c = ezc3d.c3d()
    labels = list(markers)
    c["parameters"]["POINT"]["RATE"]["value"] = [rate]
    c["parameters"]["POINT"]["LABELS"]["value"] = labels
    c["parameters"]["POINT"]["UNITS"]["value"] = [units]
    n = next(iter(markers.values())).shape[0]
    pts = np.ones((4, len(labels), n))
    pts[:3] = np.stack([markers[k] / scale for k in labels], axis=1).T
    c["data"]["points"] = pts
    c.write(str(path))


def pig_markers(body: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Plug-in Gait marker tracks [m] around the given canonical joint tracks (:data:`PIG`)."""
    return {m: body[j] + np.array(o) for m, (j, o) in PIG.items()}


def walking_c3d(path: Path, seconds: float = 2.0, rate: float = 100.0) -> Path:
    """A Plug-in Gait C3D file (mm) of :func:`mdframework.testing.walking_positions`."""
    from mdframework import CANONICAL_JOINTS
    from mdframework.testing import walking_positions

    t = np.arange(round(seconds * rate)) / rate
    pos = walking_positions(t)
    body = {j: pos[:, k] for k, j in enumerate(CANONICAL_JOINTS)}
    write_c3d(path, pig_markers(body), rate, "mm", 0.001)
    return path


def point_dataset(path: Path, radar: str = "lfm") -> Path:
    """Write a dataset config at ``path``: one 0.5 s record of a point 100 m away receding at
    1 m/s, seen by the radar plugin ``radar``; ``path``."""
    path.write_text(f"""
seed = 1
[[sources]]
label = "recede"
motion = {{ kind = "point_targets", length = 0.5, targets = [
    {{ position = [100.0, 0.0, 0.0], velocity = [1.0, 0.0, 0.0], rcs = 1.0 }}] }}
[base.scatterers]
kind = "points"
[base.radar]
kind = "{radar}"
""")
    return path


def traced_peak(
    call: Callable[[], T], *, warm_up: Callable[[], object] | None = None, runs: int = 1
) -> tuple[T, int]:
    """What ``call`` returns and the peak of the memory traced while it ran [bytes] (numpy's
    arrays included).

    ``warm_up`` (the same code path, on a smaller problem where ``call`` is long) runs first,
    untraced: the one-off growth of the process that a path's first run brings (first imports,
    caches) stays out of the peak. With ``runs`` above 1, ``call`` is traced that many times
    and the lowest peak is given: code that builds paths (pathlib interns their parts, which
    die with them) or otherwise interns new strings now and then resizes the interpreter's
    table of interned strings, a block of several MB counted in that run's peak (two resizes
    are at least as many new strings apart as the table holds, tens of thousands: never in
    both of two runs)."""
    import tracemalloc

    if warm_up is not None:
        warm_up()
    peaks = []
    for _ in range(runs):
        tracemalloc.start()
        try:
            out = call()
            peaks.append(tracemalloc.get_traced_memory()[1])
        finally:
            tracemalloc.stop()
    return out, min(peaks)


def data_error_and_peak(call: Callable[[], object]) -> tuple[DataFileError, int]:
    """The :class:`DataFileError` that ``call`` raises (pytest fails if none) and the peak of
    the memory traced while it ran [bytes] (numpy's arrays included), the lower of two runs
    after a first one (see :func:`traced_peak`)."""
    import pytest

    def raised() -> DataFileError:
        with pytest.raises(DataFileError) as exc:
            call()
        return exc.value

    return traced_peak(raised, warm_up=raised, runs=2)
