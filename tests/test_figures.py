"""Figures say what they show: the velocity span follows the power, captions name the run."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES
from helpers import point_run

from mdframework.config import load_run_config, validate_run_config
from mdframework.errors import ConfigError
from mdframework.figures import draw_spectrogram, run_caption, style, velocity_limits
from mdframework.output import write_run
from mdframework.pipeline import simulate


def _tone_spectrogram(v0: float, floor_db: float = -60.0) -> tuple[np.ndarray, np.ndarray]:
    """A spectrogram (at the floor everywhere) with one bin at velocity ``v0`` at 0 dB."""
    velocity = np.linspace(-6.0, 6.0, 481)  # 0.025 m/s bins
    spec = np.full((velocity.size, 20), floor_db)
    spec[np.argmin(np.abs(velocity - v0)), :] = 0.0
    return spec, velocity


def test_auto_span_covers_the_power_and_zero() -> None:
    spec, velocity = _tone_spectrogram(2.0)
    lo, hi = velocity_limits(spec, velocity, "auto", 40.0)
    dv = velocity[1] - velocity[0]
    # extent 0..2 m/s widened by a tenth (0.2) plus two bins each side
    assert lo == pytest.approx(-0.2 - 2 * dv)
    assert hi == pytest.approx(2.0 + 0.2 + 2 * dv)


def test_auto_span_counts_only_power_within_the_dynamic_range() -> None:
    spec, velocity = _tone_spectrogram(-1.0)
    spec[np.argmin(np.abs(velocity - 4.0)), :] = -45.0  # below a 40 dB display, above 50 dB
    assert velocity_limits(spec, velocity, "auto", 40.0)[1] < 0.5
    assert velocity_limits(spec, velocity, "auto", 50.0)[1] > 4.0


def test_noise_everywhere_gives_the_full_axis(rng: np.random.Generator) -> None:
    velocity = np.linspace(-6.0, 6.0, 481)
    spec = rng.uniform(-10.0, 0.0, (velocity.size, 30))
    dv = velocity[1] - velocity[0]
    full = (velocity[0] - dv / 2, velocity[-1] + dv / 2)
    assert velocity_limits(spec, velocity, "auto", 40.0) == pytest.approx(full)
    assert velocity_limits(spec, velocity, "full") == pytest.approx(full)
    assert velocity_limits(spec, velocity, 2.5) == pytest.approx((-2.5, 2.5))
    assert velocity_limits(spec, velocity, 100.0) == pytest.approx(full)


def test_auto_span_of_a_receding_point_target() -> None:
    """A point receding at 1 m/s (15 GHz, PRF 2400 Hz: +-12 m/s unambiguous) is shown on an axis
    a tenth of the unambiguous span, not the whole of it."""
    res = point_run([{"position": [100.0, 0.0, 0.0], "velocity": [1.0, 0.0, 0.0]}])
    lo, hi = velocity_limits(res.spectrogram_db, res.velocity, "auto", 40.0)
    assert -1.6 < lo < -1.0 and 0.0 < hi < 0.5
    with style() as plt:
        fig, ax = plt.subplots()
        draw_spectrogram(ax, res.spectrogram_db, res.spectrogram.time, res.velocity)
        assert ax.get_ylim() == pytest.approx((lo, hi))
        plt.close(fig)


def test_spectrogram_cells_are_centred_on_their_times_and_velocities() -> None:
    """The image's cells are centred on the frame times and the velocity bins: the extent runs
    half a hop before the first frame's time to half a hop after the last, half a bin below
    the first velocity to half a bin above the last. A record of one frame (a single FMCW
    frame, stamped 1.5 ms in) spans its window, 0 to 3 ms; it was drawn one second wide, from
    -0.5 s."""
    velocity = np.linspace(-2.0, 2.0, 9)
    time = 0.05 + np.arange(4) * 0.02
    with style() as plt:
        fig, ax = plt.subplots()
        image = draw_spectrogram(ax, np.zeros((9, 4)), time, velocity, velocity_span="full")
        assert image.get_extent() == pytest.approx([0.04, 0.12, -2.25, 2.25])
        assert ax.get_xlim() == pytest.approx((0.04, 0.12))
        ax.clear()
        image = draw_spectrogram(ax, np.zeros((9, 1)), np.array([1.5e-3]), velocity)
        assert image.get_extent()[:2] == pytest.approx([0.0, 3e-3])
        assert ax.get_xlim() == pytest.approx((0.0, 3e-3))
        plt.close(fig)


def test_caption_names_source_radar_geometry_and_effects(tmp_path: Path) -> None:
    config = load_run_config(EXAMPLES / "cmu_walk.toml")
    data = json.loads(config.model_dump_json())
    data["effects"] = [{"kind": "noise", "snr_db": 20.0}]
    data["radar"]["prf"] = 3000.0
    data["motion"]["duration"] = 1.0
    data["scene"]["person"]["aspect_deg"] = 30.0
    data["figures"] = {"velocity_span": "full", "colormap": "magma"}
    config = validate_run_config(data)
    result = simulate(config)
    resolved = json.loads(config.model_dump_json())
    title, caption = run_caption(result.metadata, resolved, (10.05, 8.1))
    assert title == "walk — cmu 02_01.amc subject 2"
    for part in ("lfm 15 GHz", "PRF 3000 Hz", "aspect 30°", "range 10.1 → 8.1 m", "noise"):
        assert part in caption, (part, caption)
    written = write_run(result, resolved, tmp_path / "run")
    assert tmp_path / "run" / "spectrogram.png" in written


def test_a_radar_without_a_prf_gives_its_slow_time_rate() -> None:
    """A CW radar's caption gives its I/Q rate as the slow-time rate, not as a PRF (it has no
    pulses); an LFM radar's gives its PRF."""
    meta = {"carrier_frequency_hz": 24e9, "prf_hz": 2000.0}
    caption = run_caption(meta, {"radar": {"kind": "cw", "sample_rate": 2000.0}})[1]
    assert caption.startswith("cw 24 GHz, slow time 2000 Hz;") and "PRF" not in caption
    caption = run_caption(meta, {"radar": {"kind": "lfm", "prf": 2000.0}})[1]
    assert caption.startswith("lfm 24 GHz, PRF 2000 Hz;")


