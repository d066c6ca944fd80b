"""ASF/AMC reader (Acclaim skeleton and motion, CMU's original format) and forward kinematics.

ASF: ``:units`` (``length`` scale, ``angle deg|rad``), ``:root`` (``order`` of the AMC root values,
``axis`` rotation order, ``position``, ``orientation``), ``:bonedata`` with ``begin ... end`` blocks
(``id``, ``name``, ``direction`` unit vector in the global frame, ``length``, ``axis ax ay az
ORDER``, optional ``dof`` and ``limits``), and ``:hierarchy`` (``parent child ...`` lines between
``begin`` and ``end``).

AMC: ``:FULLY-SPECIFIED``, ``:DEGREES`` (or ``:RADIANS``), then for each frame a frame-number line
followed by one ``bone v1 v2 ...`` line per bone with values in that bone's ``dof`` order (the
root's in its ``order``). Frame numbers must be consecutive.

Forward kinematics (as CMU's own and the common ASF/AMC readers do it): for each bone, ``C`` is the
rotation of its ``axis`` angles and ``M`` the rotation of the frame's ``rx ry rz`` values, both
composed about fixed axes in the bone's axis order (``XYZ``: ``Rz @ Ry @ Rx``); the global rotation
is ``G = G_parent @ C @ M @ C^-1`` and the bone's end is ``end_parent + length * G @ direction``.
The root sits at ``TX TY TZ`` with rotation ``C_root @ M(RX RY RZ) @ C_root^-1`` where ``C_root``
comes from its ``orientation``. Bones without ``dof`` do not rotate relative to their parent.

Every problem raises :class:`mdframework.DataFileError` with the file and 1-based line number.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from mdframework import DataFileError, limits

from .bvh import read_lines
from .kinematics import fixed_axis_rotation

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

_ROT_DOFS = ("rx", "ry", "rz")
_ROOT_CHANNELS = ("TX", "TY", "TZ", "RX", "RY", "RZ")
_SECTIONS = (
    ":version",
    ":name",
    ":units",
    ":documentation",
    ":root",
    ":bonedata",
    ":hierarchy",
    ":skin",
)


@dataclass(frozen=True)
class AsfBone:
    """One ASF bone.

    ``direction`` (3,) float64 is a unit vector in the skeleton's global frame (CMU axes);
    ``length`` is in ASF units; ``axis_deg`` (3,) float64 are the bone frame's Euler angles
    [deg] about x, y, z (converted where the ASF's ``:units angle`` is ``rad``), composed in
    ``axis_order``; ``dof`` lists the rotational degrees of
    freedom (``rx``, ``ry``, ``rz``) in AMC value order; ``parent`` is ``"root"`` or a bone name.
    """

    name: str
    direction: FloatArray
    length: float
    axis_deg: FloatArray
    axis_order: str
    dof: tuple[str, ...]
    parent: str
    line: int


@dataclass(frozen=True)
class AsfSkeleton:
    """A parsed ASF file.

    ``bones`` are in hierarchy order (every parent before its children). ``root_order`` is the order
    of the root's AMC values, ``root_axis`` the root's rotation order, ``root_orientation_deg`` (3,)
    its frame's angles [deg] (converted, like the bone axes, where the file's angles are in
    radians). ``length_scale`` is the ``:units length`` value; ``unit_m`` the metres per ASF
    unit, ``(1 / length_scale) * 2.54 / 100``. ``angles_in_degrees`` is from ``:units angle``:
    the unit of the AMC's values unless the AMC says ``:DEGREES`` or ``:RADIANS``.
    """

    path: Path
    bones: tuple[AsfBone, ...]
    root_order: tuple[str, ...]
    root_axis: str
    root_orientation_deg: FloatArray
    length_scale: float
    angles_in_degrees: bool

    @property
    def unit_m(self) -> float:
        """Metres per ASF length unit."""
        return (1.0 / self.length_scale) * 2.54 / 100.0

    def bone(self, name: str) -> AsfBone:
        """The bone called ``name``; ``KeyError`` if there is none."""
        for b in self.bones:
            if b.name == name:
                return b
        raise KeyError(name)


@dataclass(frozen=True)
class AmcMotion:
    """A parsed AMC file.

    ``values`` maps ``"root"`` and each bone that has values to an array of shape
    (n_frames, n_values), float64, in the order of the root's ``order`` / the bone's ``dof``
    (ASF units for translations, degrees for angles, converted if the file says ``:RADIANS``).
    ``frame_numbers`` (n_frames,) int64 are the numbers written in the file.
    """

    path: Path
    values: dict[str, FloatArray]
    frame_numbers: IntArray

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return int(self.frame_numbers.shape[0])


@dataclass
class _BoneDraft:
    """A bone block being read."""

    line: int
    name: str | None = None
    direction: FloatArray | None = None
    length: float | None = None
    axis_deg: FloatArray = field(default_factory=lambda: np.zeros(3))
    axis_order: str = "XYZ"
    dof: tuple[str, ...] = ()


def _float_list(path: Path, tokens: list[str], count: int, what: str, line: int) -> list[float]:
    if len(tokens) != count:
        raise DataFileError(path, f"{what} needs {count} numbers, found {len(tokens)}", line)
    try:
        out = [float(t) for t in tokens]
    except ValueError:
        bad = next(t for t in tokens if not _is_float(t))
        raise DataFileError(path, f"bad number {bad!r} in {what}", line) from None
    if not all(map(math.isfinite, out)):
        raise DataFileError(path, f"non-finite number in {what}", line)
    if max(map(abs, out), default=0.0) > limits.MAX_FILE_COORDINATE:
        limits.check_values(path, [out], limits.MAX_FILE_COORDINATE, f"{what}:", [line])
    return out


def _floats(path: Path, tokens: list[str], count: int, what: str, line: int) -> FloatArray:
    return np.array(_float_list(path, tokens, count, what, line), dtype=np.float64)


# ----------------------------------------------------------------- checks of values read


def _check_length_unit(path: Path, scale: float, line: int) -> None:
    """The ``:units length`` scale within 1e-3 .. 1e3 (CMU: 0.45)."""
    if not 1e-3 <= scale <= 1e3:
        raise DataFileError(path, f"the length unit {scale:g} is outside 0.001 .. 1000", line)


def _check_amc_angles(
    path: Path,
    bone: str,
    vals: FloatArray,
    order: tuple[str, ...],
    degrees: bool,
    lines: Callable[[int], int] | Sequence[int],
) -> None:
    """Rotation values of one AMC bone (n_frames, n_values) within +-``limits.MAX_ANGLE_DEG``;
    ``lines``: the file line of each frame's values (a sequence, or a function of the frame)."""
    rot = [k for k, c in enumerate(order) if c.upper().startswith("R")]
    limit = limits.MAX_ANGLE_DEG if degrees else np.deg2rad(limits.MAX_ANGLE_DEG)
    unit = " deg" if degrees else " rad"
    limits.check_values(path, vals[:, rot], limit, f"angle of bone {bone!r}:", lines, unit)


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _check_order(path: Path, order: str, line: int) -> str:
    o = order.upper()
    if sorted(o) != ["X", "Y", "Z"]:
        raise DataFileError(
            path, f"rotation order must be a permutation of XYZ, got {order!r}", line
        )
    return o


