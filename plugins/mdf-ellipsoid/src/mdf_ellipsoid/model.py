"""Body parts as a sphere (head) and spheroids along the segments.

Each part's RCS follows from its semi-axes (the height-scaled segment table) and the aspect angle
between its segment and the line of sight to the radar. A segment whose joints coincide (zero
length, e.g. untracked Kinect joints; here: shorter than 10 % of its nominal length 2c) keeps
the last valid orientation (the first valid one before it); a part that is never valid is
treated as a sphere of its radius.

``surface_points = N > 0`` (for the accuracy ladder, ``benchmarks/bench_accuracy.py``) replaces
each part's single scatterer by N points on its surface: a Fibonacci (near equal-area) set
``s_j`` on the unit sphere mapped to the spheroid, ``x_j = centre + Rot diag(a, a, c) s_j``, with
``Rot`` taking the local z axis onto the segment. Each point carries the part's RCS ``sigma``
(the single-point model's GO value for that pulse) times the share of the part's projected area
it represents toward the radar: for the line of sight ``u`` (local frame, unit), the projected area
element of the mapped sphere point is proportional to ``max(0, s_j . (u_x/a, u_y/a, u_z/c))``, so
points on the shadowed side carry nothing and the weights sum to one: the *incoherent* power sum
equals the single-point RCS, while the coherent sum now spreads each limb's return over the
Doppler of its surface (points far from a joint move faster). The points are independent point
scatterers (no surface-integral phase), so ``semi_axes``/``axes`` are not given in this mode.

``scattering_phase`` (single-scatterer mode): ``centre`` (default, Chen's code) puts each part's
scatterer at its position, the centre of its spheroid; ``specular`` puts it at the part's
geometric-optics specular point for the line of sight to the radar, the surface point whose
normal points at the radar: with ``u`` the unit vector from the centre to the radar and ``z``
the unit segment axis, ``x_s = centre + (a^2 u + (c^2 - a^2)(z.u) z) / h(u)``, with the support
function ``h(u) = sqrt(a^2 + (c^2 - a^2)(z.u)^2)``. Its range is ``R - h(u)`` in the far field, so
the echo gets the GO phase ``exp(+j 2 k h)``; as a limb turns, ``h`` changes (from ``a``
broadside to ``c`` end-on) and adds the Doppler ``+(2/lambda) dh/dt`` (positive approaching:
the range ``R - h`` falls as ``h`` grows). The sphere head's front
surface is ``a`` nearer (a constant phase). The RCS is unchanged; the spheroids' centres are
given as ``Scatterers.centres`` for the effects that need the shapes (shadowing, multipath).
Surface points already sit on the surface, so ``specular`` with ``surface_points > 0`` is refused.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from mdframework import Motion, PluginConfig, ScattererModel, Scatterers, Skeleton
from mdframework.physics import body as bodymodel
from mdframework.physics import rcs

#: Segments shorter than this fraction of their nominal length have no usable orientation
#: (coincident joints, and the spline's small ringing around such a collapse).
MIN_SEGMENT_FRACTION = 0.1


class EllipsoidConfig(PluginConfig):
    """Sphere head and spheroid limbs."""

    kind: Literal["ellipsoid"] = "ellipsoid"
    placement: Literal["joints17", "chen16"] = Field(
        "joints17",
        description="joints17: one scatterer per canonical joint (the paper's K = 17); "
        "chen16: Chen's 16 body parts.",
    )
    head: Literal["sphere", "spheroid"] = Field(
        "sphere", description="The head as a sphere of radius 0.1 m (paper) or Chen's spheroid."
    )
    sphere_rcs: Literal["optical", "mie"] = Field(
        "optical", description="Sphere RCS: optical pi r^2, or the exact Mie series."
    )
    surface_points: int = Field(
        0,
        ge=0,
        le=1024,
        description="0: one scatterer per part; N > 0: N points on each part's surface, "
        "weighted by their projected area toward the radar.",
    )
    height: float | None = Field(
        None,
        gt=0.5,
        lt=2.5,
        description="Body height [m] for segment sizes; default: estimated from the legs.",
    )
    scattering_phase: Literal["centre", "specular"] = Field(
        "centre",
        description="centre: each part's scatterer at its centre (Chen); specular: at its "
        "specular point for the radar, h(u) nearer (the GO phase of the spheroid's echo).",
    )

    @model_validator(mode="after")
    def _one_placement(self) -> EllipsoidConfig:
        if self.scattering_phase == "specular" and self.surface_points > 0:
            raise ValueError(
                "scattering_phase = 'specular' needs surface_points = 0: surface points "
                "already lie on the surface"
            )
        return self


def _usable(length2: np.ndarray, semi_c: np.ndarray) -> np.ndarray:
    """Segments long enough to give an orientation, from their squared lengths |axis|^2 (any
    shape ending in n_parts) and the parts' semi-axes c (n_parts,): bool, the same shape."""
    return np.asarray(length2 > (MIN_SEGMENT_FRACTION * 2.0 * semi_c) ** 2)


