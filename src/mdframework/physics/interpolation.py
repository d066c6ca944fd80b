"""Resampling joint tracks to pulse times.

Positions are interpolated, never the complex return; the default is a C2-smooth cubic spline.
Output times never extend past the recording (no extrapolation). Untracked frames (``valid`` False)
are dropped per joint and the spline bridges the gap.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

Method = Literal["cubic", "pchip", "akima", "linear"]
#: The methods whose interpolants are linear in their data (:meth:`TrackResampler.mapped`).
LINEAR_IN_DATA: tuple[Method, ...] = ("cubic", "linear")


def pulse_times(t_first: float, t_last: float, prf: float) -> FloatArray:
    """Pulse times ``t_first + n / prf`` [s] for every n with time <= ``t_last``, (n_pulses,).

    Built from time, not by integer upsampling, so non-integer rate ratios are exact."""
    n = int(np.floor((t_last - t_first) * prf * (1.0 + 1e-12))) + 1
    return t_first + np.arange(n, dtype=np.float64) / prf


#: Frames kept beyond each end of a record window when only the window is resampled. A cubic
#: spline's end condition decays by a factor 2 - sqrt(3) ~ 0.27 per knot, so 16 knots put the
#: recording's own window edges ~1e-9 of their effect away from the record.
WINDOW_MARGIN_FRAMES = 16


def window_frames(
    time: FloatArray, t_first: float, t_last: float, margin: int = WINDOW_MARGIN_FRAMES
) -> slice:
    """The frames of a recording (``time`` (n_frames,) [s]) that resampling a record from
    ``t_first`` to ``t_last`` [s] needs: those inside, plus ``margin`` frames on either side."""
    lo = int(np.searchsorted(time, t_first, side="right")) - 1 - margin
    hi = int(np.searchsorted(time, t_last, side="left")) + 1 + margin
    return slice(max(lo, 0), min(hi, time.shape[0]))


class TrackResampler:
    """Joint tracks of a recording, interpolated at any times within it; the interpolants are
    built once, so a record can be evaluated block by block.

    ``time`` (n_frames,) [s] strictly increasing; ``positions`` (n_frames, n_joints, 3) [m];
    ``valid`` (n_frames, n_joints) bool: untracked frames are dropped per joint and the
    interpolant bridges the gap. ``method``: cubic (C2 spline; natural ends below 4 frames),
    pchip, akima (modified Akima) or linear.
    """

    def __init__(
        self, time: FloatArray, positions: FloatArray, valid: BoolArray, method: Method = "cubic"
    ) -> None:
        if method not in ("cubic", "pchip", "akima", "linear"):
            raise ValueError(f"unknown interpolation method {method!r}")
        self.n_joints = int(positions.shape[1])
        self.method = method
        #: (joints, time, values (n_frames, n_sel * 3)), one group when every frame is valid
        self._groups: list[tuple[NDArray[np.intp], FloatArray, Any]] = []
        if np.all(valid):
            self._add(np.arange(self.n_joints), time, positions)
            return
        for j in range(self.n_joints):
            ok = valid[:, j]
            if ok.sum() < 2:
                raise ValueError(f"joint {j} has fewer than two valid frames")
            self._add(np.array([j]), time[ok], positions[ok][:, [j], :])

    def _add(self, joints: NDArray[np.intp], t: FloatArray, y: FloatArray) -> None:
        flat = np.ascontiguousarray(y.reshape(y.shape[0], -1), dtype=np.float64)
        if self.method == "linear":
            self._groups.append((joints, t, flat))
            return
        from scipy.interpolate import Akima1DInterpolator, PchipInterpolator, make_interp_spline

        if self.method == "cubic":
            # The interpolating cubic spline (not-a-knot ends) in B-spline form: the same curve
            # as scipy's CubicSpline to ~1e-15 of the values, built in a quarter of the time and
            # evaluated in two thirds (one banded solve and de Boor's recurrence in compiled
            # code; tracks are finite here, so scipy's finiteness checks are skipped)
            bc = "natural" if t.shape[0] < 4 else None
            f: Any = make_interp_spline(t, flat, k=3, bc_type=bc, axis=0, check_finite=False)
        elif self.method == "pchip":
            # scipy forms the harmonic mean of neighbouring slopes as 1 / (w1/m1 + w2/m2);
            # slopes below ~1e-300 (a track that all but stands still) overflow the
            # reciprocals to inf, whose reciprocal, the derivative, is then exactly its limit
            # 0: harmless, not reported
            with np.errstate(over="ignore"):
                f = PchipInterpolator(t, flat, axis=0)
        else:
            f = Akima1DInterpolator(t, flat, axis=0, method="makima")
        self._groups.append((joints, t, f))

    def mapped(self, affine: Callable[[FloatArray, FloatArray], FloatArray]) -> TrackResampler:
        """The resampler of the tracks mapped by ``affine(time, joints)``, a map that is affine
        in the joints and in time (``R x + a + b t``, e.g. a scene placement), without building
        the interpolants again: the cubic spline and linear interpolation are linear in their
        data and reproduce constants and straight lines, so mapping them is mapping their
        coefficients (a B-spline's at its Greville abscissae, where sum_i xi_i B_i(t) = t).
        ``affine`` takes ``time`` (n,) [s] and ``joints`` (n, n_sel, 3) [m] and returns the
        same shape. Equal to building the resampler on the mapped frames, to rounding. Not for
        pchip or akima, whose interpolants are not linear in their data (ValueError)."""
        if self.method not in LINEAR_IN_DATA:
            raise ValueError(f"{self.method} interpolation is not linear in its data")
        out = object.__new__(TrackResampler)
        out.n_joints, out.method, out._groups = self.n_joints, self.method, []
        for joints, t, f in self._groups:
            if self.method == "linear":
                moved = affine(t, f.reshape(t.shape[0], joints.size, 3))
                out._groups.append((joints, t, moved.reshape(t.shape[0], -1)))
                continue
            from scipy.interpolate import BSpline

            k = int(f.k)
            n_coef = f.c.shape[0]
            knots = np.asarray(f.t, dtype=np.float64)
            windows = np.lib.stride_tricks.sliding_window_view(knots[1:], k)[:n_coef]
            greville = windows.mean(axis=1)
            coef = affine(greville, f.c.reshape(n_coef, joints.size, 3)).reshape(n_coef, -1)
            out._groups.append((joints, t, BSpline.construct_fast(knots, coef, k, axis=0)))
        return out

    def __call__(self, t_out: FloatArray) -> FloatArray:
        """Positions (n_out, n_joints, 3) float64 [m] at ``t_out`` (n_out,) [s], which must lie
        within every joint's first and last valid frame (never extrapolated)."""
        t_out = np.asarray(t_out, dtype=np.float64)
        n = t_out.shape[0]
        out = np.empty((n, self.n_joints, 3), dtype=np.float64)
        for joints, t, f in self._groups:
            if t_out.size and (t_out[0] < t[0] - 1e-12 or t_out[-1] > t[-1] + 1e-12):
                who = "" if joints.size > 1 else f"joint {int(joints[0])} is valid only "
                raise ValueError(
                    f"output times {t_out[0]:.4f}..{t_out[-1]:.4f} s leave the recording; "
                    f"{who}from {t[0]:.4f} to {t[-1]:.4f} s; interpolation never extrapolates"
                )
            tq = t_out
            if n and (t_out[0] < t[0] or t_out[-1] > t[-1]):  # within the 1e-12 s tolerance
                tq = np.clip(t_out, t[0], t[-1])
            if self.method == "linear":
                vals = np.stack([np.interp(tq, t, f[:, k]) for k in range(f.shape[1])], axis=1)
            else:
                vals = f(tq)
            if len(self._groups) == 1:
                return np.asarray(vals, dtype=np.float64).reshape(n, self.n_joints, 3)
            out[:, joints, :] = vals.reshape(n, joints.size, 3)
        return out


def resample_tracks(
    time: FloatArray,
    positions: FloatArray,
    valid: BoolArray,
    t_out: FloatArray,
    method: Method = "cubic",
) -> FloatArray:
    """Interpolate joint tracks to new times (a one-off :class:`TrackResampler`).

    ``time`` (n_frames,) [s] strictly increasing; ``positions`` (n_frames, n_joints, 3) [m];
    ``valid`` (n_frames, n_joints); ``t_out`` (n_out,) [s] within every joint's first and last
    valid frame. Returns (n_out, n_joints, 3) float64 [m].
    """
    return TrackResampler(time, positions, valid, method)(t_out)
