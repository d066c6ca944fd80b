"""Body self-shadowing (effect kind ``shadowing``, stage ``scatterers``).

Line of sight from the radar to every scatterer, cast with MuJoCo's batched ray caster
(``mujoco.mj_multiRay``: one call per evaluated pulse, all rays from the radar position) against
the body's geoms. A scatterer is *blocked* when the nearest surface along its ray is a geom
that is neither its own part nor contains the scatterer, and lies nearer than the scatterer
(by more than ``tolerance``). Blocked scatterers' RCS is multiplied by
``10 ** (-attenuation_db / 10)``; ``attenuation_db = inf`` removes them.

Bodies:

- ``ellipsoids`` (default when the scatterers carry ``semi_axes`` and ``axes``, as the
  ``ellipsoid`` and ``mujoco_body`` models do): one ellipsoid per scatterer centred at its
  position, or at ``Scatterers.centres`` when given (the geom centre for ``mujoco_body``, whose
  full frames are used; the spheroid centre for the ``ellipsoid`` model's specular points). The
  ray goes to the scatterer's position itself. When only the
  c-axis is known the a/b orientation about it is arbitrary, exact for Chen's ``a = b``.
- ``capsules`` (default otherwise, e.g. point scatterers on a canonical body): a capsule around
  each of the 16 canonical segments of ``context.skeleton``, with the part's radius from the
  segment table and the segment's median length over the record.

Geoms are free-standing world geoms whose world frames are written into ``mjData`` for every
evaluated pulse (no kinematics is needed). ``decimation = k`` casts on every k-th pulse and holds
the result for the next k - 1 (the visibility of a limb changes on the time scale of a gait
cycle, ~1 s, so k = 8 at 2400 Hz still resolves 3.3 ms). The effect runs only when the scene's
``effects`` list names it; otherwise nothing is cast.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from mdframework import (
    CANONICAL_SEGMENTS,
    Effect,
    PluginConfig,
    Scatterers,
    SceneContext,
    SceneError,
)
from mdframework.physics.body import PART_RADII

if TYPE_CHECKING:
    import mujoco  # type: ignore[import-untyped]

FloatArray = NDArray[np.float64]

#: effect -> why it must not come after ``shadowing`` (:meth:`Shadowing.check_effects`)
HIDDEN_AFTER = {
    "static_scene": "the room's reflectors would never be hidden by the person (a reflector "
    "behind the body would be seen through it)",
}
BoolArray = NDArray[np.bool_]

#: Radius key (of ``PART_RADII``) of each canonical segment's capsule.
SEGMENT_PART: dict[tuple[str, str], str] = {
    ("base", "neck"): "torso",
    ("neck", "head"): "head",
    **{
        seg: part
        for s in ("l", "r")
        for seg, part in {
            ("neck", f"{s}_shoulder"): "shoulder",
            (f"{s}_shoulder", f"{s}_elbow"): "upper_arm",
            (f"{s}_elbow", f"{s}_hand"): "lower_arm",
            ("base", f"{s}_hip"): "hip",
            (f"{s}_hip", f"{s}_knee"): "upper_leg",
            (f"{s}_knee", f"{s}_ankle"): "lower_leg",
            (f"{s}_ankle", f"{s}_toe"): "foot",
        }.items()
    },
}


class ShadowingConfig(PluginConfig):
    """Self-shadowing of body parts by other body parts."""

    kind: Literal["shadowing"] = "shadowing"
    attenuation_db: float = Field(
        20.0,
        ge=0,
        allow_inf_nan=True,
        description="RCS reduction of a blocked scatterer [dB]; inf removes it.",
    )
    decimation: int = Field(
        1,
        ge=1,
        le=1_000_000,
        description="Cast rays on every k-th pulse and hold the result in between.",
    )
    bodies: Literal["auto", "ellipsoids", "capsules"] = Field(
        "auto",
        description="Occluders: the scatterers' ellipsoids, or capsules around the canonical "
        "skeleton; auto: ellipsoids when the scatterer model gives shapes.",
    )
    tolerance: float = Field(
        1e-3, ge=0, le=1, description="A hit must be this much nearer than the scatterer [m]."
    )


def _frames_from_axis(axis: FloatArray) -> FloatArray:
    """Rotation matrices (..., 3, 3) whose third column is the unit ``axis`` (..., 3) and whose
    first two columns complete a right-handed frame (arbitrary roll)."""
    n = np.linalg.norm(axis, axis=-1, keepdims=True)
    z = np.where(n > 0, axis / np.where(n > 0, n, 1.0), np.array([0.0, 0.0, 1.0]))
    helper = np.where(np.abs(z[..., :1]) < 0.9, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    x = helper - np.sum(helper * z, -1, keepdims=True) * z
    x /= np.linalg.norm(x, axis=-1, keepdims=True)
    y = np.cross(z, x)
    return np.stack([x, y, z], axis=-1)


def _build_model(types: list[int], sizes: FloatArray) -> tuple[mujoco.MjModel, mujoco.MjData]:
    import mujoco  # type: ignore[import-untyped]  # heavy: imported when used

    names = {int(mujoco.mjtGeom.mjGEOM_ELLIPSOID): "ellipsoid",
             int(mujoco.mjtGeom.mjGEOM_CAPSULE): "capsule"}  # fmt: skip
    geoms = "\n".join(
        f'<geom type="{names[t]}" size="{" ".join(f"{v:.17g}" for v in s)}" '
        'contype="0" conaffinity="0"/>'
        for t, s in zip(types, sizes, strict=True)
    )
    xml = f"<mujoco><worldbody>{geoms}</worldbody></mujoco>"
    m = mujoco.MjModel.from_xml_string(xml)
    return m, mujoco.MjData(m)


class Shadowing(Effect):
    """Attenuates scatterers hidden from the radar by other body parts."""

    name = "shadowing"
    Config = ShadowingConfig
    config: ShadowingConfig
    stage = "scatterers"

    def __init__(self, config: PluginConfig | None = None) -> None:
        super().__init__(config)
        self.start_record()

    def check_effects(self, effects: Sequence[Effect]) -> None:
        """Refuse ``static_scene`` listed after this one (:data:`HIDDEN_AFTER`): listed before,
        its reflectors are scatterers the body can hide."""
        self.refuse_listed_after(effects, HIDDEN_AFTER)

    def start_record(self, body: Any = None, radar_position: Any = None) -> None:
        """Reset the ray row carried between blocks and the record's blocked fractions."""
        self._stats: dict[str, Any] = {}
        self._carry: BoolArray | None = None
        self._totals: tuple[int, Any, int] = (0, None, 0)

    # ---------------------------------------------------------------- occluder geometry

    def _ellipsoids(
        self, scat: Scatterers
    ) -> tuple[list[int], FloatArray, FloatArray, FloatArray, BoolArray]:
        import mujoco  # type: ignore[import-untyped]  # heavy: imported when used

        if scat.semi_axes is None or scat.axes is None:
            raise SceneError(
                "effects.shadowing: bodies = 'ellipsoids' needs a scatterer model that gives "
                "body-part shapes (ellipsoid, mujoco_body)"
            )
        # the shapes' centres, when the scatterers are not at them (the ellipsoid model's
        # specular points lie on their own part's surface: the own part never blocks)
        centres = scat.centres if scat.centres is not None else scat.positions
        rotations = getattr(scat, "rotations", None)
        if rotations is None:
            rotations = _frames_from_axis(scat.axes)
        n_s = scat.positions.shape[1]
        types = [int(mujoco.mjtGeom.mjGEOM_ELLIPSOID)] * n_s
        own = np.eye(n_s, dtype=bool)
        return types, np.asarray(scat.semi_axes, np.float64), centres, rotations, own

    def _capsules(
        self, scat: Scatterers, context: SceneContext
    ) -> tuple[list[int], FloatArray, FloatArray, FloatArray, BoolArray]:
        import mujoco  # type: ignore[import-untyped]  # heavy: imported when used

        skel = context.skeleton
        try:
            tail = skel.positions[:, [skel.index(a) for a, _ in CANONICAL_SEGMENTS]]
            tip = skel.positions[:, [skel.index(b) for _, b in CANONICAL_SEGMENTS]]
        except KeyError:
            raise SceneError(
                "effects.shadowing: capsules need the canonical 17-joint body; this skeleton "
                f"has joints {', '.join(skel.joint_names[:5])}..."
            ) from None
        seg = tip - tail
        length = np.linalg.norm(seg, axis=-1)
        half = 0.5 * np.median(length, axis=0)
        radius = np.array([PART_RADII[SEGMENT_PART[s]] for s in CANONICAL_SEGMENTS])
        sizes = np.stack([radius, np.maximum(half, 1e-6), np.zeros_like(radius)], axis=1)
        types = [int(mujoco.mjtGeom.mjGEOM_CAPSULE)] * len(CANONICAL_SEGMENTS)
        own = np.zeros((scat.positions.shape[1], len(types)), dtype=bool)
        return types, sizes, 0.5 * (tail + tip), _frames_from_axis(seg), own

    @staticmethod
    def _contains(
        types: list[int], sizes: FloatArray, centres: FloatArray, rot: FloatArray, x: FloatArray
    ) -> BoolArray:
        """(n_p, n_s, n_g): whether each scatterer position ``x`` (n_p, n_s, 3) lies inside each
        geom (1 % margin)."""
        import mujoco  # type: ignore[import-untyped]  # heavy: imported when used

        n_p, n_s = x.shape[:2]
        out = np.zeros((n_p, n_s, len(types)), dtype=bool)
        for g, (kind, size) in enumerate(zip(types, sizes, strict=True)):
            local = np.einsum("pji,psj->psi", rot[:, g], x - centres[:, g, None, :])
            if kind == int(mujoco.mjtGeom.mjGEOM_ELLIPSOID):
                out[:, :, g] = np.sum((local / size) ** 2, axis=-1) <= 1.0201
            else:
                z = np.clip(local[..., 2], -size[1], size[1])
                r2 = local[..., 0] ** 2 + local[..., 1] ** 2 + (local[..., 2] - z) ** 2
                out[:, :, g] = r2 <= (1.01 * size[0]) ** 2
        return out

    # ---------------------------------------------------------------- the effect

    def visibility(self, scat: Scatterers, context: SceneContext) -> BoolArray:
        """Whether each scatterer is blocked, (n_pulses, n_scatterers) bool."""
        import mujoco  # type: ignore[import-untyped]  # heavy: imported when used

        c = self.config
        use_ellipsoids = c.bodies == "ellipsoids" or (
            c.bodies == "auto" and scat.semi_axes is not None and scat.axes is not None
        )
        if use_ellipsoids:
            types, sizes, centres, rot, own = self._ellipsoids(scat)
        else:
            types, sizes, centres, rot, own = self._capsules(scat, context)
        n_p, n_s = scat.positions.shape[:2]
        if context.block_start == 0:  # a record's first block
            self.start_record()
        # rays at the record's pulses 0, d, 2d, ...: the same pulses for any cut into blocks
        first = (-context.block_start) % c.decimation
        idx = np.arange(first, n_p, c.decimation)
        x = scat.positions[idx]
        centres, rot = centres[idx], rot[idx]
        allowed = self._contains(types, sizes, centres, rot, x) | own[None]
        radar = np.asarray(context.radar_position, dtype=np.float64)
        ray = x - radar
        rng = np.linalg.norm(ray, axis=-1)
        unit = ray / rng[..., None]
        m, d = _build_model(types, sizes)
        geomid = np.empty(n_s, dtype=np.int32)
        dist = np.empty(n_s, dtype=np.float64)
        # a block may hold no ray pulse (shorter than the decimation): it holds the last rays
        cutoff = float(rng.max() + 1.0) if rng.size else 0.0
        xmat = rot.reshape(len(idx), len(types), 9)
        blocked = np.zeros((len(idx), n_s), dtype=bool)
        cols = np.arange(n_s)
        for k in range(len(idx)):
            d.geom_xpos[:] = centres[k]
            d.geom_xmat[:] = xmat[k]
            mujoco.mj_multiRay(
                m, d, radar, unit[k].ravel(), None, 1, -1, geomid, dist, None, n_s, cutoff
            )
            hit = geomid >= 0
            g = np.where(hit, geomid, 0)
            blocked[k] = hit & (dist < rng[k] - c.tolerance) & ~allowed[k, cols, g]
        row = (np.arange(n_p) - first) // c.decimation  # -1: before this block's first ray
        carried = self._carry if self._carry is not None else np.zeros(n_s, dtype=bool)
        full = np.concatenate((carried[None], blocked))[row + 1]
        if len(idx):
            self._carry = blocked[-1].copy()
        rays, counts, pulses = self._totals
        counts = counts + full.sum(axis=0) if counts is not None else full.sum(axis=0)
        self._totals = (rays + int(len(idx) * n_s), counts, pulses + n_p)
        self._stats = {
            "occluders": "ellipsoids" if use_ellipsoids else "capsules",
            "rays_cast": self._totals[0],
            "blocked_fraction": {
                name: float(f) / self._totals[2] for name, f in zip(scat.names, counts, strict=True)
            },
        }
        return np.asarray(full, dtype=bool)

    def apply(self, data: Scatterers, context: SceneContext) -> Scatterers:
        """Scatterers with the blocked ones' RCS attenuated."""
        blocked = self.visibility(data, context)
        factor = 10.0 ** (-self.config.attenuation_db / 10.0)
        return data.replace(rcs=np.where(blocked, data.rcs * factor, data.rcs))

    def describe(self) -> dict[str, Any]:
        """The config plus the occluder type, rays cast and each scatterer's blocked fraction."""
        return {**self.config.model_dump(), **self._stats}
