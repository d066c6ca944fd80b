"""The Boulic walker as a MuJoCo model whose geoms are the scattering ellipsoids.

The model is built as an MJCF string from the height-scaled segment table
(:data:`mdframework.physics.body.SEGMENT_FRACTIONS`, :data:`~mdframework.physics.body.PART_RADII`).
Tree (walker frame, x forward, y left, z up)::

    root (slide x, y, z: the base translation)
    ├── pelvis (hinge z = -torsion, then hinge x = +rot_leftright)
    │   └── {l,r}_thigh at (0, ±hip, 0) (hinge y = -hip)
    │       └── shank at (0, 0, -UL) (hinge y = +knee)
    │           └── foot at (0, 0, -LL) (hinge y = -ankle); toe site at (foot, 0, 0)
    └── thorax (hinge z = -thorax, then hinge y = -rot_forback)
        ├── neck and head sites
        └── {l,r}_upper_arm at (0, ±shoulder, torso) (hinge y = -shoulder)
            └── forearm at (0, 0, -UA) (hinge y = -elbow); hand site at (0, 0, -LA)

Chen's passive Euler matrices are active rotations by the negated angles, which gives the signs
above; upper body and pelvis rotate independently about the base, as in Chen's code.

Geoms: 16 ellipsoids named as the ``chen16`` parts, centred at their segment's midpoint, with
semi-axes ``(a, b, c)``: ``c`` (the geom's local z) along the segment and half its length,
``a = b`` from ``PART_RADII`` unless overridden. The a-axis (local x) is the body's forward
direction for limbs and torso, and the body's up direction for the feet. Sites mark the 17
canonical joints in their order. With ``chen_lower_leg`` the lower leg's ``c`` is half the
*upper* leg's length (Chen's Q5).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from mdframework import CANONICAL_JOINTS
from mdframework.physics.body import PART_RADII

from .gait import Gait, base_translation, frozen_elbow_z

if TYPE_CHECKING:
    pass  # type: ignore[import-untyped]

FloatArray = NDArray[np.float64]

#: Geom (body part) names, in the order of the ``chen16`` placement.
PART_NAMES: tuple[str, ...] = (
    "head",
    "torso",
    *(f"{s}_{p}" for s in ("l", "r") for p in (
        "shoulder", "upper_arm", "lower_arm", "hip", "upper_leg", "lower_leg", "foot",
    )),
)  # fmt: skip

#: Segment (key of the segment table) of each part.
PART_SEGMENT: dict[str, str] = {
    name: name.split("_", 1)[1] if name[:2] in ("l_", "r_") else name for name in PART_NAMES
}

#: The (tail, tip) canonical joints each geom's c-axis runs along.
PART_JOINTS: dict[str, tuple[str, str]] = {
    "head": ("neck", "head"),
    "torso": ("base", "neck"),
    **{
        f"{s}_{p}": (a.format(s=s), b.format(s=s))
        for s in ("l", "r")
        for p, (a, b) in {
            "shoulder": ("neck", "{s}_shoulder"),
            "upper_arm": ("{s}_shoulder", "{s}_elbow"),
            "lower_arm": ("{s}_elbow", "{s}_hand"),
            "hip": ("base", "{s}_hip"),
            "upper_leg": ("{s}_hip", "{s}_knee"),
            "lower_leg": ("{s}_knee", "{s}_ankle"),
            "foot": ("{s}_ankle", "{s}_toe"),
        }.items()
    },
}

_DOWN = "1 0 0 0 -1 0"  # local x forward, z down (limbs hanging from their joint)
_UP = "1 0 0 0 1 0"
_LEFT = "1 0 0 0 0 -1"  # z along +y
_RIGHT = "1 0 0 0 0 1"  # z along -y
_FORWARD = "0 0 1 0 -1 0"  # x up, z forward (feet)


def _f(*v: float) -> str:
    return " ".join(f"{x:.17g}" for x in v)


def build_mjcf(
    gait: Gait,
    radii: Mapping[str, tuple[float, float]] | None = None,
    chen_lower_leg: bool = False,
) -> str:
    """MJCF text of the walker's body.

    ``radii`` maps a segment name to its ``(a, b)`` semi-axes [m] (default ``PART_RADII``,
    ``a = b``). Returns the XML string."""
    d = gait.dims
    ab = {seg: (r, r) for seg, r in PART_RADII.items()}
    if radii:
        ab.update({k: (float(v[0]), float(v[1])) for k, v in radii.items()})
    half = {
        "head": d.head / 2,
        "torso": d.torso / 2,
        "shoulder": d.shoulder / 2,
        "upper_arm": d.upper_arm / 2,
        "lower_arm": d.lower_arm / 2,
        "hip": d.hip / 2,
        "upper_leg": d.upper_leg / 2,
        "lower_leg": (d.upper_leg if chen_lower_leg else d.lower_leg) / 2,
        "foot": d.foot / 2,
    }

    def geom(name: str, pos: tuple[float, float, float], axes: str) -> str:
        a, b = ab[PART_SEGMENT[name]]
        c = half[PART_SEGMENT[name]]
        return (
            f'<geom name="{name}" type="ellipsoid" size="{_f(a, b, c)}" pos="{_f(*pos)}" '
            f'xyaxes="{axes}"/>'
        )

    def site(name: str, pos: tuple[float, float, float]) -> str:
        return f'<site name="{name}" pos="{_f(*pos)}"/>'

    legs = []
    for s, y in (("l", d.hip), ("r", -d.hip)):
        legs.append(
            f"""
      <body name="{s}_thigh" pos="{_f(0, y, 0)}">
        <joint name="{s}_hip" type="hinge" axis="0 1 0"/>
        {site(f"{s}_hip", (0, 0, 0))}
        {geom(f"{s}_upper_leg", (0, 0, -d.upper_leg / 2), _DOWN)}
        <body name="{s}_shank" pos="{_f(0, 0, -d.upper_leg)}">
          <joint name="{s}_knee" type="hinge" axis="0 1 0"/>
          {site(f"{s}_knee", (0, 0, 0))}
          {geom(f"{s}_lower_leg", (0, 0, -d.lower_leg / 2), _DOWN)}
          <body name="{s}_foot" pos="{_f(0, 0, -d.lower_leg)}">
            <joint name="{s}_ankle" type="hinge" axis="0 1 0"/>
            {site(f"{s}_ankle", (0, 0, 0))}
            {site(f"{s}_toe", (d.foot, 0, 0))}
            {geom(f"{s}_foot", (d.foot / 2, 0, 0), _FORWARD)}
          </body>
        </body>
      </body>"""
        )
    arms = []
    for s, y in (("l", d.shoulder), ("r", -d.shoulder)):
        arms.append(
            f"""
      <body name="{s}_upper_arm" pos="{_f(0, y, d.torso)}">
        <joint name="{s}_shoulder" type="hinge" axis="0 1 0"/>
        {site(f"{s}_shoulder", (0, 0, 0))}
        {geom(f"{s}_upper_arm", (0, 0, -d.upper_arm / 2), _DOWN)}
        <body name="{s}_forearm" pos="{_f(0, 0, -d.upper_arm)}">
          <joint name="{s}_elbow" type="hinge" axis="0 1 0"/>
          {site(f"{s}_elbow", (0, 0, 0))}
          {site(f"{s}_hand", (0, 0, -d.lower_arm))}
          {geom(f"{s}_lower_arm", (0, 0, -d.lower_arm / 2), _DOWN)}
        </body>
      </body>"""
        )
    return f"""<mujoco model="boulic_walker">
  <compiler angle="radian" boundmass="1e-6" boundinertia="1e-9"/>
  <option gravity="0 0 0"/>
  <default><geom contype="0" conaffinity="0" group="0"/><site size="0.01"/></default>
  <worldbody>
    <body name="root">
      <joint name="tx" type="slide" axis="1 0 0"/>
      <joint name="ty" type="slide" axis="0 1 0"/>
      <joint name="tz" type="slide" axis="0 0 1"/>
      {site("base", (0, 0, 0))}
      <body name="pelvis">
        <joint name="pelvis_z" type="hinge" axis="0 0 1"/>
        <joint name="pelvis_x" type="hinge" axis="1 0 0"/>
        {geom("l_hip", (0, d.hip / 2, 0), _LEFT)}
        {geom("r_hip", (0, -d.hip / 2, 0), _RIGHT)}
        {"".join(legs)}
      </body>
      <body name="thorax">
        <joint name="thorax_z" type="hinge" axis="0 0 1"/>
        <joint name="thorax_y" type="hinge" axis="0 1 0"/>
        {site("neck", (0, 0, d.torso))}
        {site("head", (0, 0, d.torso + d.head))}
        {geom("torso", (0, 0, d.torso / 2), _UP)}
        {geom("head", (0, 0, d.torso + d.head / 2), _UP)}
        {geom("l_shoulder", (0, d.shoulder / 2, d.torso), _LEFT)}
        {geom("r_shoulder", (0, -d.shoulder / 2, d.torso), _RIGHT)}
        {"".join(arms)}
      </body>
    </body>
  </worldbody>
