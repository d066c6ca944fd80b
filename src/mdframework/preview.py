"""Motion previews: the body in the scene beside its spectrogram (``mdf show``).

Two figures of one run, both drawn in the project style (:mod:`mdframework.figures`):

- :func:`animate` saves an animation (GIF through Pillow, or MP4 through the ffmpeg binary that
  ``imageio-ffmpeg`` ships) of three panels: the scene from above (radar, line of sight to the
  hip centre, the hip centre's path, the body's outline), the body in 3-D following the person
  (segments, the line of sight toward the radar), and the spectrogram with a time cursor.
- :func:`plot_stills` saves the body at chosen instants above the spectrogram, with the instants
  marked on it.

The body is a :class:`~mdframework.skeleton.Skeleton` in the scene frame, times [s] from the
record's first pulse (the spectrogram's time base); at an instant the preview shows the body's
nearest frame (never an interpolated pose). Joints marked not valid are left out. A body with
the canonical joints is drawn with the canonical segments, any other as points.

matplotlib is imported inside the functions that draw.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .errors import MdfError
from .figures import COLORMAP, DYNAMIC_RANGE_DB, draw_spectrogram, run_caption, save, style
from .progress import QUIET, Progress
from .skeleton import CANONICAL_JOINTS, CANONICAL_SEGMENTS, Skeleton

if TYPE_CHECKING:
    from .pipeline import RunResult

FloatArray = NDArray[np.float64]

#: Animation formats and the matplotlib writer each uses.
FORMATS = ("gif", "mp4")
#: Resolution of animations [dots per inch] (14 x 4.8 in: 1120 x 384 pixels).
ANIMATION_DPI = 80
#: Side of the 3-D body view [m].
BODY_BOX_M = 2.2
#: Colour of a canonical segment by the body side of its distal joint (colour-blind-safe cycle:
#: blue left, dark orange right, dark grey trunk and head), so left and right limbs differ.
SIDE_COLOURS = {"left": "C0", "right": "C5", "centre": "C3"}


def segment_side(distal: str) -> str:
    """``"left"``, ``"right"`` or ``"centre"``: the body side of a segment, by the canonical name
    of its distal joint (``l_...``, ``r_...``, or neither)."""
    if distal.startswith("l_"):
        return "left"
    if distal.startswith("r_"):
        return "right"
    return "centre"


class PreviewError(MdfError):
    """A preview cannot be made as asked (an instant outside the record, no video encoder)."""


@dataclass(frozen=True)
class SpectrogramView:
    """A spectrogram and how to show it: ``power_db`` (n_doppler, n_frames) [dB re peak],
    ``time`` (n_frames,) [s from the first pulse], ``velocity`` (n_doppler,) ascending [m/s]."""

    power_db: NDArray[np.floating[Any]]
    time: FloatArray
    velocity: FloatArray
    dynamic_range_db: float = DYNAMIC_RANGE_DB
    velocity_span: str | float = "auto"
    colormap: str = COLORMAP


def frame_at(time: FloatArray, instants: FloatArray) -> NDArray[np.intp]:
    """Index of the frame nearest to each instant (ties to the earlier frame); ``time``
    (n_frames,) strictly increasing [s], ``instants`` (n,) [s]."""
    t = np.asarray(time, dtype=np.float64)
    x = np.asarray(instants, dtype=np.float64)
    right = np.clip(np.searchsorted(t, x, side="left"), 1, max(1, t.size - 1))
    left = right - 1
    if t.size == 1:
        return np.zeros(x.shape, dtype=np.intp)
    nearer_left = np.abs(x - t[left]) <= np.abs(t[right] - x)
    return np.where(nearer_left, left, right).astype(np.intp)


def animation_times(body: Skeleton, fps: int) -> FloatArray:
    """Times [s] of the animation frames: every ``1/fps`` s from the body's first frame to its
    last, in real time."""
    from .limits import MAX_ANIMATION_FPS

    if not 0 < fps <= MAX_ANIMATION_FPS:
        raise PreviewError(f"--fps: must be 1 .. {MAX_ANIMATION_FPS}, got {fps}")
    n = int(np.floor(body.duration * fps + 1e-9)) + 1
    return np.asarray(body.time[0] + np.arange(n) / fps, dtype=np.float64)


#: The highest frame rate a GIF plays at: its frame times are in hundredths of a second, and
#: viewers commonly slow frames shorter than 20 ms down to 100 ms.
GIF_MAX_FPS = 50


def check_frame_rate(fmt: str, fps: int) -> None:
    """Refuse (:class:`PreviewError`, naming ``--fps``) a GIF faster than :data:`GIF_MAX_FPS`,
    which would not play in real time; an MP4 takes any rate ``mdf show`` allows."""
    if fmt == "gif" and fps > GIF_MAX_FPS:
        raise PreviewError(
            f"--fps: a GIF plays at most {GIF_MAX_FPS} frames per second in real time (its "
            f"frame times are hundredths of a second), got {fps}: lower --fps, or use "
            "--format mp4"
        )


#: The most instants ``skeleton.png`` shows: one panel each, side by side, 2.6 inches wide.
MAX_INSTANTS = 12


def check_instants(body: Skeleton, instants: Sequence[float] | FloatArray) -> FloatArray:
    """The instants as an array, at most :data:`MAX_INSTANTS`, each within the body's time span
    (else :class:`PreviewError` naming ``--at`` and the span)."""
    x: FloatArray = np.asarray(list(instants), dtype=np.float64)
    if x.size > MAX_INSTANTS:
        raise PreviewError(
            f"--at: skeleton.png shows at most {MAX_INSTANTS} instants side by side, got {x.size}"
        )
    lo, hi = float(body.time[0]), float(body.time[-1])
    bad = x[(x < lo - 1e-9) | (x > hi + 1e-9) | ~np.isfinite(x)]
    if x.size == 0 or bad.size:
        which = f"{bad[0]:g} s is" if bad.size else "no instant is"
        # + 0.0: a span starting microseconds before 0 reads 0.000, not -0.000
        span = f"{round(lo, 3) + 0.0:.3f} to {round(hi, 3) + 0.0:.3f} s"
        raise PreviewError(f"--at: {which} outside the record ({span})")
    return x


def default_instants(body: Skeleton, n: int = 5) -> FloatArray:
    """``n`` instants evenly spread over the record: the centres of ``n`` equal parts."""
    lo, hi = float(body.time[0]), float(body.time[-1])
    step = (hi - lo) / n
    return np.asarray(lo + step * (np.arange(n) + 0.5), dtype=np.float64)


class _Scene:
    """The artists of the preview panels and how they follow time."""

    def __init__(self, body: Skeleton, radar_position: FloatArray) -> None:
        self.body = body
        self.radar = np.asarray(radar_position, dtype=np.float64)
        if body.joint_names == CANONICAL_JOINTS:
            self.segments = [(body.index(a), body.index(b)) for a, b in CANONICAL_SEGMENTS]
            self.sides = [segment_side(b) for _, b in CANONICAL_SEGMENTS]
            self.centre: int | None = body.index("base")
        else:
            self.segments = []
            self.sides = []
            self.centre = None
        self.top_lines: list[Any] = []
        self.body_lines: list[Any] = []
        self.top_points: Any = None

    def pose(self, frame: int) -> FloatArray:
        """Joint positions of one frame, NaN where not valid, (n_joints, 3) [m]."""
        p = np.array(self.body.positions[frame], dtype=np.float64)
        p[~self.body.valid[frame]] = np.nan
        return p

    def centre_of(self, pose: FloatArray) -> FloatArray:
        """Hip centre, or the mean of the valid joints (3,) [m]."""
        if self.centre is not None and np.all(np.isfinite(pose[self.centre])):
            return np.asarray(pose[self.centre], dtype=np.float64)
        return np.asarray(np.nanmean(pose, axis=0), dtype=np.float64)

    def path(self) -> FloatArray:
        """The centre's track over the record (n_frames, 3) [m]."""
        return np.array(
            [self.centre_of(self.pose(k)) for k in range(self.body.n_frames)], dtype=np.float64
        )

    def draw_top(self, ax: Any) -> None:
        """Top view: radar, path, line of sight, body outline (x-y plane)."""
        path = self.path()
        ax.plot(path[:, 0], path[:, 1], ls="--", lw=1.0, color="0.5", label="path")
        ax.plot(*self.radar[:2], marker="^", ms=9, color="C1", ls="", label="radar")
        (self.los_top,) = ax.plot([], [], lw=1.0, color="C1", label="line of sight")
        self.top_lines = [ax.plot([], [], lw=1.5, color=SIDE_COLOURS[s])[0] for s in self.sides]
        (self.top_points,) = ax.plot([], [], ls="", marker=".", ms=3, color="C0")
        xy = np.vstack([path[:, :2], self.radar[None, :2]])
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        mid = (xy.min(axis=0) + xy.max(axis=0)) / 2
        half = float(np.max(xy.max(axis=0) - xy.min(axis=0))) / 2 + 1.0
        ax.set_xlim(mid[0] - half, mid[0] + half)
        ax.set_ylim(mid[1] - half, mid[1] + half)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title("scene from above")
        ax.legend(loc="upper left", fontsize=7)

    def draw_body(self, ax: Any) -> None:
        """3-D body view that follows the person."""
        self.body_lines = []
        labelled = {"centre"}  # the legend names the sides once each
        for side in self.sides:
            label = None if side in labelled else side
            labelled.add(side)
            (line,) = ax.plot([], [], [], lw=2.0, color=SIDE_COLOURS[side], label=label)
            self.body_lines.append(line)
        (self.body_points,) = ax.plot([], [], [], ls="", marker="o", ms=2.5, color="C3")
        (self.los_body,) = ax.plot(
            [], [], [], lw=1.0, ls="--", color="C1", label="toward the radar"
        )
        ax.set_box_aspect((1.0, 1.0, 1.0))
        # the box follows the person: tick labels would change every frame, so none are drawn
        ax.set_xticklabels([])
        ax.set_yticklabels([])
        ax.set_zticklabels([])
        # no tick labels to clear: the axis names sit against the box, not in the next panel
        ax.set_xlabel("x", labelpad=-12)
        ax.set_ylabel("y", labelpad=-12)
        ax.set_zlabel("z", labelpad=-12)
        ax.set_title(f"body (box {BODY_BOX_M:g} m)")
        ax.legend(loc="upper left", fontsize=7)
        self.body_ax = ax

    def update(self, t: float) -> FloatArray:
        """Show the body's nearest frame to ``t``; returns that frame's pose (n_joints, 3)."""
        k = int(frame_at(self.body.time, np.array([t]))[0])
        pose = self.pose(k)
        centre = self.centre_of(pose)
        for line, (a, b) in zip(self.top_lines, self.segments, strict=False):
            line.set_data(pose[[a, b], 0], pose[[a, b], 1])
        for line3, (a, b) in zip(self.body_lines, self.segments, strict=True):
            line3.set_data_3d(pose[[a, b], 0], pose[[a, b], 1], pose[[a, b], 2])
        self.body_points.set_data_3d(pose[:, 0], pose[:, 1], pose[:, 2])
        if self.top_points is not None:
            self.top_points.set_data(pose[:, 0], pose[:, 1])
            self.los_top.set_data([self.radar[0], centre[0]], [self.radar[1], centre[1]])
        to_radar = self.radar - centre
        dist = float(np.linalg.norm(to_radar))
        tip = centre + to_radar * min(1.0, 0.5 * BODY_BOX_M / dist) if dist > 0 else centre
        self.los_body.set_data_3d([centre[0], tip[0]], [centre[1], tip[1]], [centre[2], tip[2]])
        half = BODY_BOX_M / 2
        ax = self.body_ax
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_zlim(centre[2] - half, centre[2] + half)
        return pose