def read_asf(path: str | Path) -> AsfSkeleton:
    """Read an ASF skeleton file.

    Parameters
    ----------
    path : str or Path
        The ``.asf`` file.

    Returns
    -------
    AsfSkeleton

    Raises
    ------
    mdframework.DataFileError
        Unknown section or keyword, bad number, bone missing from or unknown to the hierarchy,
        unsupported ``dof``, truncated block; the message names the file and line.
    """
    p = Path(path)
    lines = read_lines(p, "an ASF file")
    section = ""
    length_scale = 1.0
    degrees = True
    root_order: tuple[str, ...] = _ROOT_CHANNELS
    root_axis = "XYZ"
    root_orient = np.zeros(3)
    unit_lines: dict[str, int] = {}
    bones: dict[str, _BoneDraft] = {}
    current: _BoneDraft | None = None
    last_key = ""
    links: list[tuple[str, list[str], int]] = []
    hierarchy_open = False
    hierarchy_closed = False
    seen_any = False

    for i, raw in enumerate(lines):
        ln = i + 1
        toks = raw.split()
        if not toks or toks[0].startswith("#"):
            continue
        seen_any = True
        key = toks[0]
        if key.startswith(":"):
            if current is not None:
                raise DataFileError(p, f"bone block not closed before {key!r} (missing 'end')", ln)
            if key.lower() not in _SECTIONS:
                raise DataFileError(p, f"unknown ASF section {key!r}", ln)
            section = key.lower()
            continue
        if section == ":units":
            if len(toks) != 2:
                raise DataFileError(
                    p, f"expected '<unit> <value>' in :units, found {raw.strip()!r}", ln
                )
            if key in unit_lines:
                raise DataFileError(
                    p, f"unit {key!r} given twice (first on line {unit_lines[key]})", ln
                )
            unit_lines[key] = ln
            if key == "length":
                length_scale = float(_floats(p, toks[1:], 1, "the length unit", ln)[0])
                if length_scale <= 0:
                    raise DataFileError(p, "the length unit must be positive", ln)
                _check_length_unit(p, length_scale, ln)
            elif key == "angle":
                if toks[1].lower() not in ("deg", "rad"):
                    raise DataFileError(p, f"angle unit must be deg or rad, got {toks[1]!r}", ln)
                degrees = toks[1].lower() == "deg"
            elif key == "mass":
                if _floats(p, toks[1:], 1, "the mass unit", ln)[0] <= 0:
                    raise DataFileError(p, "the mass unit must be positive", ln)
            else:
                raise DataFileError(p, f"unknown unit {key!r} in :units", ln)
        elif section in (":documentation", ":version", ":name", ":skin"):
            continue
        elif section == ":root":
            if key == "order":
                order = tuple(t.upper() for t in toks[1:])
                if sorted(order) != sorted(_ROOT_CHANNELS):
                    raise DataFileError(
                        p, f"root order must list TX TY TZ RX RY RZ, got {' '.join(toks[1:])!r}", ln
                    )
                root_order = order
            elif key == "axis":
                if len(toks) != 2:
                    raise DataFileError(p, "root axis needs one rotation order such as XYZ", ln)
                root_axis = _check_order(p, toks[1], ln)
            elif key == "position":
                _floats(p, toks[1:], 3, "the root position", ln)
            elif key == "orientation":
                root_orient = _floats(p, toks[1:], 3, "the root orientation", ln)
            else:
                raise DataFileError(p, f"unknown keyword {key!r} in :root", ln)
        elif section == ":bonedata":
            if current is None:
                if key != "begin":
                    raise DataFileError(p, f"expected 'begin' of a bone, found {key!r}", ln)
                current = _BoneDraft(line=ln)
                last_key = "begin"
                continue
            if key == "end":
                for what in ("name", "direction", "length"):
                    if getattr(current, what) is None:
                        raise DataFileError(p, f"bone block ends without {what!r}", ln)
                name = str(current.name)
                if name in bones or name == "root":
                    raise DataFileError(p, f"bone {name!r} defined twice", current.line)
                bones[name] = current
                current = None
                continue
            if key == "id":
                pass
            elif key == "name":
                if len(toks) != 2:
                    raise DataFileError(p, "bone name must be one word", ln)
                current.name = toks[1]
                current.line = ln
            elif key == "direction":
                d = _floats(p, toks[1:], 3, "the bone direction", ln)
                if not np.any(d):
                    raise DataFileError(p, "bone direction is the zero vector", ln)
                # Used as written (unit to the file's 6 digits), as CMU's recipe and readers do.
                current.direction = d
            elif key == "length":
                length = float(_floats(p, toks[1:], 1, "the bone length", ln)[0])
                if length < 0:
                    raise DataFileError(p, "bone length must not be negative", ln)
                current.length = length
            elif key == "axis":
                if len(toks) != 5:
                    raise DataFileError(p, "bone axis needs three angles and an order (XYZ)", ln)
                current.axis_deg = _floats(p, toks[1:4], 3, "the bone axis", ln)
                current.axis_order = _check_order(p, toks[4], ln)
            elif key == "dof":
                dof = tuple(t.lower() for t in toks[1:])
                for d_ in dof:
                    if d_ not in _ROT_DOFS:
                        raise DataFileError(
                            p, f"unsupported dof {d_!r} (only rx, ry, rz are supported)", ln
                        )
                if len(set(dof)) != len(dof):
                    raise DataFileError(p, "a dof is listed twice", ln)
                current.dof = dof
            elif key == "limits" or (key.startswith("(") and last_key == "limits"):
                key = "limits"
            elif key in ("bodymass", "cofmass"):
                pass
            else:
                raise DataFileError(p, f"unknown keyword {key!r} in a bone block", ln)
            last_key = key
        elif section == ":hierarchy":
            if key == "begin" and not hierarchy_open:
                hierarchy_open = True
            elif key == "end" and hierarchy_open:
                hierarchy_open = False
                hierarchy_closed = True
            elif hierarchy_open:
                links.append((key, toks[1:], ln))
            else:
                raise DataFileError(p, f"unexpected {key!r} in :hierarchy (expected begin/end)", ln)
        else:
            raise DataFileError(p, f"unexpected {key!r} outside any ASF section", ln)

    last = len(lines)
    if not seen_any:
        raise DataFileError(p, "empty ASF file", 1)
    if current is not None:
        raise DataFileError(p, "file ends inside a bone block (missing 'end')", last)
    if hierarchy_open or not hierarchy_closed:
        raise DataFileError(p, "file ends without a complete :hierarchy block", last)

    parent_of: dict[str, tuple[str, int]] = {}
    children: dict[str, list[str]] = {"root": []}
    for parent, kids, ln in links:
        if parent != "root" and parent not in bones:
            raise DataFileError(p, f"hierarchy names unknown bone {parent!r}", ln)
        for kid in kids:
            if kid not in bones:
                raise DataFileError(p, f"hierarchy names unknown bone {kid!r}", ln)
            if kid in parent_of:
                raise DataFileError(p, f"bone {kid!r} has two parents in the hierarchy", ln)
            parent_of[kid] = (parent, ln)
            children.setdefault(parent, []).append(kid)
    ordered: list[str] = []
    stack = list(reversed(children["root"]))
    while stack:
        b = stack.pop()
        ordered.append(b)
        stack.extend(reversed(children.get(b, [])))
    for name, info in bones.items():
        if name not in ordered:
            raise DataFileError(
                p, f"bone {name!r} is not connected to the root in :hierarchy", info.line
            )
    # the ASF's own angles (root orientation, bone axes) follow its `angle` unit
    to_deg = 1.0 if degrees else 180.0 / math.pi
    out: list[AsfBone] = []
    for name in ordered:
        info = bones[name]
        assert info.direction is not None and info.length is not None
        out.append(
            AsfBone(
                name=name,
                direction=info.direction,
                length=info.length,
                axis_deg=info.axis_deg * to_deg,
                axis_order=info.axis_order,
                dof=info.dof,
                parent=parent_of[name][0],
                line=info.line,
            )
        )
    return AsfSkeleton(
        p, tuple(out), root_order, root_axis, root_orient * to_deg, length_scale, degrees
    )


