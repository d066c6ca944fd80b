"""Boulic (1990) global walking model as coded by V.C. Chen ("The Micro-Doppler
Effect in Radar", 2011).

Pure numpy: the gait parameters, the joint-angle and translation trajectories as functions of the
cycle phase, and a plain evaluation of the kinematic chain with Chen's passive Euler matrices
(:func:`chain_positions`, the reference the MuJoCo model is checked against).

Frames and units: walker frame, ``x`` forward, ``y`` to the walker's left, ``z`` up; metres,
seconds; angles are degrees in the trajectory tables and radians everywhere else.

Two modes (``chen_compatible``):

- **corrected** (default):

  * Q1: the base advances ``RLc * H_t`` per cycle, i.e. it moves at ``rv * H_t`` m/s
    (Boulic's relative length is in units of the leg length ``H_t = 0.491 H``).
  * Q2: gait class ``a`` uses the lateral and forward/backward amplitudes with the sign of
    classes ``b``/``c`` (``al = 0.128 rv^2 - 0.128 rv``, ``aa = 0.084 rv^2 - 0.084 rv``), so
    they are continuous at ``rv = 0.5``.
  * Q3: the elbow's gait-``c`` third control value is ``-6 (rv - 1.3)/1.7 + 17``.
  * Q4: the elbows are rotated with the upper body using their current height (rigid arms).
  * Q6: the forward progression is exactly linear in time (no ``linspace`` end-point step).
  * Origin: the body is lifted by ``H_t`` so that the feet walk near ``z = 0``.
- **chen_compatible**: the code as written: base at ``rv`` m/s (Q1), the gait-``a`` sign flip
  (Q2), the ``(rv - .13)`` elbow typo (Q3), the elbow height frozen at the first sample (Q4),
  the per-cycle ``linspace(0, RLc - RLc/(nt+1), nt)`` progression (Q6) and Chen's origin at the
  base (hip centre at ``z = 0``, feet near ``z = -H_t``).

Not changed in either mode: the feet slide (Q8, nothing pins the stance foot); the pelvis
left/right amplitude is Boulic's ``1.66 rv`` (the Python port's ``0.01 rv`` of Q7 is not
followed); translations are in metres as in Chen's code.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from mdframework import CANONICAL_JOINTS
from mdframework.physics.body import LEG_FRACTION, SEGMENT_FRACTIONS

FloatArray = NDArray[np.float64]

GaitClass = Literal["a", "b", "c"]

#: Names of the angle and translation tracks returned by :meth:`Gait.tracks`.
TRACK_NAMES: tuple[str, ...] = (
    "vertical",
    "lateral",
    "forward",
    "rot_forback",
    "rot_leftright",
    "torsion",
    "hip",
    "knee",
    "ankle",
    "thorax",
    "shoulder",
    "elbow",
)


def cycle_duration(rv: float) -> float:
    """Dc = RLc / rv [s] of the relative velocity ``rv`` [1/s], RLc = 1.346 sqrt(rv)."""
    return 1.346 * float(np.sqrt(rv)) / rv


def gait_class(rv: float) -> GaitClass:
    """Boulic's gait class for the relative velocity ``rv`` [1/s]: ``a`` below 0.5, ``b`` below
    1.3, ``c`` up to 3. Raises ``ValueError`` outside ``0 < rv <= 3``."""
    if not rv > 0:
        raise ValueError(f"relative velocity rv must be > 0, got {rv}")
    if rv < 0.5:
        return "a"
    if rv < 1.3:
        return "b"
    if rv <= 3:
        return "c"
    raise ValueError(f"relative velocity rv must be <= 3, got {rv}")


def _periodic_pchip(xs: list[float], ys: list[float], phase: FloatArray) -> FloatArray:
    """PCHIP through control points replicated at ``x - 1, x, x + 1`` (duplicate knots dropped,
    as Chen's code does for the hip), evaluated at ``phase`` in [0, 1)."""
    kx = np.concatenate([np.asarray(xs) + s for s in (-1.0, 0.0, 1.0)])
    ky = np.concatenate([np.asarray(ys)] * 3)
    order = np.argsort(kx, kind="stable")
    kx, ky = kx[order], ky[order]
    keep = np.ones(kx.shape, dtype=bool)
    keep[1:] = np.diff(kx) > 1e-12
    from scipy.interpolate import PchipInterpolator

    return np.asarray(PchipInterpolator(kx[keep], ky[keep])(phase), dtype=np.float64)


@dataclass(frozen=True)
class Dimensions:
    """Segment lengths [m] of a walker of height ``height`` [m]."""

    height: float

    def __getattr__(self, name: str) -> float:
        if name in SEGMENT_FRACTIONS:
            return SEGMENT_FRACTIONS[name] * self.height
        raise AttributeError(name)

    @property
    def leg(self) -> float:
        """H_t = 0.491 H, the hip height [m]."""
        return LEG_FRACTION * self.height


@dataclass(frozen=True)
class Gait:
    """One walker: height ``height`` [m], relative velocity ``rv`` [1/s], samples per cycle
    ``nt`` (even; used by the chen-compatible progression and the elbow quirk's first sample)
    and the mode."""

    height: float
    rv: float
    nt: int = 2048
    chen_compatible: bool = False

    def __post_init__(self) -> None:
        gait_class(self.rv)
        if self.nt < 4 or self.nt % 2:
            raise ValueError(f"nt must be even and >= 4, got {self.nt}")
        if not self.height > 0:
            raise ValueError(f"height must be > 0, got {self.height}")

    # ------------------------------------------------------------------ timing

    @property
    def gait(self) -> GaitClass:
        """Gait class a, b or c."""
        return gait_class(self.rv)

    @property
    def dims(self) -> Dimensions:
        """Segment lengths [m]."""
        return Dimensions(self.height)

    @property
    def relative_cycle_length(self) -> float:
        """RLc = 1.346 sqrt(rv), the cycle length in units of H_t."""
        return 1.346 * float(np.sqrt(self.rv))

    @property
    def cycle_duration(self) -> float:
        """Dc = RLc / rv [s]."""
        return cycle_duration(self.rv)

    @property
    def support_duration(self) -> float:
        """Ds = 0.752 Dc - 0.143 [s]."""
        return 0.752 * self.cycle_duration - 0.143

    @property
    def support_fraction(self) -> float:
        """Ds / Dc."""
        return self.support_duration / self.cycle_duration

    @property
    def cycle_advance(self) -> float:
        """Distance the base advances per cycle [m]: RLc H_t (corrected) or RLc (Chen, Q1)."""
        rlc = self.relative_cycle_length
        return rlc if self.chen_compatible else rlc * self.dims.leg

    @property
    def speed(self) -> float:
        """Mean forward speed of the base [m/s]: rv H_t (corrected) or rv (Chen, Q1)."""
        return self.cycle_advance / self.cycle_duration

    @property
    def origin_height(self) -> float:
        """Height of the base above the walker frame's origin without the vertical oscillation
        [m]: H_t (corrected: feet near z = 0) or 0 (Chen's frame)."""
        return 0.0 if self.chen_compatible else self.dims.leg

    # ------------------------------------------------------------------ trajectories

    def tracks(self, phase: FloatArray) -> dict[str, FloatArray]:
        """Trajectories of the right side at cycle phases ``phase`` (n,) in [0, 1).

        Returns a dict over :data:`TRACK_NAMES`: translations ``vertical``, ``lateral``,
        ``forward`` [m] (offsets of the base, without the progression) and angles [deg]. The
        left side uses the angles at ``phase + 0.5``.
        """
        p = np.asarray(phase, dtype=np.float64)
        rv, g, chen = self.rv, self.gait, self.chen_compatible
        u = (rv - 1.3) / 1.7
        w = (rv - 0.5) / 0.8
        dsmod = self.support_fraction
        two_pi = 2.0 * np.pi
        out: dict[str, FloatArray] = {}
        av = 0.015 * rv
        out["vertical"] = -av + av * np.sin(two_pi * (2 * p - 0.35))
        sign_a = 1.0 if chen else -1.0  # Q2
        al = sign_a * (-0.128 * rv**2 + 0.128 * rv) if g == "a" else -0.032
        out["lateral"] = al * np.sin(two_pi * (p - 0.1))
        aa = sign_a * (-0.084 * rv**2 + 0.084 * rv) if g == "a" else -0.021
        phia = 0.625 - dsmod
        out["forward"] = aa * np.sin(two_pi * (2 * p + 2 * phia))
        a1 = -8 * rv**2 + 8 * rv if g == "a" else 2.0
        out["rot_forback"] = -a1 + a1 * np.sin(two_pi * (2 * p - 0.1))
        a2 = 1.66 * rv
        out["rot_leftright"] = np.select(
            [p < 0.15, p < 0.5, p < 0.65],
            [
                -a2 + a2 * np.cos(two_pi * 10 * p / 3),
                -a2 - a2 * np.cos(two_pi * 10 * (p - 0.15) / 7),
                a2 - a2 * np.cos(two_pi * 10 * (p - 0.5) / 3),
            ],
            a2 + a2 * np.cos(two_pi * 10 * (p - 0.65) / 7),
        )
        out["torsion"] = -4 * rv * np.cos(two_pi * p)
        if g == "a":
            hip = ([-0.1, 0.5, 0.9], [50 * rv, -30 * rv, 50 * rv])
            knee = ([0.17, 0.4, 0.75, 1.0], [3, 3, 140 * rv, 3])
            ankle = ([0, 0.08, 0.5, dsmod, 0.85], [-3, -30 * rv - 3, 22 * rv - 3, -34 * rv - 3, -3])
            elbow = ([0.05, 0.5, 0.9], [6 * rv + 3, 34 * rv + 3, 10 * rv + 3])
        elif g == "b":
            hip = ([-0.1, 0.5, 0.9], [25, -15, 25])
            knee = ([0.17, 0.4, 0.75, 1.0], [3, 3, 70, 3])
            ankle = ([0, 0.08, 0.5, dsmod, 0.85], [-3, -18, 8, -20, -3])
            elbow = ([0.05, 0.01 * w + 0.5, 0.9], [8 * w + 6, 24 * w + 20, 9 * w + 8])
        else:
            hip = ([0.2 * u - 0.1, 0.5, 0.9], [5 * u + 25, -15, 6 * u + 25])
            knee = (
                [-0.05 * u + 0.17, 0.4, -0.05 * u + 0.75, -0.03 * u + 1],
                [22 * u + 3, 3, -5 * u + 70, 3 * u + 3],
            )
            ankle = (
                [0, 0.08, -0.1 * u + 0.5, dsmod, 0.85],
                [5 * u - 3, 4 * u - 18, -3 * u + 8, -8 * u - 20, 5 * u - 3],
            )
            y3 = -6 * (rv - 0.13) / 1.7 + 17 if chen else -6 * u + 17  # Q3
            elbow = ([0.05, 0.04 * u + 0.51, -0.1 * u + 0.9], [-6 * u + 14, 26 * u + 44, y3])
        thorax = ([0.1, 0.4, 0.6, 0.9], [4 * rv / 3, -4.5 * rv / 3, -4 * rv / 3, 4.5 * rv / 3])
        for name, (xs, ys) in (
            ("hip", hip),
            ("knee", knee),
            ("ankle", ankle),
            ("thorax", thorax),
            ("elbow", elbow),
        ):
            out[name] = _periodic_pchip(list(xs), [float(y) for y in ys], p)
        a_s = 9.88 * rv
        out["shoulder"] = 3 - a_s / 2 - a_s * np.cos(two_pi * p)
        return out

    def progression(self, time: FloatArray) -> FloatArray:
        """Forward progression of the base [m] at ``time`` (n,) [s] from the start.

        Corrected: ``speed * t``. Chen (Q6): ``k RLc + linspace(0, RLc - RLc/(nt+1), nt)``
        within cycle ``k``, interpolated linearly between the samples."""
        t = np.asarray(time, dtype=np.float64)
        if not self.chen_compatible:
            return self.speed * t
        rlc, nt = self.relative_cycle_length, self.nt
        cycles = np.floor(t / self.cycle_duration + 1e-12)
        within = t / self.cycle_duration - cycles
        step = (rlc - rlc / (nt + 1)) / (nt - 1)
        return np.asarray(cycles * rlc + within * nt * step, dtype=np.float64)

    def phase(self, time: FloatArray) -> FloatArray:
        """Cycle phase in [0, 1) at ``time`` (n,) [s]."""
        x = np.asarray(time, dtype=np.float64) / self.cycle_duration
        p = x - np.floor(x + 1e-12)
        return np.asarray(np.clip(p, 0.0, None), dtype=np.float64)


# ---------------------------------------------------------------------- plain numpy chain


def chen_rotation(psi: FloatArray, theta: FloatArray, phi: FloatArray) -> FloatArray:
    """Chen's ``XYZConvention`` Euler matrix ``Rz(phi) Ry(theta) Rx(psi)`` with passive
    matrices; angles (n,) [rad], result (n, 3, 3)."""
    psi, theta, phi = (np.asarray(a, dtype=np.float64) for a in (psi, theta, phi))
    n = np.broadcast(psi, theta, phi).shape
    cx, sx, cy, sy = np.cos(psi), np.sin(psi), np.cos(theta), np.sin(theta)
    cz, sz = np.cos(phi), np.sin(phi)
    one, zero = np.ones(n), np.zeros(n)
    rx = np.stack([one, zero, zero, zero, cx, sx, zero, -sx, cx], -1).reshape(*n, 3, 3)
    ry = np.stack([cy, zero, -sy, zero, one, zero, sy, zero, cy], -1).reshape(*n, 3, 3)
    rz = np.stack([cz, sz, zero, -sz, cz, zero, zero, zero, one], -1).reshape(*n, 3, 3)
    return np.asarray(rz @ ry @ rx, dtype=np.float64)


def _apply(r: FloatArray, v: FloatArray) -> FloatArray:
    return np.asarray(np.einsum("nij,nj->ni", r, v), dtype=np.float64)


def chain_positions(gait: Gait, time: FloatArray) -> FloatArray:
    """Canonical joints (n, 17, 3) [m] at ``time`` (n,) [s] by Chen's kinematic chain,
    evaluated step by step with his passive matrices, in the walker frame.

    This is the reference evaluation; the MuJoCo model must reproduce it (in chen-compatible
    mode the frozen elbow height Q4 is applied here too)."""
    t = np.asarray(time, dtype=np.float64)
    n = t.shape[0]
    d = gait.dims
    phase = gait.phase(t)
    right = gait.tracks(phase)
    left = gait.tracks(np.mod(phase + 0.5, 1.0))
    deg = np.pi / 180.0
    zero = np.zeros(n)
    ones = np.ones(n)
    pts: dict[str, FloatArray] = {}

    def vec(x: FloatArray | float, y: FloatArray | float, z: FloatArray | float) -> FloatArray:
        return np.stack([x * ones, y * ones, z * ones], axis=1)

    for side, tr, y0 in (("l", left, d.hip), ("r", right, -d.hip)):
        r_a = chen_rotation(zero, tr["ankle"] * deg, zero)
        toe = _apply(r_a, vec(d.foot, 0.0, 0.0)) + vec(0.0, y0, -(d.upper_leg + d.lower_leg))
        r_k = chen_rotation(zero, -tr["knee"] * deg, zero)
        ankle = _apply(r_k, vec(0.0, 0.0, -d.lower_leg)) + vec(0.0, y0, -d.upper_leg)
        toe = _apply(r_k, vec(toe[:, 0], 0.0, toe[:, 2] + d.upper_leg)) + vec(0, y0, -d.upper_leg)
        r_h = chen_rotation(zero, tr["hip"] * deg, zero)
        knee = _apply(r_h, vec(0.0, 0.0, -d.upper_leg)) + vec(0.0, y0, 0.0)
        ankle = _apply(r_h, vec(ankle[:, 0], 0.0, ankle[:, 2])) + vec(0.0, y0, 0.0)
        toe = _apply(r_h, vec(toe[:, 0], 0.0, toe[:, 2])) + vec(0.0, y0, 0.0)
        pts.update({f"{side}_knee": knee, f"{side}_ankle": ankle, f"{side}_toe": toe})
    # pelvis rotation (always the right side's tracks, as in Chen's code)
    r_p = chen_rotation(-right["rot_leftright"] * deg, zero, right["torsion"] * deg)
    pts["l_hip"] = _apply(r_p, vec(0.0, d.hip, 0.0))
    pts["r_hip"] = _apply(r_p, vec(0.0, -d.hip, 0.0))
    for k in ("l_knee", "r_knee", "l_ankle", "r_ankle", "l_toe", "r_toe"):
        pts[k] = _apply(r_p, pts[k])
    # arms
    elbow_local: dict[str, FloatArray] = {}
    for side, tr, ys in (("l", left, d.shoulder), ("r", right, -d.shoulder)):
        r_e = chen_rotation(zero, tr["elbow"] * deg, zero)
        hand = _apply(r_e, vec(0.0, 0.0, -d.lower_arm)) + vec(0.0, ys, d.torso - d.upper_arm)
        r_s = chen_rotation(zero, tr["shoulder"] * deg, zero)
        elbow = _apply(r_s, vec(0.0, 0.0, -d.upper_arm)) + vec(0.0, ys, d.torso)
        hand = _apply(r_s, vec(hand[:, 0], 0.0, hand[:, 2] - d.torso)) + vec(0.0, ys, d.torso)
        elbow_local[side] = elbow
        pts[f"{side}_hand"] = hand
    r_u = chen_rotation(zero, right["rot_forback"] * deg, right["thorax"] * deg)
    pts["head"] = _apply(r_u, vec(0.0, 0.0, d.torso + d.head))
    pts["neck"] = _apply(r_u, vec(0.0, 0.0, d.torso))
    pts["l_shoulder"] = _apply(r_u, vec(0.0, d.shoulder, d.torso))
    pts["r_shoulder"] = _apply(r_u, vec(0.0, -d.shoulder, d.torso))
    for side in ("l", "r"):
        e = elbow_local[side].copy()
        if gait.chen_compatible:  # Q4: z of the first sample of the cycle (phase 0)
            e[:, 2] = frozen_elbow_z(gait, side)
        pts[f"{side}_elbow"] = _apply(r_u, e)
        pts[f"{side}_hand"] = _apply(r_u, pts[f"{side}_hand"])
    pts["base"] = np.zeros((n, 3))
    out = np.stack([pts[j] for j in CANONICAL_JOINTS], axis=1)
    out += base_translation(gait, t)[:, None, :]
    return out


def frozen_elbow_z(gait: Gait, side: str) -> float:
    """Q4: the elbow height [m] before the upper-body rotation at the first sample (phase 0)
    that Chen's code uses for every sample (``lelbow(3,1)``)."""
    phase0 = np.array([0.0 if side == "r" else 0.5])
    shoulder = gait.tracks(phase0)["shoulder"][0] * np.pi / 180.0
    return float(gait.dims.torso - gait.dims.upper_arm * np.cos(shoulder))


def base_translation(gait: Gait, time: FloatArray) -> FloatArray:
    """Position of the base (hip centre) [m] at ``time`` (n,) [s], (n, 3): progression plus the
    forward/backward, lateral and vertical oscillations, plus the origin height."""
    t = np.asarray(time, dtype=np.float64)
    tr = gait.tracks(gait.phase(t))
    x = gait.progression(t) + tr["forward"]
    return np.stack([x, tr["lateral"], tr["vertical"] + gait.origin_height], axis=1)