def _figure(plt: Any, scene: _Scene, spec: SpectrogramView) -> tuple[Any, Any]:
    fig = plt.figure(figsize=(14, 4.8), layout="constrained")
    grid = fig.add_gridspec(1, 3, width_ratios=(1.0, 1.0, 1.6))
    scene.draw_top(fig.add_subplot(grid[0]))
    scene.draw_body(fig.add_subplot(grid[1], projection="3d"))
    ax = fig.add_subplot(grid[2])
    im = _spectrogram(ax, spec, scene.body)
    fig.colorbar(im, ax=ax, label="power [dB re peak]")
    cursor = _time_mark(ax, float(spec.time[0]), lw=1.2)
    return fig, cursor


def _spectrogram(ax: Any, spec: SpectrogramView, body: Skeleton) -> Any:
    """The spectrogram, its time axis covering the whole record (the body's first to last
    frame) as well as the frames: the first frame is centred half a window after the record's
    start, and a cursor or an instant before it must stay on the axes."""
    im = draw_spectrogram(
        ax,
        spec.power_db,
        spec.time,
        spec.velocity,
        dynamic_range_db=spec.dynamic_range_db,
        velocity_span=spec.velocity_span,
        colormap=spec.colormap,
    )
    lo, hi = ax.get_xlim()
    ax.set_xlim(min(lo, float(body.time[0])), max(hi, float(body.time[-1])))
    return im


