"""DeepMimic motion clips: JSON text with a loop mode and a list of frames.

A clip (DeepMimic's ``data/motions/*.txt``) is one JSON object::

    {
    "Loop": "wrap",
    "Frames":
    [
    [0.0333, 0.0000, 0.8475, 0.0000, 0.9987, 0.0141, -0.0007, -0.0494, ...],
    ...
    ]
    }

``Loop`` is ``"wrap"`` (a cycle: the clip may be repeated), ``"mirror"`` (a cycle whose every
other repetition DeepMimic plays mirrored left for right) or ``"none"`` (also when absent).
Other keys (``VelFilterCutoff``, ``RightJoints``, ...) are not used.
Each frame is, for the character's joints in file order: the duration of the frame [s], the
root position (3) [m] and rotation (4, a quaternion w, x, y, z) in the world, then each joint's
rotation relative to its parent: a quaternion (w, x, y, z) for a spherical joint, an angle
[rad] about the joint's z axis for a revolute one (knees, elbows), nothing for a fixed one. For
``humanoid3d`` that is 44 numbers (:mod:`mdf_deepmimic.character`).

Time: frame ``i`` starts at the sum of the durations of the frames before it; the last
frame's duration is not used (DeepMimic's own clips give it as 0). Every other duration must
lie in [1 / ``limits.MAX_FRAME_RATE_HZ``, 1 / ``limits.MIN_FRAME_RATE_HZ``] s.

Checks, before anything is allocated for the frames: the file is at most
:data:`MAX_CLIP_BYTES` long, UTF-8 text without NUL bytes, valid JSON (a truncated file names
its last line), an object with a ``Frames`` list of at most ``limits.MAX_FRAMES`` frames; then
every frame is a list of numbers of the character's width, durations as above, every value
finite, positions within ``limits.MAX_COORDINATE_M``, angles within ``limits.MAX_ANGLE_DEG``,
quaternions of norm in [:data:`MIN_QUATERNION_NORM`, :data:`MAX_QUATERNION_NORM`] (they are
normalised, as DeepMimic does: its own clips hold quaternions of norm 0.58-1). An error names
the file, the line of the frame, the frame's number (from 0) and the joint.
"""

from __future__ import annotations

import math
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from mdframework import DataFileError, limits

from .character import HUMANOID3D, Character, read_json

FloatArray = NDArray[np.float64]

#: Largest clip file [bytes]: about 140,000 frames of ``humanoid3d`` written as DeepMimic does
#: (44 numbers of 21 characters), over an hour at 30 frames per second.
MAX_CLIP_BYTES = 128 * 1024 * 1024
#: Quaternions must have a norm in this range (then they are normalised).
MIN_QUATERNION_NORM = 0.1
MAX_QUATERNION_NORM = 10.0
#: Loop modes of a clip.
LOOPS = ("wrap", "mirror", "none")


@dataclass(frozen=True)
class Clip:
    """A clip as read, in the file's frame (y up) and units (metres, radians).

    ``time`` (n,) float64 [s] from 0; ``durations`` (n,) [s] as in the file; ``root_position``
    (n, 3) [m]; ``rotations``: joint name -> (n, 4) float64 unit quaternions (w, x, y, z) for
    the root and the spherical joints, (n,) float64 angles [rad] for the revolute joints.
    ``renormalised``: how many quaternions had a norm off 1 by more than 1e-3, and
    ``min_norm``/``max_norm`` the extreme norms found.
    """

    loop: str
    time: FloatArray
    durations: FloatArray
    root_position: FloatArray
    rotations: dict[str, FloatArray]
    renormalised: int = 0
    min_norm: float = 1.0
    max_norm: float = 1.0

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return int(self.time.shape[0])


class _FrameLines:
    """The 1-based line on which each frame starts, found only when an error needs it."""

    def __init__(self, text: str) -> None:
        self.text = text
        self._lines: list[int] | None = None

    def key_line(self, key: str) -> int | None:
        m = re.search(rf'"{re.escape(key)}"\s*:', self.text)
        return self.text.count("\n", 0, m.start()) + 1 if m else None

    def __call__(self, frame: int) -> int:
        if self._lines is None:
            self._lines = self._scan()
        if 0 <= frame < len(self._lines):
            return self._lines[frame]
        return self.key_line("Frames") or 1

    def _scan(self) -> list[int]:
        m = re.search(r'"Frames"\s*:\s*\[', self.text)
        if m is None:
            return []
        starts: list[int] = []
        depth, line, last = 1, 1 + self.text.count("\n", 0, m.end()), m.end()
        for b in re.finditer(r"[\[\]]", self.text[m.end() :]):
            pos = m.end() + b.start()
            if b.group() == "[":
                if depth == 1:
                    line += self.text.count("\n", last, pos)
                    last = pos
                    starts.append(line)
                depth += 1
            else:
                depth -= 1
                if depth == 0:
                    break
        return starts


def _is_number(v: object) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


