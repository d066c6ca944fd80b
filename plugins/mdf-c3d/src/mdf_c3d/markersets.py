"""Marker sets: canonical joint = mean of named markers.

Each canonical joint lists one or more marker groups; the first group whose markers are all in
the file is used, and the joint is the mean of its markers in every frame where they are all
seen. Marker names are matched without a subject prefix (``S03:LASI`` matches ``LASI``).

=================  ============================================================================
set                markers
=================  ============================================================================
plug-in-gait       Vicon Plug-in Gait full body: head ``LFHD RFHD LBHD RBHD``, neck
                   ``C7 CLAV``, shoulders ``LSHO``, elbows ``LELB``, hands ``LWRA LWRB``
                   (the wrist), pelvis ``LASI RASI LPSI RPSI`` (or ``SACR``), hips
                   ``LASI LPSI`` (or ``LASI SACR``), knees ``LKNE``, ankles ``LANK``, toes
                   ``LTOE``; and the same on the right.
cmu                The CMU database's 41-marker set: as Plug-in Gait with the waist markers
                   ``LFWT RFWT LBWT RBWT`` for the pelvis.
opensim-gait       The 41 markers of OpenSim's gait examples (Gait2354/Gait2392 subject01,
                   Hamner's running subjects): head ``R.Temple L.Temple Top.Head``, neck
                   ``R.Acromium L.Acromium``, shoulders ``L.Acromium``, elbows ``L.Elbow``,
                   hands ``L.Wrist.Med L.Wrist.Lat``, pelvis ``R.ASIS L.ASIS V.Sacral``, hips
                   ``L.ASIS V.Sacral``, knees ``L.Thigh.Rear L.Shank.Upper`` (the thigh
                   cluster's lowest marker and the shank cluster's highest: the set has no knee
                   marker), ankles ``L.Heel L.Midfoot.Sup L.Midfoot.Lat``, toes
                   ``L.Toe.Lat L.Toe.Med``; and the same on the right.
keypoints          Markerless keypoints, joint centres already (Pose2Sim's TRC files, HALPE_26
                   or OpenPose BODY_25 names): pelvis ``Hip`` (or ``MidHip``, or
                   ``LHip RHip``), neck ``Neck``, head ``Head`` (or ``LEar REar``, or
                   ``Nose``), shoulders ``LShoulder``, elbows ``LElbow``, hands ``LWrist``,
                   hips ``LHip``, knees ``LKnee``, ankles ``LAnkle``, toes
                   ``LBigToe LSmallToe``; and the same on the right.
=================  ============================================================================

A mean of skin markers is not the joint centre: the knee and ankle markers sit on the lateral
side (about 5 cm off the joint axis), the hip from the pelvis markers lies a few centimetres
above and outside the hip joint; the OpenSim set's knee lies between two cluster markers about
10 cm above and below the joint. For the radar signature (body parts tens of centimetres long,
speeds of metres per second) these offsets are small; a ``marker_map`` with medial and lateral
markers (``l_knee = ["LKNE", "LMKNE"]``) gives the joint centre.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from mdframework import CANONICAL_JOINTS

Groups = tuple[tuple[str, ...], ...]


@dataclass(frozen=True)
class MarkerSet:
    """Canonical joint -> marker groups (first complete group wins), and signature markers."""

    name: str
    description: str
    joints: Mapping[str, Groups]
    signature: tuple[str, ...]


def _mirror(left: dict[str, Groups]) -> dict[str, Groups]:
    """Left-side entries plus their right-side mirror (a leading L -> R; markers on the
    midline, such as ``SACR`` or ``V.Sacral``, stay)."""
    out = dict(left)
    for key, groups in left.items():
        out["r_" + key[2:]] = tuple(
            tuple("R" + m[1:] if m.startswith("L") else m for m in g) for g in groups
        )
    return out


MARKER_SETS: dict[str, MarkerSet] = {
    "plug-in-gait": MarkerSet(
        "plug-in-gait",
        "Vicon Plug-in Gait full body",
        {
            "base": (("LASI", "RASI", "LPSI", "RPSI"), ("LASI", "RASI", "SACR")),
            "neck": (("C7", "CLAV"),),
            "head": (("LFHD", "RFHD", "LBHD", "RBHD"),),
            **_mirror(
                {
                    "l_shoulder": (("LSHO",),),
                    "l_elbow": (("LELB",),),
                    "l_hand": (("LWRA", "LWRB"),),
                    "l_hip": (("LASI", "LPSI"), ("LASI", "SACR")),
                    "l_knee": (("LKNE",),),
                    "l_ankle": (("LANK",),),
                    "l_toe": (("LTOE",),),
                }
            ),
        },
        ("LASI", "RASI", "LPSI", "RPSI", "SACR", "LFHD", "LUPA", "LFRM"),
    ),
    "cmu": MarkerSet(
        "cmu",
        "CMU motion capture database, 41 markers",
        {
            "base": (("LFWT", "RFWT", "LBWT", "RBWT"),),
            "neck": (("C7", "CLAV"),),
            "head": (("LFHD", "RFHD", "LBHD", "RBHD"),),
            **_mirror(
                {
                    "l_shoulder": (("LSHO",),),
                    "l_elbow": (("LELB",),),
                    "l_hand": (("LWRA", "LWRB"),),
                    "l_hip": (("LFWT", "LBWT"),),
                    "l_knee": (("LKNE",),),
                    "l_ankle": (("LANK",),),
                    "l_toe": (("LTOE",),),
                }
            ),
        },
        ("LFWT", "RFWT", "LBWT", "RBWT", "LSHN", "LMT5"),
    ),
    "opensim-gait": MarkerSet(
        "opensim-gait",
        "OpenSim gait example markers (Gait2354/Gait2392 subject01, Hamner running)",
        {
            "base": (("R.ASIS", "L.ASIS", "V.Sacral"),),
            "neck": (("R.Acromium", "L.Acromium"),),
            "head": (("R.Temple", "L.Temple", "Top.Head"),),
            **_mirror(
                {
                    "l_shoulder": (("L.Acromium",),),
                    "l_elbow": (("L.Elbow",),),
                    "l_hand": (("L.Wrist.Med", "L.Wrist.Lat"),),
                    "l_hip": (("L.ASIS", "V.Sacral"),),
                    "l_knee": (("L.Thigh.Rear", "L.Shank.Upper"),),
                    "l_ankle": (("L.Heel", "L.Midfoot.Sup", "L.Midfoot.Lat"),),
                    "l_toe": (("L.Toe.Lat", "L.Toe.Med"),),
                }
            ),
        },
        ("V.Sacral", "R.Thigh.Upper", "R.Shank.Upper", "Top.Head", "R.Temple"),
    ),
    "keypoints": MarkerSet(
        "keypoints",
        "Markerless keypoints (Pose2Sim's TRC files: HALPE_26, OpenPose BODY_25)",
        {
            "base": (("Hip",), ("MidHip",), ("LHip", "RHip")),
            "neck": (("Neck",),),
            "head": (("Head",), ("LEar", "REar"), ("Nose",)),
            **_mirror(
                {
                    "l_shoulder": (("LShoulder",),),
                    "l_elbow": (("LElbow",),),
                    "l_hand": (("LWrist",),),
                    "l_hip": (("LHip",),),
                    "l_knee": (("LKnee",),),
                    "l_ankle": (("LAnkle",),),
                    "l_toe": (("LBigToe", "LSmallToe"), ("LBigToe",)),
                }
            ),
        },
        ("LBigToe", "RBigToe", "LSmallToe", "RHeel", "LShoulder", "RWrist"),
    ),
}


def strip_prefix(label: str) -> str:
    """``"S03:LASI"`` -> ``"LASI"`` (labels without a prefix are unchanged)."""
    return label.rsplit(":", 1)[-1]


class MarkerMismatch(ValueError):
    """No marker set fits a file's markers; the message names them and the nearest set."""