def _time_mark(ax: Any, t: float, lw: float) -> Any:
    """A vertical line at ``t``: white with a dark edge, seen on the colour map and on the
    blank axes outside the frames."""
    from matplotlib import patheffects

    edge = [patheffects.Stroke(linewidth=lw + 1.2, foreground="0.2"), patheffects.Normal()]
    return ax.axvline(t, color="white", lw=lw, path_effects=edge)


def animate(
    path: Path,
    body: Skeleton,
    radar_position: FloatArray,
    spec: SpectrogramView,
    *,
    fps: int = 12,
    title: str = "",
    caption: str = "",
    progress: Progress = QUIET,
) -> int:
    """Save the animated preview to ``path`` (``.gif`` or ``.mp4``); one frame every ``1/fps``
    s of the record, played in real time (``progress``: a bar over the frames). Returns the
    number of frames."""
    fmt = Path(path).suffix.lower().lstrip(".")
    times = animation_times(body, fps)
    progress.stage(f"laying out {Path(path).name}")
    with style() as plt:
        from matplotlib.animation import FFMpegWriter, PillowWriter

        writer: Any
        if fmt == "gif":
            writer = _real_time_gif(PillowWriter)(fps=fps)
        elif fmt == "mp4":
            writer = FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"])
            plt.rcParams["animation.ffmpeg_path"] = _ffmpeg()
        else:
            raise PreviewError(f"--format: {fmt!r} is not one of {', '.join(FORMATS)}")
        scene = _Scene(body, radar_position)
        fig, cursor = _figure(plt, scene, spec)
        if title:
            fig.suptitle(title)
        if caption:
            fig.text(0.01, 0.01, caption, fontsize=7.5, color="0.25")
            fig.get_layout_engine().set(rect=(0.0, 0.05, 1.0, 0.95))
        scene.update(float(times[0]))
        fig.canvas.draw()  # lay the figure out once; the frames only move artists
        fig.set_layout_engine("none")

        label = f"drawing {Path(path).name}"
        with (
            writer.saving(fig, str(path), dpi=ANIMATION_DPI),
            progress.bar(times.size, label, "frame") as advance,
        ):
            for t in times:
                scene.update(float(t))
                cursor.set_xdata([t, t])
                writer.grab_frame()
                advance(1)
        plt.close(fig)
    return int(times.size)