def read_clip(path: Path, character: Character = HUMANOID3D) -> Clip:
    """Read and check a DeepMimic clip for ``character`` (see the module docstring).

    Raises
    ------
    mdframework.DataFileError
        The file is too large, binary, not JSON, not a clip object, has fewer than two or too
        many frames, a frame of the wrong width or with a value that is not a number, a
        duration, position, angle or quaternion out of range (names the line and frame).
    """
    text, doc = read_json(path, "a DeepMimic clip", MAX_CLIP_BYTES)
    lines = _FrameLines(text)
    if not isinstance(doc, dict) or not isinstance(doc.get("Frames"), list):
        raise DataFileError(
            path,
            'not a DeepMimic clip: expected a JSON object with a "Frames" list of frames',
            lines.key_line("Frames"),
        )
    loop = doc.get("Loop", "none")
    if loop not in LOOPS:
        raise DataFileError(
            path,
            f'"Loop" is {loop!r}; a clip\'s loop is "wrap", "mirror" or "none"',
            lines.key_line("Loop"),
        )
    frames: list[Any] = doc["Frames"]
    n = len(frames)
    limits.check_declared_count(path, lines.key_line("Frames") or 1, "frames", n)
    if n < 2:
        raise DataFileError(
            path, f"{n} frame(s): a motion needs at least two", lines.key_line("Frames")
        )
    width = character.frame_width
    for i, f in enumerate(frames):
        if not isinstance(f, list) or len(f) != width:
            got = f"{len(f)} values" if isinstance(f, list) else f"a {type(f).__name__}"
            raise DataFileError(
                path,
                f"frame {i} has {got}; a {character.name} frame has {width}: the duration, "
                "the root position (3) and rotation (4), then "
                + ", ".join(f"{joint} ({w})" for _, joint, _, w in character.layout()[3:]),
                lines(i),
            )
        if not all(map(_is_number, f)):
            bad = next(v for v in f if not _is_number(v))
            raise DataFileError(path, f"frame {i}: {bad!r} is not a number", lines(i))
    values = np.array(frames, dtype=np.float64)
    return _check_and_split(path, values, loop, character, lines)


def _check_and_split(
    path: Path, values: FloatArray, loop: str, character: Character, lines: _FrameLines
) -> Clip:
    n = values.shape[0]
    limits.check_values(path, values, sys.float_info.max, "a value", lines)  # finite
    d = values[:, 0]
    lo, hi = 1.0 / limits.MAX_FRAME_RATE_HZ, 1.0 / limits.MIN_FRAME_RATE_HZ
    bad = np.flatnonzero(~((d[:-1] >= lo) & (d[:-1] <= hi)))
    if bad.size:
        i = int(bad[0])
        raise DataFileError(
            path,
            f"frame {i}: duration {float(d[i])!r} s is outside [{lo:g}, {hi:g}] s (frames at "
            f"{limits.MIN_FRAME_RATE_HZ:g}-{limits.MAX_FRAME_RATE_HZ:g} per second); only the "
            "last frame's duration may be 0",
            lines(i),
        )
    if not 0.0 <= d[-1] <= hi:
        raise DataFileError(
            path, f"frame {n - 1} (the last): duration {float(d[-1])!r} s is outside [0, {hi:g}] s",
            lines(n - 1),
        )  # fmt: skip
    limits.check_values(
        path, values[:, 1:4], limits.MAX_COORDINATE_M, "a root position", lines, unit=" m"
    )
    rotations: dict[str, FloatArray] = {}
    renormalised, lo_norm, hi_norm = 0, 1.0, 1.0
    max_angle = math.radians(limits.MAX_ANGLE_DEG)
    for kind, joint, col, _ in character.layout()[2:]:
        if kind == "revolute":
            limits.check_values(
                path, values[:, col], max_angle, f"the {joint} angle", lines, unit=" rad"
            )
            rotations[joint] = values[:, col].copy()
            continue
        q = values[:, col : col + 4]
        norm = np.linalg.norm(q, axis=1)
        out = np.flatnonzero(~((norm >= MIN_QUATERNION_NORM) & (norm <= MAX_QUATERNION_NORM)))
        if out.size:
            i = int(out[0])
            raise DataFileError(
                path,
                f"frame {i}: the {joint} quaternion {q[i].tolist()} has norm {norm[i]:.3g}, "
                f"outside [{MIN_QUATERNION_NORM:g}, {MAX_QUATERNION_NORM:g}]: not a rotation",
                lines(i),
            )
        renormalised += int(np.count_nonzero(np.abs(norm - 1.0) > 1e-3))
        lo_norm, hi_norm = min(lo_norm, float(norm.min())), max(hi_norm, float(norm.max()))
        rotations[joint] = q / norm[:, None]
    time = np.concatenate([[0.0], np.cumsum(d[:-1])])
    limits.check_time_stamps(path, time)
    return Clip(
        loop=loop,
        time=time,
        durations=d.copy(),
        root_position=values[:, 1:4].copy(),
        rotations=rotations,
        renormalised=renormalised,
        min_norm=lo_norm,
        max_norm=hi_norm,
    )
