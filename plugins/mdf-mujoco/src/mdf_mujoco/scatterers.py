"""Body-part ellipsoids with their true orientation (kind ``mujoco_body``).

For a Boulic motion the MuJoCo model is evaluated at every pulse time (``mj_kinematics`` per
pulse) and each geom's centre, axes and semi-axes are read from ``geom_xpos``, ``geom_xmat`` and
``geom_size``. The walker frame is mapped to the scene by the rigid motion the pipeline's
placement applied (a rotation about the vertical, found once by least squares, and a translation
per pulse, from the base), checked against the placed skeleton. The RCS uses the line of sight in
each geom's own frame (:func:`mdframework.physics.rcs.ellipsoid_rcs_local`), so ellipsoids with
``a != b`` (set through ``radii``) get the correct aspect.

For other motions (CMU, Kinect...) the geoms are built around the canonical segments: c-axis
along the segment, a-axis the body's forward direction made orthogonal to it.

With Chen's radii (``a = b``, the default) the orientation about the segment does not matter and
the RCS equals that of the ``ellipsoid`` model with the same placement (tested).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, field_validator

from mdframework import (
    CANONICAL_JOINTS,
    Motion,
    PluginConfig,
    ScattererModel,
    Scatterers,
    Skeleton,
)
from mdframework.physics import body, rcs
from mdframework.physics.body import PART_RADII, SEGMENT_FRACTIONS

from .body_model import PART_JOINTS, PART_NAMES, PART_SEGMENT, WalkerBody
from .source import BoulicMotion

#: A body part's semi-axis [m]: above 0, at most 1 m.
SemiAxis = Annotated[float, Field(gt=0, le=1.0)]

FloatArray = NDArray[np.float64]

_J = {name: i for i, name in enumerate(CANONICAL_JOINTS)}

#: Largest allowed mismatch [m] between the placed skeleton and the rigidly moved MuJoCo joints.
MAX_PLACEMENT_RESIDUAL = 5e-3


@dataclass(frozen=True)
class BodyScatterers(Scatterers):
    """:class:`~mdframework.Scatterers` with the full ellipsoid frames: ``centres``
    (n_pulses, n_scat, 3) [m] (the base class's field) and ``rotations`` (n_pulses, n_scat,
    3, 3), whose columns are the a-, b- and c-axes (unit vectors, scene frame)."""

    rotations: FloatArray | None = None


class MujocoBodyConfig(PluginConfig):
    """Ellipsoid body parts with their true orientation (MuJoCo geoms for the Boulic walker)."""

    kind: Literal["mujoco_body"] = "mujoco_body"
    placement: Literal["centres", "chen16"] = Field(
        "centres",
        description="centres: each part's scatterer at its ellipsoid's centre; chen16: at Chen's "
        "points (head top, hand, toe, shoulder and hip joints, midpoints otherwise).",
    )
    radii: dict[str, tuple[SemiAxis, SemiAxis]] | None = Field(
        None,
        description="Semi-axes (a, b) [m] per segment (head, torso, shoulder, upper_arm, "
        "lower_arm, hip, upper_leg, lower_leg, foot); a is forward (up for the feet). "
        "Default: Chen's a = b (0.05-0.15 m), the same at every height: only c (half the "
        "segment's length) scales with the height.",
    )
    height: float | None = Field(
        None, gt=0.5, lt=2.5, description="Height [m] for non-Boulic motions; default estimated."
    )

    @field_validator("radii")
    @classmethod
    def _known(
        cls, v: dict[str, tuple[float, float]] | None
    ) -> dict[str, tuple[float, float]] | None:
        if v:
            bad = sorted(set(v) - set(PART_RADII))
            if bad:
                raise ValueError(f"unknown segments {bad}; known: {sorted(PART_RADII)}")
        return v


def rotation_about_z(walker: FloatArray, scene: FloatArray) -> float:
    """Angle [rad] of the rotation about +z that best maps ``walker`` joints onto ``scene``
    joints (both (n, k, 3) [m], each taken relative to its joint 0) in least squares."""
    w = walker - walker[:, :1]
    s = scene - scene[:, :1]
    cross = np.sum(w[..., 0] * s[..., 1] - w[..., 1] * s[..., 0])
    dot = np.sum(w[..., 0] * s[..., 0] + w[..., 1] * s[..., 1])
    return float(np.arctan2(cross, dot))


def _unit(v: FloatArray) -> tuple[FloatArray, FloatArray]:
    n = np.sqrt(np.sum(v * v, axis=-1))
    return v / np.where(n > 0, n, 1.0)[..., None], n


class MujocoBody(ScattererModel):
    """Ellipsoids with their own frames (kind ``mujoco_body``)."""

    name = "mujoco_body"
    Config = MujocoBodyConfig
    config: MujocoBodyConfig

    def start_record(self, body_: Skeleton) -> None:
        """The body height for the segment sizes, from the whole record (block-invariant)."""
        self._height = self.config.height or body.estimate_height(body_.positions)

    def scatterers(
        self, motion: Motion, skeleton: Skeleton, radar_position: FloatArray, wavelength: float
    ) -> Scatterers:
        """Scatterers of the 16 parts at every pulse of a block (names as the ``chen16``
        placement)."""
        if isinstance(motion, BoulicMotion) and motion.gait is not None:
            joints, centres, rot, semi = self._boulic_frames(motion, skeleton)
        else:
            joints, centres, rot, semi = self._segment_frames(skeleton)
        if self.config.placement == "chen16":
            positions, _ = body.part_geometry(body.body_parts("chen16", "spheroid"), joints)
        else:
            positions = centres
        los, _ = _unit(np.asarray(radar_position, dtype=np.float64) - positions)
        local = np.einsum("psji,psj->psi", rot, los)  # R^T u: line of sight in the geom frame
        sigma = rcs.ellipsoid_rcs_local(semi[:, 0], semi[:, 1], semi[:, 2], local)
        axes = rot[..., 2] * semi[None, :, 2, None]
        return BodyScatterers(
            positions, sigma, PART_NAMES, semi.copy(), axes, centres=centres, rotations=rot
        )

    def _boulic_frames(
        self, motion: BoulicMotion, skeleton: Skeleton
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        assert motion.gait is not None
        walker = WalkerBody(motion.gait, self.config.radii)
        frames = walker.frames(skeleton.time)
        placed = skeleton.positions
        angle = rotation_about_z(frames.joints, placed)
        c, s = np.cos(angle), np.sin(angle)
        rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        shift = placed[:, 0] - frames.joints[:, 0] @ rz.T
        joints = frames.joints @ rz.T + shift[:, None, :]
        residual = float(np.max(np.abs(joints - placed)))
        if residual > MAX_PLACEMENT_RESIDUAL:
            raise ValueError(
                f"mujoco_body: the placed skeleton differs from the rigidly moved Boulic model by "
                f"{residual:.3g} m; the placement is not a rotation about z plus a translation"
            )
        centres = frames.centres @ rz.T + shift[:, None, :]
        rot = np.einsum("ij,psjk->psik", rz, frames.rotations)
        return joints, centres, rot, frames.semi_axes

    def _segment_frames(
        self, skeleton: Skeleton
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        joints = skeleton.positions
        height = getattr(self, "_height", None) or self.config.height
        height = height or body.estimate_height(joints)
        ab = {k: (r, r) for k, r in PART_RADII.items()} | dict(self.config.radii or {})
        semi = np.array(
            [
                (*ab[PART_SEGMENT[p]], SEGMENT_FRACTIONS[PART_SEGMENT[p]] * height / 2)
                for p in PART_NAMES
            ]
        )
        tail = joints[:, [_J[PART_JOINTS[p][0]] for p in PART_NAMES]]
        tip = joints[:, [_J[PART_JOINTS[p][1]] for p in PART_NAMES]]
        centres = 0.5 * (tail + tip)
        zc, length = _unit(tip - tail)
        ok = length > 1e-6
        if not np.all(ok):  # coincident joints: hold the last valid direction
            idx = np.where(ok, np.arange(len(zc))[:, None], -1)
            np.maximum.accumulate(idx, axis=0, out=idx)
            idx = np.where(idx < 0, np.argmax(ok, axis=0)[None, :], idx)
            zc = np.take_along_axis(zc, idx[:, :, None], axis=0)
            zc[:, ~np.any(ok, axis=0)] = (0.0, 0.0, 1.0)
        left = joints[:, _J["l_hip"]] - joints[:, _J["r_hip"]]
        forward = np.stack([left[:, 1], -left[:, 0], np.zeros(len(left))], axis=1)
        xa = forward[:, None, :] - np.sum(forward[:, None, :] * zc, -1, keepdims=True) * zc
        xa, nx = _unit(xa)
        up = np.array([0.0, 0.0, 1.0])
        alt, _ = _unit(up - zc[..., 2:3] * zc)
        xa = np.where((nx > 1e-6)[..., None], xa, alt)
        ya = np.cross(zc, xa)
        rot = np.stack([xa, ya, zc], axis=-1)
        return joints, centres, rot, semi