def _real_time_gif(pillow_writer: Any) -> Any:
    """A subclass of matplotlib's ``PillowWriter`` whose GIF plays in real time: GIF stores
    frame durations in whole centiseconds, so one duration for all frames (``int(1000 / fps)``
    ms, 80 instead of 83.3 at 12 fps) ran the animation up to 6 % fast; each frame here lasts
    until the next one's time, rounded to a centisecond, so frame ``k`` starts within 5 ms of
    ``k / fps``."""

    class RealTimeGif(pillow_writer):  # type: ignore[misc]
        def finish(self) -> None:
            frames = self._frames
            edges = np.round(np.arange(len(frames) + 1) * 100.0 / self.fps)  # [cs]
            durations = [10 * int(d) for d in np.diff(edges)]  # [ms]
            frames[0].save(
                self.outfile,
                save_all=True,
                append_images=frames[1:],
                duration=durations,
                loop=0,
            )

    return RealTimeGif


def plot_stills(
    path: Path,
    body: Skeleton,
    radar_position: FloatArray,
    spec: SpectrogramView,
    instants: Sequence[float] | FloatArray | None = None,
    *,
    title: str = "",
    caption: str = "",
) -> FloatArray:
    """Save the body at ``instants`` [s from the first pulse] (default: five spread over the
    record) in 3-D above the spectrogram, with the instants marked on it. Returns the times of
    the frames shown [s]."""
    at = default_instants(body) if instants is None else check_instants(body, instants)
    frames = frame_at(body.time, at)
    scene = _Scene(body, radar_position)
    with style() as plt:
        n = at.size
        fig = plt.figure(figsize=(max(8.0, 2.6 * n), 7.5), layout="constrained")
        grid = fig.add_gridspec(2, n, height_ratios=(1.2, 1.0))
        for i, k in enumerate(frames):
            ax = fig.add_subplot(grid[0, i], projection="3d")
            scene.draw_body(ax)
            if i:
                ax.get_legend().remove()
            scene.update(float(body.time[k]))
            ax.set_title(f"t = {body.time[k]:.2f} s")
        ax = fig.add_subplot(grid[1, :])
        im = _spectrogram(ax, spec, body)
        for i, k in enumerate(frames):
            _time_mark(ax, float(body.time[k]), lw=1.0)
            ax.annotate(
                f"{i + 1}",
                (float(body.time[k]), 1.0),
                xycoords=("data", "axes fraction"),
                ha="center",
                va="bottom",
            )
        fig.colorbar(im, ax=ax, label="power [dB re peak]")
        if title:
            fig.suptitle(title)
        save(fig, path, caption)
    return np.asarray(body.time[frames], dtype=np.float64)


