"""Resampling joint tracks to pulse times (``physics.md`` section 6.4).

Positions are interpolated, never the complex return; the default is a C2-smooth cubic spline.
Output times never extend past the recording (no extrapolation). Untracked frames (``valid`` False)
are dropped per joint and the spline bridges the gap.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

Method = Literal["cubic", "pchip", "akima", "linear"]


def pulse_times(t_first: float, t_last: float, prf: float) -> FloatArray:
    """Pulse times ``t_first + n / prf`` [s] for every n with time <= ``t_last``, (n_pulses,).

    Built from time, not by integer upsampling, so non-integer rate ratios are exact."""
    n = int(np.floor((t_last - t_first) * prf * (1.0 + 1e-12))) + 1
    return t_first + np.arange(n, dtype=np.float64) / prf


def resample_tracks(
    time: FloatArray,
    positions: FloatArray,
    valid: BoolArray,
    t_out: FloatArray,
    method: Method = "cubic",
) -> FloatArray:
    """Interpolate joint tracks to new times.

    ``time`` (n_frames,) [s] strictly increasing; ``positions`` (n_frames, n_joints, 3) [m];
    ``valid`` (n_frames, n_joints); ``t_out`` (n_out,) [s] within every joint's first and last
    valid frame. Returns (n_out, n_joints, 3) float64 [m].
    """
    if method not in ("cubic", "pchip", "akima", "linear"):
        raise ValueError(f"unknown interpolation method {method!r}")
    out = np.empty((t_out.shape[0], positions.shape[1], 3), dtype=np.float64)
    if np.all(valid):
        return _interp(time, positions, t_out, method)
    for j in range(positions.shape[1]):
        ok = valid[:, j]
        if ok.sum() < 2:
            raise ValueError(f"joint {j} has fewer than two valid frames")
        tj = time[ok]
        if t_out[0] < tj[0] - 1e-12 or t_out[-1] > tj[-1] + 1e-12:
            raise ValueError(
                f"joint {j} is valid only from {tj[0]:.4f} to {tj[-1]:.4f} s; "
                "interpolation never extrapolates"
            )
        out[:, j, :] = _interp(tj, positions[ok, j, :], t_out, method)
    return out


def _interp(t: FloatArray, y: FloatArray, t_out: FloatArray, method: Method) -> FloatArray:
    if t_out[0] < t[0] - 1e-12 or t_out[-1] > t[-1] + 1e-12:
        raise ValueError(
            f"output times {t_out[0]:.4f}..{t_out[-1]:.4f} s leave the recording "
            f"{t[0]:.4f}..{t[-1]:.4f} s; interpolation never extrapolates"
        )
    tq = np.clip(t_out, t[0], t[-1])
    from scipy.interpolate import Akima1DInterpolator, CubicSpline, PchipInterpolator

    if method == "linear":
        flat = y.reshape(y.shape[0], -1)
        res = np.stack([np.interp(tq, t, flat[:, k]) for k in range(flat.shape[1])], axis=1)
        return res.reshape((tq.shape[0], *y.shape[1:]))
    if method == "cubic":
        if t.shape[0] < 4:
            return np.asarray(CubicSpline(t, y, axis=0, bc_type="natural")(tq), np.float64)
        return np.asarray(CubicSpline(t, y, axis=0)(tq), dtype=np.float64)
    if method == "pchip":
        # scipy forms the harmonic mean of neighbouring slopes as 1 / (w1/m1 + w2/m2); slopes
        # below ~1e-300 (a track that all but stands still) overflow the reciprocals to inf,
        # whose reciprocal, the derivative, is then exactly its limit 0: harmless, not reported
        with np.errstate(over="ignore"):
            return np.asarray(PchipInterpolator(t, y, axis=0)(tq), dtype=np.float64)
    return np.asarray(Akima1DInterpolator(t, y, axis=0, method="makima")(tq), np.float64)