</mujoco>
"""


#: The hinge joints and, for each, the trajectory it follows and the sign of its angle.
_HINGES: tuple[tuple[str, str, str, float], ...] = (
    ("pelvis_z", "r", "torsion", -1.0),
    ("pelvis_x", "r", "rot_leftright", 1.0),
    ("thorax_z", "r", "thorax", -1.0),
    ("thorax_y", "r", "rot_forback", -1.0),
    *(
        (f"{s}_{j}", s, track, sign)
        for s in ("l", "r")
        for j, track, sign in (
            ("hip", "hip", -1.0),
            ("knee", "knee", 1.0),
            ("ankle", "ankle", -1.0),
            ("shoulder", "shoulder", -1.0),
            ("elbow", "elbow", -1.0),
        )
    ),
)


@dataclass(frozen=True)
class Frames:
    """Kinematics of ``n`` samples: ``joints`` (n, 17, 3) [m] (canonical order); geom centres
    ``centres`` (n, 16, 3) [m] and orientations ``rotations`` (n, 16, 3, 3) whose columns are
    the geom's a-, b- and c-axes (unit vectors, walker frame); ``semi_axes`` (16, 3) [m]."""

    joints: FloatArray
    centres: FloatArray
    rotations: FloatArray
    semi_axes: FloatArray