def read_amc(path: str | Path, asf: AsfSkeleton) -> AmcMotion:
    """Read an AMC motion file for the skeleton ``asf``.

    Parameters
    ----------
    path : str or Path
        The ``.amc`` file.
    asf : AsfSkeleton
        Its skeleton (gives each bone's number and order of values).

    Returns
    -------
    AmcMotion
        Values per bone, shape (n_frames, n_values), float64; angles in degrees.

    Raises
    ------
    mdframework.DataFileError
        Unknown keyword, bone not in the ASF, wrong number of values, bad number, bone missing or
        repeated in a frame, non-consecutive frame numbers, zero frames; names the file and line.
    """
    p = Path(path)
    lines = read_lines(p, "an AMC file")
    regular = _read_regular_amc(p, lines, asf)
    if regular is not None:
        return regular
    counts, _ = _amc_layout(asf)
    bone_lines: dict[str, list[int]] = {}
    degrees = asf.angles_in_degrees
    rows: dict[str, list[list[float]]] = {}
    numbers: list[int] = []
    in_frame: set[str] = set()
    expected = {name for name, c in counts.items() if c > 0}

    def close_frame(next_line: int) -> None:
        missing = expected - in_frame
        if missing:
            raise DataFileError(
                p,
                f"frame {numbers[-1]} lacks bone(s) {', '.join(sorted(missing))}",
                next_line,
            )

    for i, raw in enumerate(lines):
        ln = i + 1
        toks = raw.split()
        if not toks or toks[0].startswith("#"):
            continue
        key = toks[0]
        if key.startswith(":"):
            if numbers:
                raise DataFileError(p, f"keyword {key!r} after the first frame", ln)
            k = key.upper()
            if k == ":DEGREES":
                degrees = True
            elif k == ":RADIANS":
                degrees = False
            elif k != ":FULLY-SPECIFIED":
                raise DataFileError(p, f"unknown AMC keyword {key!r}", ln)
            continue
        if key.isdigit():
            if len(toks) != 1:
                raise DataFileError(p, f"frame number line has extra text {raw.strip()!r}", ln)
            num = int(key)
            if numbers:
                close_frame(ln)
                if num != numbers[-1] + 1:
                    raise DataFileError(
                        p,
                        f"frame number {num} follows {numbers[-1]}; frames must be consecutive",
                        ln,
                    )
            numbers.append(num)
            in_frame = set()
            continue
        if not numbers:
            raise DataFileError(p, f"expected a frame number, found {key!r}", ln)
        if key not in counts:
            raise DataFileError(p, f"bone {key!r} is not in the skeleton {asf.path.name}", ln)
        if key in in_frame:
            raise DataFileError(p, f"bone {key!r} appears twice in frame {numbers[-1]}", ln)
        vals = _float_list(p, toks[1:], counts[key], f"the values of bone {key!r}", ln)
        bone_lines.setdefault(key, []).append(ln)
        in_frame.add(key)
        rows.setdefault(key, []).append(vals)
    if not numbers:
        raise DataFileError(p, "the file holds zero frames", max(len(lines), 1))
    close_frame(len(lines))
    arrays = {
        name: np.asarray(r, dtype=np.float64).reshape(len(numbers), counts[name])
        for name, r in rows.items()
    }
    return _amc_motion(p, asf, arrays, degrees, bone_lines.__getitem__, numbers)