def _ffmpeg() -> str:
    try:
        import imageio_ffmpeg
    except ImportError:
        raise PreviewError(
            "--format mp4 needs the ffmpeg binary of imageio-ffmpeg: "
            "pip install 'mdframework[video]', or use --format gif"
        ) from None
    return str(imageio_ffmpeg.get_ffmpeg_exe())


def stage_preview(
    result: RunResult,
    resolved_config: Mapping[str, Any],
    stage: Path,
    *,
    fmt: str = "gif",
    fps: int = 12,
    instants: Sequence[float] | None = None,
    progress: Progress = QUIET,
) -> None:
    """Write ``motion.<fmt>`` (:func:`animate`) and ``skeleton.png`` (:func:`plot_stills`) of a
    run into the staging folder ``stage`` (``mdf show`` commits them with the run's files). The
    body is ``result.body`` (times from the first pulse); the figures carry the run's title and
    caption and its ``[figures]`` options. ``progress`` reports the animation's frames and the
    stills."""
    if fmt not in FORMATS:
        raise PreviewError(f"--format: {fmt!r} is not one of {', '.join(FORMATS)}")
    body = result.body
    at = None if instants is None else check_instants(body, instants)
    radar = np.asarray(result.metadata["radar_position_m"], dtype=np.float64)
    look = dict(resolved_config.get("figures", {}))
    spec = SpectrogramView(
        result.spectrogram_db,
        result.spectrogram.time,
        result.velocity,
        dynamic_range_db=float(look.get("dynamic_range_db", DYNAMIC_RANGE_DB)),
        velocity_span=look.get("velocity_span", "auto"),
        colormap=str(look.get("colormap", COLORMAP)),
    )
    gate = (float(result.gate_range[0]), float(result.gate_range[-1]))
    title, caption = run_caption(result.metadata, resolved_config, gate)
    try:
        animate(
            stage / f"motion.{fmt}",
            body,
            radar,
            spec,
            fps=fps,
            title=title,
            caption=caption,
            progress=progress,
        )
        progress.stage("drawing skeleton.png")
        plot_stills(stage / "skeleton.png", body, radar, spec, at, title=title, caption=caption)
    finally:
        progress.end()