def test_a_source_named_as_its_activity_is_named_once() -> None:
    """Point targets name their activity after their source: the title says it once."""
    meta = {"motion": {"source": "point_targets", "activity": "point_targets"}}
    assert run_caption(meta, {})[0] == "point_targets"
    meta = {"motion": {"source": "cmu", "activity": "walk", "file": "02_01.amc"}}
    assert run_caption(meta, {})[0] == "walk — cmu 02_01.amc"


def test_unknown_colormap_is_a_config_error() -> None:
    data = {"motion": {"kind": "point_targets", "length": 1.0, "targets": []}}
    with pytest.raises(ConfigError, match=r"figures\.colormap: .*unknown colour map 'jett'"):
        validate_run_config({**data, "figures": {"colormap": "jett"}})
    with pytest.raises(ConfigError, match=r"figures\.dynamic_range_db"):
        validate_run_config({**data, "figures": {"dynamic_range_db": 0}})


def test_every_allowed_matplotlib_draws_the_colour_maps_a_config_accepts() -> None:
    """The list of colour maps is matplotlib 3.11's; pyproject.toml allowed 3.8, which lacks
    some of them (berlin, vanimo, grey_r ...): a config accepted them and the figure failed.
    The lowest matplotlib allowed is the one the list comes from."""
    import tomllib

    from conftest import ROOT

    from mdframework.settings import COLORMAPS_MATPLOTLIB

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    wanted = [d for d in project["dependencies"] if d.startswith("matplotlib")]
    assert wanted == [f"matplotlib>={COLORMAPS_MATPLOTLIB}"]


def test_the_colour_maps_a_config_accepts_are_matplotlibs() -> None:
    """The names figures.colormap accepts without importing matplotlib are exactly the
    installed matplotlib's colour maps, each also reversed."""
    from matplotlib import colormaps

    from mdframework.settings import COLORMAPS

    assert {*COLORMAPS, *(f"{name}_r" for name in COLORMAPS)} == set(colormaps)
    target = {"position": [10.0, 0.0, 0.0], "velocity": [1.0, 0.0, 0.0]}
    data = {"motion": {"kind": "point_targets", "length": 1.0, "targets": [target]}}
    for name in ("magma_r", "tab20c", "Greys"):
        assert validate_run_config({**data, "figures": {"colormap": name}}).figures.colormap == name
    with pytest.raises(ConfigError, match="unknown colour map 'magma_r_r'"):
        validate_run_config({**data, "figures": {"colormap": "magma_r_r"}})


