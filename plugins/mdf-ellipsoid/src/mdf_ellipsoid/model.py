"""Body parts as a sphere (head) and spheroids along the segments (``physics.md`` section 2).

Each part's RCS follows from its semi-axes (the height-scaled segment table) and the aspect angle
between its segment and the line of sight to the radar. A segment whose joints coincide (zero
length, e.g. untracked Kinect joints; here: shorter than 10 % of its nominal length 2c) keeps
the last valid orientation (the first valid one before it); a part that is never valid is
treated as a sphere of its radius.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from mdframework import Motion, PluginConfig, ScattererModel, Scatterers, Skeleton
from mdframework.physics import body, rcs

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
    height: float | None = Field(
        None,
        gt=0.5,
        lt=2.5,
        description="Body height [m] for segment sizes; default: estimated from the legs.",
    )


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


class EllipsoidBody(ScattererModel):
    """Sphere/spheroid RCS of the canonical body parts."""

    name = "ellipsoid"
    Config = EllipsoidConfig
    config: EllipsoidConfig

    def scatterers(
        self, motion: Motion, skeleton: Skeleton, radar_position: np.ndarray, wavelength: float
    ) -> Scatterers:
        """Positions and RCS of every body part at every pulse."""
        c = self.config
        parts = body.body_parts(c.placement, c.head)
        joints = skeleton.positions
        height = c.height if c.height is not None else body.estimate_height(joints)
        a, semi_c = body.part_semi_axes(parts, height)
        pos, axes = body.part_geometry(parts, joints)
        length2 = axes[..., 0] ** 2 + axes[..., 1] ** 2 + axes[..., 2] ** 2
        ok = length2 > (MIN_SEGMENT_FRACTION * 2.0 * semi_c) ** 2
        if not np.all(ok):
            axes, never = hold_last_valid(axes, ok)
            semi_c = np.where(never, a, semi_c)
        los = np.asarray(radar_position, dtype=np.float64) - pos
        sigma = rcs.spheroid_rcs(a, semi_c, axes, los)
        spheres = np.array([p.sphere for p in parts])
        if np.any(spheres):
            if c.sphere_rcs == "mie":
                value = np.array([rcs.sphere_rcs_mie(r, wavelength) for r in a[spheres]])
            else:
                value = rcs.sphere_rcs_optical(a[spheres])
            sigma[:, spheres] = value
        semi_axes = np.stack([a, a, semi_c], axis=1)
        return Scatterers(pos, sigma, tuple(p.name for p in parts), semi_axes, axes)