def _amc_layout(asf: AsfSkeleton) -> tuple[dict[str, int], dict[str, tuple[str, ...]]]:
    """The number of AMC values of the root and of each bone, and their order."""
    counts = {"root": 6, **{b.name: len(b.dof) for b in asf.bones}}
    orders = {"root": asf.root_order, **{b.name: b.dof for b in asf.bones}}
    return counts, orders


def _amc_motion(
    p: Path,
    asf: AsfSkeleton,
    arrays: dict[str, FloatArray],
    degrees: bool,
    lines_of: Callable[[str], Callable[[int], int] | Sequence[int]],
    numbers: list[int],
) -> AmcMotion:
    """The motion of parsed AMC values (bone -> (n_frames, n_values)), with the angle limits
    checked (``lines_of(bone)`` gives each frame's line of that bone) and radians converted."""
    _, orders = _amc_layout(asf)
    values: dict[str, FloatArray] = {}
    for name, arr in arrays.items():
        _check_amc_angles(p, name, arr, orders[name], degrees, lines_of(name))
        if not degrees:
            if name == "root":
                rot = [k for k, c in enumerate(asf.root_order) if c.startswith("R")]
                arr[:, rot] = np.rad2deg(arr[:, rot])
            else:
                arr = np.rad2deg(arr)
        values[name] = arr
    return AmcMotion(p, values, np.asarray(numbers, dtype=np.int64))