def _plane_dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Dot products of vectors stored coordinates first, (3, ...) -> (...)."""
    out = x[0] * y[0]
    out += x[1] * y[1]
    out += x[2] * y[2]
    return out


def hold_last_valid(axes: np.ndarray, ok: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Replace invalid rows of ``axes`` (n_pulses, n_parts, 3) by the last valid one (or the
    first valid one before any). Returns the filled axes and a (n_parts,) mask of parts that are
    never valid."""
    n_p = axes.shape[0]
    idx = np.where(ok, np.arange(n_p)[:, None], -1)
    np.maximum.accumulate(idx, axis=0, out=idx)
    first = np.argmax(ok, axis=0)
    idx = np.where(idx < 0, first[None, :], idx)
    filled = np.take_along_axis(axes, idx[:, :, None], axis=0)
    return filled, ~np.any(ok, axis=0)


def fibonacci_sphere(n: int) -> np.ndarray:
    """``n`` near equal-area unit vectors (n, 3) (Fibonacci lattice)."""
    k = np.arange(n, dtype=np.float64) + 0.5
    z = 1.0 - 2.0 * k / n
    r = np.sqrt(np.clip(1.0 - z * z, 0.0, None))
    phi = np.pi * (3.0 - np.sqrt(5.0)) * k
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def _unit_axes(axes: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(axes, axis=-1, keepdims=True)
    return np.where(n > 0, axes / np.where(n > 0, n, 1.0), np.array([0.0, 0.0, 1.0]))


def helper_directions(axes: np.ndarray) -> np.ndarray:
    """(n_parts, 3): per part, the world axis least aligned with its segment at any frame of
    ``axes`` (n_frames, n_parts, 3); it fixes the roll of :func:`segment_frames`."""
    worst = np.max(np.abs(_unit_axes(axes)), axis=0)
    return np.asarray(np.eye(3)[np.argmin(worst, axis=-1)])


def segment_frames(axes: np.ndarray, helper: np.ndarray | None = None) -> np.ndarray:
    """Rotations (n_pulses, n_parts, 3, 3) whose third column is the unit ``axes`` (n_pulses,
    n_parts, 3). The roll about the axis is fixed by one helper direction per part over the
    whole record (``helper`` (n_parts, 3), default :func:`helper_directions` of ``axes``), so
    the frame turns smoothly with the segment and surface points do not jump between pulses."""
    z = _unit_axes(axes)
    if helper is None:
        helper = helper_directions(axes)
    helper = helper[None, :, :]
    x = helper - np.sum(helper * z, -1, keepdims=True) * z
    x /= np.linalg.norm(x, axis=-1, keepdims=True)
    return np.stack([x, np.cross(z, x), z], axis=-1)


def surface_scatterers(
    pos: np.ndarray,
    axes: np.ndarray,
    a: np.ndarray,
    semi_c: np.ndarray,
    sigma: np.ndarray,
    radar_position: np.ndarray,
    n_points: int,
    helper: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Surface points (n_pulses, n_parts * n_points, 3) [m] and their RCS (n_pulses,
    n_parts * n_points) [m^2] (see the module docstring), part-major order."""
    s = fibonacci_sphere(n_points)
    rot = segment_frames(axes, helper)
    scale = np.stack([a, a, semi_c], axis=1)
    local = s[None, :, :] * scale[:, None, :]
    pts = pos[:, :, None, :] + np.einsum("psij,sqj->psqi", rot, local)
    los = np.asarray(radar_position, dtype=np.float64) - pos
    u = np.einsum("psji,psj->psi", rot, los)
    u /= np.linalg.norm(u, axis=-1, keepdims=True)
    w = np.einsum("qj,psj->psq", s, u / scale[None, :, :])
    w = np.clip(w, 0.0, None)
    # with few points none may face the radar: the part's RCS is then shared equally
    total = np.sum(w, axis=-1, keepdims=True)
    w = np.where(total > 0, w / np.where(total > 0, total, 1.0), 1.0 / n_points)
    n_p, n_s = sigma.shape
    return pts.reshape(n_p, n_s * n_points, 3), (sigma[:, :, None] * w).reshape(n_p, -1)


class EllipsoidBody(ScattererModel):
    """Sphere/spheroid RCS of the canonical body parts."""

    name = "ellipsoid"
    Config = EllipsoidConfig
    config: EllipsoidConfig

    def start_record(self, body: Skeleton) -> None:
        """Record-wide quantities, so that any cut into blocks gives the same scatterers: the
        body height (unless configured) from the record's joints (n_frames, 17, 3), and each
        part's first usable orientation (held over untracked pulses before it)."""
        c = self.config
        self._parts = bodymodel.body_parts(c.placement, c.head)
        height = c.height if c.height is not None else bodymodel.estimate_height(body.positions)
        self._a, self._semi_c = bodymodel.part_semi_axes(self._parts, height)
        _, axes = bodymodel.part_geometry(self._parts, body.positions)
        ok = _usable(np.sum(axes * axes, axis=-1), self._semi_c)
        self._carry = axes[np.argmax(ok, axis=0), np.arange(axes.shape[1])]
        self._never = ~np.any(ok, axis=0)
        # the surface points' roll about each segment (their frames only)
        self._helper = helper_directions(axes) if c.surface_points > 0 else None

    def scatterers(
        self, motion: Motion, skeleton: Skeleton, radar_position: np.ndarray, wavelength: float
    ) -> Scatterers:
        """Positions and RCS of every body part at every pulse of a block."""
        c = self.config
        if not hasattr(self, "_carry"):  # used without a record (a one-off block)
            self.start_record(skeleton)
        parts, a, semi_c = self._parts, self._a, self._semi_c
        # coordinates first, (3, n_pulses, n_parts): every product runs over contiguous planes
        joint_planes = np.ascontiguousarray(np.moveaxis(skeleton.positions, -1, 0))
        pos_t, axes_t = bodymodel.part_geometry(parts, joint_planes, joint_axis=-1)
        norm2 = _plane_dot(axes_t, axes_t)
        ok = _usable(norm2, semi_c)
        if not np.all(ok):
            ext = np.concatenate((self._carry[None], np.moveaxis(axes_t, 0, -1)))
            ok_ext = np.concatenate((~self._never[None], ok))
            filled, _ = hold_last_valid(ext, ok_ext)
            axes_t = np.ascontiguousarray(np.moveaxis(filled[1:], -1, 0))
            semi_c = np.where(self._never, a, semi_c)
            norm2 = _plane_dot(axes_t, axes_t)
        axes = np.moveaxis(axes_t, 0, -1)  # (n_pulses, n_parts, 3), a view
        self._carry = axes[-1].copy()
        rp = np.asarray(radar_position, dtype=np.float64)
        los_t = rp[:, None, None] - pos_t
        los2 = _plane_dot(los_t, los_t)
        dot = _plane_dot(axes_t, los_t)
        sigma = rcs.spheroid_rcs_from_products(a, semi_c, dot, norm2, los2)
        spheres = np.array([p.sphere for p in parts])
        if np.any(spheres):
            if c.sphere_rcs == "mie":
                value = np.array([rcs.sphere_rcs_mie(r, wavelength) for r in a[spheres]])
            else:
                value = rcs.sphere_rcs_optical(a[spheres])
            sigma[:, spheres] = value
        names = tuple(p.name for p in parts)
        pos = (
            skeleton.positions
            if pos_t is joint_planes
            else np.ascontiguousarray(np.moveaxis(pos_t, 0, -1))
        )
        if c.surface_points > 0:
            n = c.surface_points
            pts, sig = surface_scatterers(
                pos, axes, a, semi_c, sigma, radar_position, n, self._helper
            )
            return Scatterers(pts, sig, tuple(f"{m}#{j}" for m in names for j in range(n)))
        semi_axes = np.stack([a, a, semi_c], axis=1)
        if c.scattering_phase == "specular":
            _, alpha, beta = rcs.spheroid_specular_from_products(a, semi_c, dot, norm2, los2)
            spec_t = alpha * los_t
            spec_t += beta * axes_t
            spec_t += pos_t
            los_t = rp[:, None, None] - spec_t
            ranges = np.sqrt(_plane_dot(los_t, los_t))
            spec = np.ascontiguousarray(np.moveaxis(spec_t, 0, -1))
            mask = np.ones(len(names), dtype=bool)
            scat = Scatterers(spec, sigma, names, semi_axes, axes, centres=pos, specular=mask)
            return scat.with_ranges(rp, ranges)
        scat = Scatterers(pos, sigma, names, semi_axes, axes)
        return scat.with_ranges(rp, np.sqrt(los2, out=los2))