def resolve(
    mset: Mapping[str, Groups], labels: Iterable[str]
) -> tuple[dict[str, tuple[str, ...]], list[str]]:
    """Map marker groups onto a file's labels.

    Returns canonical joint -> file labels (as written, prefix included) for the joints with a
    complete group, and the joints without one (with the markers the set wants for them).
    """
    by_plain: dict[str, str] = {}
    for lab in labels:
        by_plain.setdefault(strip_prefix(lab), lab)
    mapping: dict[str, tuple[str, ...]] = {}
    missing: list[str] = []
    for joint in CANONICAL_JOINTS:
        groups = mset.get(joint, ())
        group = next((g for g in groups if all(m in by_plain for m in g)), None)
        if group is None:
            want = " or ".join(" + ".join(g) for g in groups) or "no markers given"
            missing.append(f"{joint} ({want})")
        else:
            mapping[joint] = tuple(by_plain[m] for m in group)
    return mapping, missing


def user_groups(marker_map: Mapping[str, str | Sequence[str]]) -> dict[str, Groups]:
    """A config's ``marker_map`` (joint -> marker or markers) as marker groups."""
    return {j: ((m,) if isinstance(m, str) else tuple(m),) for j, m in marker_map.items()}


def detect_marker_set(
    labels: Sequence[str], extra: Mapping[str, Groups] | None = None, name: str = "auto"
) -> tuple[str, dict[str, tuple[str, ...]]]:
    """The marker set that fits a file's labels (``name`` one of :data:`MARKER_SETS` or
    ``"auto"``), completed or overridden by ``extra`` groups (from ``marker_map``); returns its
    name and the canonical joint -> file labels map.

    Raises
    ------
    MarkerMismatch
        No set fits: names the file's markers and the nearest set's missing joints, and says
        how to give a marker map.
    """
    extra = dict(extra or {})
    sets = list(MARKER_SETS.values()) if name == "auto" else [MARKER_SETS[name]]
    plain = {strip_prefix(lab) for lab in labels}
    fits: list[tuple[int, str, dict[str, tuple[str, ...]]]] = []
    nearest: tuple[list[str], str] | None = None
    candidates = [(s.name, {**s.joints, **extra}, s.signature) for s in sets]
    if set(extra) >= set(CANONICAL_JOINTS):
        candidates.insert(0, ("marker_map", extra, ()))
    for set_name, groups, signature in candidates:
        mapping, missing = resolve(groups, labels)
        if not missing:
            fits.append((sum(m in plain for m in signature), set_name, mapping))
        elif nearest is None or len(missing) < len(nearest[0]):
            nearest = (missing, set_name)
    if fits:
        fits.sort(key=lambda f: -f[0])
        return fits[0][1], fits[0][2]
    assert nearest is not None
    shown = ", ".join(labels[:60]) + (f", ... ({len(labels)} in all)" if len(labels) > 60 else "")
    raise MarkerMismatch(
        f"the markers do not make the canonical body: the nearest marker set "
        f"{nearest[1]!r} lacks {', '.join(nearest[0])}; the file's markers are {shown}; give "
        "motion.marker_map (canonical joint = marker or list of markers to average) for the "
        "missing joints"
    )