#: Token put between the lines of an AMC file for the whole-file parse (not in any valid file)
_EOL = "|"


def _read_regular_amc(p: Path, lines: list[str], asf: AsfSkeleton) -> AmcMotion | None:
    """Parse an AMC file whose frames all list the same bones in the same order on consecutive
    lines (as every CMU file does) in one pass over the whole file: the values are converted by
    numpy with Python's own ``float`` (an object array's cast), so they are the line-by-line
    parse's bit for bit. Returns None for any other file (comments or blank lines among the
    frames, a bone missing or moved, a bad or out-of-range number, ...): the line-by-line parse
    then reads it, or names the file and line of its first problem."""
    counts, _ = _amc_layout(asf)
    degrees = asf.angles_in_degrees
    first = None
    for i, raw in enumerate(lines):
        toks = raw.split()
        if not toks or toks[0].startswith("#"):
            continue
        if toks[0].isdigit():
            first = i
            break
        k = toks[0].upper()
        if len(toks) != 1 or k not in (":FULLY-SPECIFIED", ":DEGREES", ":RADIANS"):
            return None
        if k != ":FULLY-SPECIFIED":
            degrees = k == ":DEGREES"
    if first is None or len(lines[first].split()) != 1:
        return None
    # the bones of the first frame, in file order, give every frame's layout
    names: list[str] = []
    for raw in lines[first + 1 :]:
        toks = raw.split()
        if not toks or toks[0].isdigit():
            break
        if toks[0] not in counts or toks[0] in names or len(toks) != 1 + counts[toks[0]]:
            return None
        names.append(toks[0])
    if not {name for name, c in counts.items() if c > 0} <= set(names):
        return None
    end = len(lines)
    while end > first and not lines[end - 1].strip():
        end -= 1
    text = f" {_EOL} ".join(lines[first:end])
    if text.count(_EOL) != end - first - 1:  # the file has one of its own
        return None
    # per frame: number, EOL, then per bone: name, values, EOL
    tokens = np.array((text + f" {_EOL}").split(), dtype=object)
    width = 2 + sum(2 + counts[name] for name in names)
    if tokens.size % width:
        return None
    frames = tokens.reshape(-1, width)
    cols: dict[str, slice] = {}
    col = 2
    for name in names:
        cols[name] = slice(col + 1, col + 1 + counts[name])
        if not (np.all(frames[:, col] == name) and np.all(frames[:, cols[name].stop] == _EOL)):
            return None
        col = cols[name].stop + 1
    if not np.all(frames[:, 1] == _EOL):
        return None
    heads = frames[:, 0].tolist()
    if not all(h.isascii() and h.isdigit() for h in heads):
        return None
    numbers = [int(h) for h in heads]
    if numbers != list(range(numbers[0], numbers[0] + len(numbers))):
        return None
    arrays: dict[str, FloatArray] = {}
    for name in names:
        try:
            arr = frames[:, cols[name]].astype(np.float64)  # Python's float() of each token
        except ValueError:
            return None
        if not np.all(np.abs(arr) <= limits.MAX_FILE_COORDINATE):  # NaN fails too
            return None
        arrays[name] = arr
    step = 1 + len(names)

    def lines_of(name: str) -> Callable[[int], int]:
        line = first + 2 + names.index(name)  # 1-based line of the bone in the first frame
        return lambda k: line + k * step

    return _amc_motion(p, asf, arrays, degrees, lines_of, numbers)


