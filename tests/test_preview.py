"""Motion previews show the body's own frames at the right instants, in the right place."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image
from synthetic import standing

from mdframework.figures import style
from mdframework.preview import (
    PreviewError,
    SpectrogramView,
    _figure,
    _Scene,
    animate,
    animation_times,
    check_instants,
    frame_at,
    plot_stills,
)
from mdframework.skeleton import CANONICAL_JOINTS, Skeleton

RADAR = np.array([10.0, 0.0, 2.0])


def walker(frame_rate: float = 30.0, duration: float = 1.0, speed: float = 1.2) -> Skeleton:
    """The standing body moving along +x at ``speed`` [m/s], frames at ``frame_rate``."""
    t = np.arange(0.0, duration + 1e-9, 1.0 / frame_rate)
    pos = standing()[None] + np.array([speed, 0.0, 0.0]) * t[:, None, None]
    return Skeleton(t, pos, CANONICAL_JOINTS)


def spec_for(body: Skeleton) -> SpectrogramView:
    time = np.linspace(body.time[0], body.time[-1], 40)
    velocity = np.linspace(-5.0, 5.0, 101)
    power = np.full((velocity.size, time.size), -60.0)
    power[np.argmin(np.abs(velocity - 1.2))] = 0.0
    return SpectrogramView(power, time, velocity)


def test_frame_at_picks_the_nearest_frame() -> None:
    t = np.array([0.0, 0.1, 0.3, 0.6])
    got = frame_at(t, np.array([-1.0, 0.0, 0.04, 0.05, 0.06, 0.21, 0.59, 9.0]))
    assert got.tolist() == [0, 0, 0, 0, 1, 2, 3, 3]  # tie at 0.05 goes to the earlier frame


def test_animation_frames_run_in_real_time() -> None:
    body = walker(duration=1.0)
    times = animation_times(body, 12)
    assert times.size == 13 and times[-1] == pytest.approx(1.0)
    with pytest.raises(PreviewError, match="--fps"):
        animation_times(body, 0)
    with pytest.raises(PreviewError, match=r"--fps: must be 1 \.\. 100"):
        animation_times(body, 10**6)  # a million frames a second: hours of drawing before


def test_the_scene_shows_the_nearest_frame_and_the_line_of_sight() -> None:
    body = walker(frame_rate=10.0)
    scene = _Scene(body, RADAR)
    with style() as plt:
        fig, _ = _figure(plt, scene, spec_for(body))
        pose = scene.update(0.34)  # frames at 0.3 and 0.4 s: 0.3 is nearer
        assert np.array_equal(pose, body.positions[3])
        neck = CANONICAL_JOINTS.index("neck")
        base = CANONICAL_JOINTS.index("base")
        x, y, z = scene.body_lines[0].get_data_3d()  # segment base -> neck
        assert np.allclose([x, y, z], body.positions[3][[base, neck]].T)
        los_x, los_y = scene.los_top.get_data()
        assert np.allclose(los_x, [RADAR[0], body.positions[3, base, 0]])
        assert np.allclose(los_y, [RADAR[1], body.positions[3, base, 1]])
        # the 3-D view follows the hip centre
        lo, hi = scene.body_ax.get_xlim()
        assert (lo + hi) / 2 == pytest.approx(body.positions[3, base, 0])
        plt.close(fig)


def test_untracked_joints_are_left_out() -> None:
    body = walker()
    valid = np.ones(body.valid.shape, dtype=bool)
    valid[:, CANONICAL_JOINTS.index("head")] = False
    scene = _Scene(Skeleton(body.time, body.positions, body.joint_names, valid), RADAR)
    pose = scene.pose(0)
    assert np.all(np.isnan(pose[CANONICAL_JOINTS.index("head")]))
    assert np.all(np.isfinite(np.delete(pose, CANONICAL_JOINTS.index("head"), axis=0)))


def test_instants_outside_the_record_are_refused() -> None:
    body = walker(duration=1.0)
    assert check_instants(body, [0.0, 0.5, 1.0]).tolist() == [0.0, 0.5, 1.0]
    with pytest.raises(PreviewError, match=r"--at: 1.5 s is outside the record \(0.000 to 1.000"):
        check_instants(body, [0.2, 1.5])
    # one panel per instant, side by side: more than a dozen would make an unreadable image
    assert check_instants(body, np.linspace(0, 1, 12)).size == 12
    with pytest.raises(PreviewError, match=r"^--at: skeleton.png shows at most 12 instants .* 13$"):
        check_instants(body, np.linspace(0, 1, 13))
    # an FMCW record's body starts a few microseconds before its first chirp: 0.000, not -0.000
    early = Skeleton(body.time - 7e-6, body.positions, body.joint_names)
    with pytest.raises(PreviewError, match=r"record \(0\.000 to 1\.000 s\)"):
        check_instants(early, [5.0])


def test_gif_has_one_frame_per_step_at_the_frame_rate(tmp_path: Path) -> None:
    body = walker(duration=0.5)
    n = animate(tmp_path / "m.gif", body, RADAR, spec_for(body), fps=10, title="t", caption="c")
    with Image.open(tmp_path / "m.gif") as gif:
        assert gif.n_frames == n == 6
        assert gif.info["duration"] == 100  # ms per frame at 10 fps (GIF stores centiseconds)


def test_stills_show_the_frames_nearest_the_instants(tmp_path: Path) -> None:
    body = walker(frame_rate=10.0)
    shown = plot_stills(tmp_path / "s.png", body, RADAR, spec_for(body), [0.26, 0.74])
    assert shown.tolist() == pytest.approx([0.3, 0.7])
    assert (tmp_path / "s.png").stat().st_size > 10_000


def test_unknown_format_is_refused(tmp_path: Path) -> None:
    body = walker(duration=0.2)
    with pytest.raises(PreviewError, match="--format"):
        animate(tmp_path / "m.avi", body, RADAR, spec_for(body))
    assert not (tmp_path / "m.avi").exists()


def test_mp4_through_the_shipped_ffmpeg(tmp_path: Path) -> None:
    """imageio-ffmpeg (the ``video`` extra, in ``dev``) ships the encoder; the file it writes is
    read back by the same binary with the frame count and rate asked for."""
    import subprocess

    import imageio_ffmpeg

    body = walker(duration=0.5)
    n = animate(tmp_path / "m.mp4", body, RADAR, spec_for(body), fps=10)
    probe = subprocess.run(
        [imageio_ffmpeg.get_ffmpeg_exe(), "-i", str(tmp_path / "m.mp4")],
        capture_output=True,
        text=True,
        check=False,
    )
    assert "h264" in probe.stderr and "10 fps" in probe.stderr
    frames, _ = imageio_ffmpeg.count_frames_and_secs(str(tmp_path / "m.mp4"))
    assert frames == n == 6


def test_mdf_show_writes_the_run_and_its_preview(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`mdf show` on a 1 s CMU walk: the run's files plus an animation whose frames step through
    the record at --fps, and stills at the asked instants; the joints are in result.npz."""
    import json
    import tomllib

    from conftest import EXAMPLES

    from mdframework import cli

    data = tomllib.loads((EXAMPLES / "cmu_walk.toml").read_text())
    data["motion"]["file"] = str(EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc")
    data["motion"]["duration"] = 1.0
    config = tmp_path / "walk.json"
    config.write_text(json.dumps(data))
    out = tmp_path / "out"
    code = cli.main(["show", str(config), "--out", str(out), "--fps", "5", "--at", "0.2", "0.8"])
    assert code == 0, capsys.readouterr().err
    names = {p.name for p in out.iterdir()}
    assert {"motion.gif", "skeleton.png", "spectrogram.png", "result.npz"} <= names
    with Image.open(out / "motion.gif") as gif:
        assert gif.n_frames == 6 and gif.info["duration"] == 200  # 0..1 s at 5 fps
    with np.load(out / "result.npz") as d:
        t, joints = d["body_time_s"], d["body_positions_m"]
        assert t[0] >= 0.0 and t[-1] <= 1.0 + 1e-9
        assert joints.shape == (t.size, len(CANONICAL_JOINTS), 3)
        # the placed walker starts at the origin (hip centre) and walks toward the radar at +x
        base = joints[:, CANONICAL_JOINTS.index("base")]
        assert np.hypot(*base[0, :2]) < 0.05 and base[-1, 0] > base[0, 0] + 0.5


def test_mdf_show_refuses_an_instant_outside_the_record(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from conftest import EXAMPLES

    from mdframework import cli

    out = tmp_path / "out"
    code = cli.main(["show", str(EXAMPLES / "point_target.toml"), "--out", str(out), "--at", "7"])
    err = capsys.readouterr().err
    assert code == 2 and "--at: 7 s is outside the record" in err
    assert not out.exists()


def test_left_and_right_limbs_are_drawn_in_their_own_colours() -> None:
    """Every segment ending on an ``l_`` joint has one colour, every ``r_`` one another, the
    trunk and head a third, in the top view and in the 3-D view, and the 3-D legend names
    both sides: a mirrored body must look mirrored."""
    from matplotlib.colors import to_hex

    from mdframework.skeleton import CANONICAL_SEGMENTS

    body = walker()
    scene = _Scene(body, RADAR)
    with style() as plt:
        fig, _ = _figure(plt, scene, spec_for(body))
        for lines in (scene.top_lines, scene.body_lines):
            colour: dict[str, set[str]] = {"l_": set(), "r_": set(), "": set()}
            for line, (_, distal) in zip(lines, CANONICAL_SEGMENTS, strict=True):
                side = distal[:2] if distal[:2] in ("l_", "r_") else ""
                colour[side].add(to_hex(line.get_color()))
            assert all(len(c) == 1 for c in colour.values()), colour
            assert len(set.union(*colour.values())) == 3, colour
        names = [t.get_text() for t in scene.body_ax.get_legend().get_texts()]
        assert "left" in names and "right" in names
        plt.close(fig)


def test_the_spectrogram_axis_spans_the_whole_record(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """STFT frames are centred from half a window after the record's start: the spectrogram's
    time axis still runs from the record's first to its last instant, so the animation's cursor
    and the stills' instants near the ends stay on it (the cursor left the axes for the first
    and last half window; stills at the ends widened the axis by matplotlib's margins)."""
    from mdframework import preview

    body = walker(frame_rate=10.0)  # 0 .. 1 s
    time = np.linspace(0.1, 0.9, 17)  # frames 0.05 s apart: cells 0.075 .. 0.925 s
    velocity = np.linspace(-5.0, 5.0, 101)
    spec = SpectrogramView(np.zeros((velocity.size, time.size)), time, velocity)
    with style() as plt:
        fig, cursor = _figure(plt, _Scene(body, RADAR), spec)
        assert cursor.axes.get_xlim() == pytest.approx((0.0, 1.0))
        plt.close(fig)
    saved: list[Any] = []
    monkeypatch.setattr(preview, "save", lambda fig, path, caption="", **kw: saved.append(fig))
    plot_stills(tmp_path / "s.png", body, RADAR, spec, [0.0, 1.0])
    (ax,) = [a for a in saved[0].axes if a.get_xlabel() == "time [s]"]
    assert ax.get_xlim() == pytest.approx((0.0, 1.0))


def test_the_body_views_axis_names_stay_out_of_the_spectrogram() -> None:
    """The 3-D view has no tick labels; its axis names sit against its box, so its "z" does not
    land on the spectrogram's velocity label beside it (as it did in every animation frame)."""
    body = walker()
    scene = _Scene(body, RADAR)
    with style() as plt:
        fig, cursor = _figure(plt, scene, spec_for(body))
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        z_name = scene.body_ax.zaxis.label.get_window_extent(renderer)
        velocity_name = cursor.axes.yaxis.label.get_window_extent(renderer)
        assert z_name.x1 < velocity_name.x0, (z_name, velocity_name)
        plt.close(fig)


@pytest.mark.parametrize("fps", [12, 7])
def test_gif_frames_start_at_their_own_times(tmp_path: Path, fps: int) -> None:
    """GIF durations are whole centiseconds: frame k starts within 5 ms of k / fps, so the
    animation plays in real time (at the default 12 fps every frame lasted 80 ms instead of
    83.3, and the walk ran 4 % fast)."""
    body = walker(duration=1.0)
    n = animate(tmp_path / "m.gif", body, RADAR, spec_for(body), fps=fps)
    durations = []
    with Image.open(tmp_path / "m.gif") as gif:
        for k in range(gif.n_frames):
            gif.seek(k)
            durations.append(gif.info["duration"])
    assert len(durations) == n
    starts = np.concatenate([[0.0], np.cumsum(durations)])  # [ms]
    assert np.max(np.abs(starts - 1000.0 * np.arange(n + 1) / fps)) <= 5.0


def test_mdf_show_refuses_a_gif_too_fast_to_play_in_real_time(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A GIF's frame times are hundredths of a second: above 50 fps frames of 10 ms appear,
    which viewers slow down, so the docs' 'played in real time' would not hold."""
    from conftest import EXAMPLES

    from mdframework import cli

    out = tmp_path / "out"
    args = ["show", str(EXAMPLES / "point_target.toml"), "--out", str(out), "--fps", "60"]
    code = cli.main(args)
    err = capsys.readouterr().err
    assert code == 2 and "--fps: a GIF plays at most 50 frames per second" in err
    assert err.count("\n") == 1 and not out.exists()


def test_figures_page_quotes_the_limits_of_mdf_show() -> None:
    """docs/figures.md's limits on ``--fps`` (GIF) and ``--at`` are the code's."""
    from conftest import ROOT

    from mdframework.preview import GIF_MAX_FPS, MAX_INSTANTS

    page = (ROOT / "docs" / "figures.md").read_text()
    assert f"a GIF takes `--fps` up to {GIF_MAX_FPS}:" in page
    assert f"`--at` takes at most {MAX_INSTANTS} instants" in page