class WalkerBody:
    """A compiled MuJoCo model of one :class:`~mdf_mujoco.gait.Gait` and its kinematics."""

    def __init__(
        self,
        gait: Gait,
        radii: Mapping[str, tuple[float, float]] | None = None,
        chen_lower_leg: bool | None = None,
    ) -> None:
        import mujoco  # type: ignore[import-untyped]  # heavy: imported when used

        self.gait = gait
        q5 = gait.chen_compatible if chen_lower_leg is None else chen_lower_leg
        self.xml = build_mjcf(gait, radii, q5)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        m = self.model
        self._site_ids = np.array(
            [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, j) for j in CANONICAL_JOINTS]
        )
        self._geom_ids = np.array(
            [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, p) for p in PART_NAMES]
        )
        self._adr_t = np.array(
            [
                m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, j)]
                for j in ("tx", "ty", "tz")
            ]
        )
        self._adr_h = np.array(
            [m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, h[0])] for h in _HINGES]
        )
        self.semi_axes = np.asarray(m.geom_size[self._geom_ids], dtype=np.float64).copy()

    def qpos(self, time: FloatArray) -> FloatArray:
        """Joint coordinates (n, nq) at ``time`` (n,) [s]: base translation [m], hinge angles
        [rad]."""
        t = np.asarray(time, dtype=np.float64)
        phase = self.gait.phase(t)
        tracks = {"r": self.gait.tracks(phase), "l": self.gait.tracks(np.mod(phase + 0.5, 1.0))}
        q = np.zeros((t.shape[0], self.model.nq))
        q[:, self._adr_t] = base_translation(self.gait, t)
        deg = np.pi / 180.0
        for adr, (_, side, track, sign) in zip(self._adr_h, _HINGES, strict=True):
            q[:, adr] = sign * deg * tracks[side][track]
        return q

    def kinematics(self, qpos: FloatArray, geoms: bool = True) -> Frames:
        """Run ``mj_kinematics`` for every row of ``qpos`` (n, nq) and collect the frames;
        ``geoms`` False collects the joints alone (``centres`` (0, 0, 3) and ``rotations``
        (0, 0, 3, 3), empty): a motion source's frames, without the geoms' arrays, seven times
        the joints' memory.

        In chen-compatible mode the elbow sites are moved to Chen's frozen-height position (Q4);
        the geoms stay rigid."""
        import mujoco  # type: ignore[import-untyped]  # heavy: imported when used

        m, d = self.model, self.data
        n = qpos.shape[0]
        # MjData's arrays are views of the buffers mj_kinematics fills in place: take the views
        # once, copy them whole every frame (plain copies: a third of the time of picking the
        # sites and geoms frame by frame) and pick the sites and geoms once for all frames
        site_xpos, geom_xpos, geom_xmat, d_qpos = d.site_xpos, d.geom_xpos, d.geom_xmat, d.qpos
        all_sites = np.empty((n, *site_xpos.shape))
        all_pos = np.empty((n if geoms else 0, *geom_xpos.shape))
        all_mat = np.empty((n if geoms else 0, *geom_xmat.shape))
        quirk = self.gait.chen_compatible
        thorax = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "thorax")
        thorax_xpos, thorax_xmat = d.xpos[thorax], d.xmat[thorax]
        all_bpos = np.empty((n, 3)) if quirk else None
        all_bmat = np.empty((n, 9)) if quirk else None
        kinematics = mujoco.mj_kinematics
        for i in range(n):
            d_qpos[:] = qpos[i]
            kinematics(m, d)
            all_sites[i] = site_xpos
            if geoms:
                all_pos[i] = geom_xpos
                all_mat[i] = geom_xmat
            if all_bpos is not None and all_bmat is not None:
                all_bpos[i] = thorax_xpos
                all_bmat[i] = thorax_xmat
        joints = all_sites[:, self._site_ids]
        del all_sites
        ids = self._geom_ids if geoms else self._geom_ids[:0]
        rot = all_mat[:, ids].reshape(all_mat.shape[0], ids.size, 3, 3)
        if all_bpos is not None and all_bmat is not None:
            joints = self._freeze_elbows(joints, all_bpos, all_bmat.reshape(n, 3, 3))
        return Frames(joints, all_pos[:, ids], rot, self.semi_axes)

    def _freeze_elbows(self, joints: FloatArray, pos: FloatArray, mat: FloatArray) -> FloatArray:
        out = joints.copy()
        for side in ("l", "r"):
            k = CANONICAL_JOINTS.index(f"{side}_elbow")
            local = np.einsum("nji,nj->ni", mat, joints[:, k] - pos)  # thorax frame
            local[:, 2] = frozen_elbow_z(self.gait, side)
            out[:, k] = pos + np.einsum("nij,nj->ni", mat, local)
        return out

    def frames(self, time: FloatArray, geoms: bool = True) -> Frames:
        """Kinematics at ``time`` (n,) [s] (``geoms``: see :meth:`kinematics`)."""
        return self.kinematics(self.qpos(time), geoms)