def asf_forward_kinematics(asf: AsfSkeleton, amc: AmcMotion) -> tuple[tuple[str, ...], FloatArray]:
    """Positions of the root and of every bone's end point.

    Parameters
    ----------
    asf : AsfSkeleton
        The skeleton.
    amc : AmcMotion
        Its motion.

    Returns
    -------
    names : tuple of str
        ``"root"`` then the bone names (each joint is the bone's end point).
    positions : ndarray, shape (n_frames, 1 + n_bones, 3), float64
        In ASF units and CMU axes (y up).
    """
    n = amc.n_frames
    root_vals = amc.values["root"]
    col = {c: k for k, c in enumerate(asf.root_order)}
    root_pos = root_vals[:, [col["TX"], col["TY"], col["TZ"]]]
    root_rot = root_vals[:, [col["RX"], col["RY"], col["RZ"]]]
    c_root = fixed_axis_rotation(asf.root_axis, asf.root_orientation_deg[None, :])[0]
    m_root = fixed_axis_rotation(asf.root_axis, root_rot)
    glob: dict[str, FloatArray] = {"root": c_root @ m_root @ c_root.T}
    ends: dict[str, FloatArray] = {"root": root_pos}
    for bone in asf.bones:
        c = fixed_axis_rotation(bone.axis_order, bone.axis_deg[None, :])[0]
        parent_g = glob[bone.parent]
        if bone.dof:
            angles = np.zeros((n, 3))
            vals = amc.values[bone.name]
            for k, d in enumerate(bone.dof):
                angles[:, _ROT_DOFS.index(d)] = vals[:, k]
            g = parent_g @ (c @ fixed_axis_rotation(bone.axis_order, angles) @ c.T)
        else:
            g = parent_g
        glob[bone.name] = g
        ends[bone.name] = ends[bone.parent] + bone.length * (g @ bone.direction)
    names = ("root", *(b.name for b in asf.bones))
    return names, np.stack([ends[nm] for nm in names], axis=1)