def test_reading_a_config_without_figures_does_not_import_matplotlib(tmp_path: Path) -> None:
    """A config that names a colour map but draws no figures is read (and its colour map
    checked) without importing matplotlib; it used to be imported to check the name."""
    import subprocess
    import sys

    config = tmp_path / "arrays.toml"
    text = (EXAMPLES / "point_target.toml").read_text()
    config.write_text(text + '\n[figures]\nenabled = false\ncolormap = "magma"\n')
    probe = (
        "import sys; from mdframework.config import load_run_config; "
        f"c = load_run_config({str(config)!r}); "
        "print(c.figures.colormap, 'matplotlib' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["magma", "False"], out.stderr


def test_auto_span_of_the_cmu_walk() -> None:
    """docs/figures.md: a walker toward a 15 GHz radar at PRF 2400 Hz uses about -1.5..5 m/s of
    the unambiguous -12..12 m/s, and the auto axis shows just that."""
    result = simulate(load_run_config(EXAMPLES / "cmu_walk.toml"))
    lo, hi = velocity_limits(result.spectrogram_db, result.velocity, "auto", 40.0)
    assert result.metadata["max_unambiguous_velocity_mps"] == pytest.approx(12.0, abs=0.05)
    assert -2.0 < lo < -1.0 and 4.5 < hi < 5.5


def test_a_long_caption_is_wrapped_inside_the_figure(tmp_path: Path) -> None:
    """A caption longer than the figure is wide (an experiment's: dataset, classifier,
    protocol) is wrapped at spaces, and every line lies inside the saved figure."""
    from mdframework.figures import save, subplots

    caption = (
        'dataset cross_source.toml (162 records); classifier {"kind": "knn", "k": 5}; '
        "selection wrapper; mean ± std over 5 leave-subjects-out folds"
    )
    with style():
        fig, ax = subplots(figsize=(4.5, 3.0))
        ax.imshow(np.eye(3))
        save(fig, tmp_path / "c.png", caption, title="cmu: within-source")
    text = fig.texts[-1]
    assert text.get_text().count("\n") >= 1
    assert text.get_text().replace("\n", " ") == caption
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    box = text.get_window_extent(renderer)
    assert 0 <= box.x0 and box.x1 <= fig.bbox.x1 and box.y0 >= 0


def test_radar_products_carry_the_caption_and_the_figure_options(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """range_doppler.png and point_cloud.png are captioned like the run's other figures, and
    the range-Doppler map is drawn in the ``[figures]`` colour map and dynamic range."""
    from mdframework import output
    from mdframework.progress import QUIET

    calls: dict[str, dict[str, object]] = {}

    def record(name: str) -> object:
        return lambda path, *args, **kwargs: calls.__setitem__(name, kwargs)

    for name in ("plot_spectrogram", "plot_range_doppler", "plot_point_cloud"):
        monkeypatch.setattr(output, name, record(name))
    maps = np.ones((3, 4, 5))
    maps[1, 2, 3] = 100.0  # the strongest map, and the frame of the points
    arrays = {
        "spectrogram_db": np.zeros((4, 3)),
        "time_s": np.arange(3.0),
        "velocity_mps": np.linspace(-1.0, 1.0, 4),
        "doppler_hz": np.linspace(-10.0, 10.0, 4),
        "range_doppler": maps,
        "range_doppler_range_m": np.arange(5.0),
        "range_doppler_velocity_mps": np.linspace(-1.0, 1.0, 4),
        "points": np.array([[1.0, 0.1, 0.0, 3.0, 0.0, 1.0, 20.0]]),
    }
    look = {"dynamic_range_db": 25.0, "velocity_span": "full", "colormap": "magma"}
    output._plot_run(tmp_path, arrays, "walk — cmu", "fmcw 77 GHz; aspect 0°", look, QUIET)
    rd, cloud = calls["plot_range_doppler"], calls["plot_point_cloud"]
    assert rd["caption"] == cloud["caption"] == "fmcw 77 GHz; aspect 0°"
    assert rd["title"] == cloud["title"] == "walk — cmu frame 1"
    assert rd["colormap"] == "magma" and rd["dynamic_range_db"] == 25.0


def test_coinciding_records_of_two_activities_both_stay_visible(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Quantised features (coarse Doppler bins) put many records on one point: each activity's
    records there are one mark of area proportional to their number, the larger drawn behind,
    so the activity with more records there is not hidden under the other's (RadHAR's jump
    records all lay under walk records)."""
    from mdframework import figures

    drawn: list[object] = []
    monkeypatch.setattr(figures, "save", lambda fig, path, caption="", **kw: drawn.append(fig))
    x = np.array([0.0] * 5 + [0.0] * 2 + [1.0])
    y = np.array([0.6] * 5 + [0.6] * 2 + [2.0])
    labels = np.array(["jump"] * 5 + ["walk"] * 3)
    groups = np.array(["radhar"] * 8)
    figures.plot_feature_scatter(tmp_path / "s.png", x, y, labels, groups, "a", "b")
    (fig,) = drawn
    marks = []  # (x, y, area, zorder) of every mark
    for coll in fig.axes[0].collections:
        for (px, py), area in zip(
            coll.get_offsets(),
            np.broadcast_to(coll.get_sizes(), len(coll.get_offsets())),
            strict=True,
        ):
            marks.append((float(px), float(py), float(area), coll.get_zorder()))
    at = sorted((m for m in marks if (m[0], m[1]) == (0.0, 0.6)), key=lambda m: m[3])
    assert [m[2] for m in at] == [70.0, 28.0]  # jump's 5 records behind walk's 2
    assert sorted(m[2] for m in marks if m[0] == 1.0) == [14.0]
    names = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert names == ["jump (radhar)", "walk (radhar)"]


def test_side_by_side_panels_share_a_velocity_axis_that_holds_both(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A run at 5 m/s beside a walk at 1 m/s: the shared axis covers both panels' power (the
    last panel's own span used to set it for both, cutting the first panel's)."""
    from mdframework import figures

    saved: list[object] = []
    monkeypatch.setattr(figures, "save", lambda fig, path, caption="", **kw: saved.append(fig))
    fast, velocity = _tone_spectrogram(5.0)
    slow, _ = _tone_spectrogram(1.0)
    time = np.arange(fast.shape[1]) * 0.01
    figures.plot_spectrogram_panels(
        tmp_path / "p.png", [(fast, time, velocity, "run"), (slow, time, velocity, "walk")]
    )
    (fig,) = saved
    lo, hi = velocity_limits(fast, velocity, "auto", 40.0)
    for ax in fig.axes[:2]:
        assert ax.get_ylim() == pytest.approx((lo, hi))  # the run's span holds the walk's


def test_a_long_spectrogram_is_drawn_pooled_keeping_a_one_frame_flash(tmp_path: Path) -> None:
    """A 300 s record's spectrogram (1024 x 22,500 frames): drawn whole it took 1.5 GiB and
    14 s; max-pooled to the figure's cells it takes less than twice the map itself, and a flash
    of one frame and one bin, 30 dB over the rest, still shows at its time and velocity."""
    import tracemalloc

    from mdframework.figures import plot_spectrogram

    n_doppler, n_frames = 1024, 22500
    velocity = np.linspace(-12.0, 12.0, n_doppler)
    time = np.arange(n_frames) * 0.01333
    db = np.full((n_doppler, n_frames), -40.0, dtype=np.float32)
    db[700, 15000] = 0.0
    db[:, 15001:15010] = -30.0
    tracemalloc.start()
    try:
        plot_spectrogram(tmp_path / "s.png", db, time, velocity, velocity * 100.0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2 * db.nbytes
    from mdframework.figures import MAX_IMAGE_CELLS

    with style():
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots()
        im = draw_spectrogram(ax, db, time, velocity, velocity_span="full")
        drawn = np.asarray(im.get_array())
        plt.close(fig)
    assert drawn.shape == (n_doppler, -(-n_frames // 22))
    assert max(drawn.shape) <= MAX_IMAGE_CELLS
    row, col = np.unravel_index(np.argmax(drawn), drawn.shape)
    assert drawn[row, col] == 0.0 and row == 700 and col == 15000 // 22


def test_the_page_quotes_the_pooled_width_and_the_record_it_starts_at() -> None:
    """docs/figures.md: a map of more than 1024 columns (a spectrogram of a record longer than
    about 14 s at the default hop) is drawn pooled, and the 300 s map of the test above
    (1024 x 22,500 cells) is the one the page quotes."""
    import re

    from mdframework.figures import MAX_IMAGE_CELLS
    from mdframework.settings import ProcessingConfig

    page = " ".join((EXAMPLES.parent / "docs" / "figures.md").read_text().split())
    quoted = re.search(
        r"more than (\d+) columns \(a spectrogram of a record longer than about (\d+) s", page
    )
    assert quoted is not None
    assert int(quoted.group(1)) == MAX_IMAGE_CELLS
    processing = ProcessingConfig()
    longest = (MAX_IMAGE_CELLS * processing.hop + processing.window_length) / 2400.0  # lfm PRF
    assert round(longest) == int(quoted.group(2))
    assert "the spectrogram of a 300 s record (1024 x 22,500 cells) allocates less than twice" in (
        page
    )
    assert round(300.0 * 2400.0 / processing.hop, -2) == 22500  # frames of a 300 s record
