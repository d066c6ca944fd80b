"""Motion augmentation (mdframework.augment) and per-record random draws (randomize)."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import ValidationError
from synthetic import standing

from mdframework import CANONICAL_JOINTS, Motion, Skeleton
from mdframework.augment import (
    augment_motion,
    mirror_motion,
    scale_height,
    scale_speed,
    time_warp,
    warp_function,
)
from mdframework.randomize import Distribution, Randomization, set_path


def walker(n: int = 61, speed: float = 1.3) -> Skeleton:
    """The standing body translated along +x at ``speed`` m/s, 30 frames/s."""
    t = 2.0 + np.arange(n) / 30.0
    pos = standing()[None, :, :] + (speed * (t - t[0]))[:, None, None] * np.array([1.0, 0, 0])
    return Skeleton(t, pos, CANONICAL_JOINTS)


def velocity(s: Skeleton, joint: str = "base") -> np.ndarray:
    track = s.joint(joint)
    return np.asarray(np.diff(track, axis=0) / np.diff(s.time)[:, None])


def test_speed_scaling_multiplies_every_velocity() -> None:
    s = walker()
    fast = scale_speed(s, 1.5)
    np.testing.assert_allclose(velocity(fast), 1.5 * velocity(s), rtol=1e-12)
    assert fast.time[0] == s.time[0]
    assert fast.duration == pytest.approx(s.duration / 1.5)
    np.testing.assert_array_equal(fast.positions, s.positions)
    with pytest.raises(ValueError, match="positive"):
        scale_speed(s, 0.0)


def test_height_scaling_is_a_similarity_about_the_floor() -> None:
    s = walker()
    tall = scale_height(s, 1.1)
    seg = lambda k, a, b: np.linalg.norm(k.joint(a) - k.joint(b), axis=1)  # noqa: E731
    np.testing.assert_allclose(seg(tall, "neck", "head"), 1.1 * seg(s, "neck", "head"))
    np.testing.assert_allclose(tall.joint("head")[:, 2], 1.1 * s.joint("head")[:, 2])
    assert tall.positions[..., 2].min() == pytest.approx(0.0, abs=1e-12)  # feet stay down
    np.testing.assert_allclose(velocity(tall), 1.1 * velocity(s), rtol=1e-12)


def test_mirror_swaps_sides_and_is_an_involution() -> None:
    s = walker()
    motion = Motion(s, {"source": "test"}, {j: j for j in CANONICAL_JOINTS})
    m = mirror_motion(motion)
    np.testing.assert_array_equal(m.skeleton.positions[..., 1], -s.positions[..., 1])
    body = m.canonical()
    # the joint now called the left hand is the old right hand, mirrored onto the left (+y)
    np.testing.assert_allclose(body.joint("l_hand")[:, 1], -s.joint("r_hand")[:, 1])
    assert np.all(body.joint("l_hand")[:, 1] > 0)
    twice = mirror_motion(m)
    np.testing.assert_array_equal(twice.skeleton.positions, s.positions)
    assert dict(twice.canonical_map or {}) == {j: j for j in CANONICAL_JOINTS}


def test_time_warp_keeps_ends_and_order() -> None:
    u = np.linspace(0.0, 1.0, 1001)
    c = np.array([0.4, -0.3, 0.2])
    g = warp_function(u, c)
    assert g[0] == 0.0 and g[-1] == pytest.approx(1.0, abs=1e-15)
    assert np.all(np.diff(g) > 0)
    # g' = 1 + sum c_k cos(pi k u): compare with the finite difference
    gprime = 1 + sum(ck * np.cos(np.pi * (k + 1) * u) for k, ck in enumerate(c))
    np.testing.assert_allclose(np.gradient(g, u)[1:-1], gprime[1:-1], atol=2e-4)
    s = walker()
    w = time_warp(s, c)
    assert w.time[0] == s.time[0] and w.time[-1] == pytest.approx(s.time[-1])
    np.testing.assert_array_equal(w.positions, s.positions)
    with pytest.raises(ValueError, match="sum"):
        warp_function(u, np.array([0.6, 0.5]))


def test_augment_motion_order_and_identity() -> None:
    s = walker()
    motion = Motion(s, {}, {j: j for j in CANONICAL_JOINTS})
    same = augment_motion(motion)
    np.testing.assert_array_equal(same.skeleton.positions, s.positions)
    both = augment_motion(motion, speed=2.0, height=0.9)
    np.testing.assert_allclose(velocity(both.skeleton), 1.8 * velocity(s), rtol=1e-12)


def test_distributions_draw_within_their_support(rng: np.random.Generator) -> None:
    uni = Distribution(uniform=(0.8, 1.6))
    draws = np.array([uni.draw(rng) for _ in range(2000)])
    assert draws.min() >= 0.8 and draws.max() <= 1.6
    assert draws.mean() == pytest.approx(1.2, abs=0.02)
    logu = Distribution(loguniform=(0.5, 2.0))
    logs = np.log([logu.draw(rng) for _ in range(4000)])
    assert np.mean(logs) == pytest.approx(0.0, abs=0.03)  # symmetric in log about 1
    norm = Distribution(normal=(3.0, 0.5))
    assert np.std([norm.draw(rng) for _ in range(4000)]) == pytest.approx(0.5, rel=0.05)
    ch = Distribution(choice=["a", "b"])
    assert {ch.draw(rng) for _ in range(50)} == {"a", "b"}
    with pytest.raises(ValidationError, match="exactly one"):
        Distribution(uniform=(0, 1), normal=(0, 1))
    with pytest.raises(ValidationError, match="low"):
        Distribution(uniform=(2, 1))


def test_randomization_sample_is_seeded_and_complete() -> None:
    rz = Randomization.model_validate(
        {
            "radar_height": {"uniform": [0.8, 1.6]},
            "params": {"effects.0.snr_db": {"choice": [10, 20]}},
            "speed": {"uniform": [0.8, 1.2]},
            "mirror": 0.5,
            "time_warp": 0.6,
        }
    )
    a = rz.sample(np.random.default_rng(3))
    b = rz.sample(np.random.default_rng(3))
    assert a == b
    assert set(a) == {"radar_height", "effects.0.snr_db", "speed", "mirror", "time_warp"}
    assert sum(abs(c) for c in a["time_warp"]) < 0.6 + 1e-12


def test_set_path_tables_and_lists() -> None:
    cfg: dict = {"effects": [{"kind": "noise", "snr_db": 20}], "radar": {"kind": "lfm"}}
    set_path(cfg, "effects.0.snr_db", 5.0)
    set_path(cfg, "radar.carrier_frequency", 77e9)
    set_path(cfg, "scene.person.aspect_deg", 30.0)
    assert cfg["effects"][0]["snr_db"] == 5.0 and cfg["radar"]["carrier_frequency"] == 77e9
    assert cfg["scene"] == {"person": {"aspect_deg": 30.0}}
    with pytest.raises(KeyError, match=r"effects\.1: no item 1"):
        set_path(cfg, "effects.1.snr_db", 1.0)


def test_the_documented_randomize_section_is_valid() -> None:
    import re
    import tomllib

    from conftest import ROOT

    text = (ROOT / "docs" / "datasets.md").read_text()
    block = next(b for b in re.findall(r"```toml\n(.*?)```", text, re.S) if "[randomize]" in b)
    rz = Randomization.model_validate(tomllib.loads(block)["randomize"])
    draws = rz.sample(np.random.default_rng(0))
    assert {"radar_height", "speed", "effects.0.snr_db", "time_warp"} <= set(draws)


def test_augmentation_factors_stay_within_their_ranges() -> None:
    """A speed factor lies in 0.1 .. 10 and a body factor in 0.5 .. 2: a distribution reaching
    beyond (a normal one counted to 4 standard deviations) is refused naming the field; the rare
    normal draw beyond 4 standard deviations is clipped, so no record gets an absurd factor."""
    from mdframework.randomize import FACTOR_RANGES

    assert FACTOR_RANGES == {"speed": (0.1, 10.0), "body_scale": (0.5, 2.0)}
    for bad, words in (
        ({"speed": {"loguniform": [1e-12, 1e-11]}}, "speed: draws 1e-12 .. 1e-11"),
        ({"speed": {"normal": [1.0, 0.5]}}, "speed: draws -1 .. 3"),
        ({"body_scale": {"uniform": [-2.0, -1.0]}}, "outside the factor's range 0.5 .. 2"),
        ({"speed": {"choice": ["fast"]}}, "speed: the choices must be numbers"),
        ({"speed": {"loguniform": [0.05, 1.3]}}, "speed: draws 0.05 .. 1.3"),  # docs/datasets.md
    ):
        with pytest.raises(ValidationError, match=words):
            Randomization.model_validate(bad)
    ok = Randomization.model_validate(
        {"speed": {"normal": [1.0, 0.2]}, "body_scale": {"choice": [0.5, 2.0]}}
    )
    rng = np.random.default_rng(0)
    speeds = [ok.sample(rng)["speed"] for _ in range(20_000)]
    assert 0.1 <= min(speeds) and max(speeds) <= 10.0
    assert np.std(speeds) == pytest.approx(0.2, rel=0.03)
    from conftest import ROOT

    page = " ".join((ROOT / "docs" / "datasets.md").read_text().split())
    assert "`speed` 0.1 .. 10 and `body_scale` 0.5 .. 2" in page
    assert "randomize.speed: draws 0.05 .. 1.3 (...), outside the factor's range 0.1 .. 10" in page


# A drawn value that its field refuses is blamed on the [randomize] entry that drew it


def _first_draws(randomize: dict, seed: int = 7) -> dict:
    """Record 0's draws in :func:`_plan`, as the planner makes them: seeded by what the record
    is (its motion's contents, the first of that motion, window start 0, no variations, draw
    0)."""
    from conftest import EXAMPLES

    from mdframework.dataset import _load_motion, _motion_key, _record_key
    from mdframework.fingerprint import motion_fingerprint

    motion = {"kind": "cmu", "file": str(EXAMPLES / "data" / "cmu" / "bvh" / "16_21.bvh")}
    content = motion_fingerprint(_load_motion(_motion_key(motion), str(EXAMPLES)))
    key = _record_key(seed, [content, 0, 0.0, [None] * 5, 0])
    rz = Randomization.model_validate(randomize)
    return rz.sample(np.random.default_rng(np.random.SeedSequence([*key, 1])))


def _plan(tmp_path, source_extra: dict, randomize: dict, **top: object) -> None:
    import json

    from conftest import EXAMPLES

    from mdframework.dataset import load_dataset_config, plan_records

    bvh = EXAMPLES / "data" / "cmu" / "bvh" / "16_21.bvh"
    source = {"label": "walk", "motion": {"kind": "cmu", "file": str(bvh)}}
    source.update(record_length=1.0, max_records=1, **source_extra)
    cfg = {"seed": 7, "sources": [source], "randomize": randomize, **top}
    path = tmp_path / "ds.json"
    path.write_text(json.dumps(cfg))
    plan_records(*load_dataset_config(path))


def test_a_drawn_height_on_a_source_without_height_names_the_randomize_entry(tmp_path) -> None:
    """A CMU trial has no `height` (its body is the recorded one): the error used to name
    `motion.height` only; it names `randomize.height`, the value drawn and the record."""
    from mdframework.errors import ConfigError

    randomize = {"height": {"uniform": [1.5, 1.9]}}
    value = _first_draws(randomize)["height"]
    with pytest.raises(ConfigError) as err:
        _plan(tmp_path, {}, randomize)
    msg = str(err.value)
    assert msg.startswith(
        f"sources[0] record 0: randomize.height drew {value:.6g} for motion.height"
    )
    assert "unknown field 'height'" in msg and "remove the draw" in msg
    # the page's example is this message (seed 7)
    from conftest import ROOT

    page = " ".join((ROOT / "docs" / "datasets.md").read_text().split())
    quoted = page.split("then the field's rule: `")[1].split(" (...)`")[0]
    assert msg.startswith(quoted)


def test_a_draw_beyond_its_fields_range_names_the_randomize_entry_and_its_section(
    tmp_path,
) -> None:
    """The source's own [randomize] or the dataset's, and a `params` path, each named as
    written; the field's own rule follows."""
    from mdframework.errors import ConfigError

    own = {"radar_height": {"uniform": [2e4, 3e4]}}
    dataset_wide = {"aspect_deg": {"uniform": [0.0, 10.0]}}
    value = _first_draws({**dataset_wide, **own})["radar_height"]
    with pytest.raises(ConfigError) as err:
        _plan(tmp_path, {"randomize": own}, dataset_wide)
    assert str(err.value).startswith(
        f"sources[0] record 0: sources[0].randomize.radar_height drew {value:.6g} for "
        "scene.radar_position.2: must be at most 10000"
    )
    params = {"params": {"radar.prf": {"uniform": [2e7, 3e7]}}}
    value = _first_draws(params)["radar.prf"]
    with pytest.raises(ConfigError, match=r"^sources\[0\] record 0: randomize\.params\.") as err:
        _plan(tmp_path, {}, params)
    assert f'randomize.params."radar.prf" drew {value:.6g} for radar.prf: must be at most' in str(
        err.value
    )


@pytest.mark.parametrize(
    ("choice", "shown", "problem"),
    [("2000", "'2000'", 'a number, not text ("2000")'), (True, "True", "a number, not a flag")],
)
def test_a_choice_of_the_wrong_type_is_refused_at_its_draw(
    tmp_path, choice: object, shown: str, problem: str
) -> None:
    """`choice = [1000, "2000"]` for the PRF: the text is never read as 2000 Hz (nor `true` as
    1 Hz); the record that draws it is refused, naming the draw and asking for the field's
    type, not for a range."""
    from mdframework.errors import ConfigError

    params = {"params": {"radar.prf": {"choice": [choice]}}}
    with pytest.raises(ConfigError) as err:
        _plan(tmp_path, {}, params)
    msg = str(err.value)
    assert f'randomize.params."radar.prf" drew {shown} for radar.prf: {problem}' in msg
    assert msg.endswith("give the distribution values of the field's type")


def test_a_record_skipped_for_a_bad_draw_says_which_draw(tmp_path) -> None:
    """With on_error = "skip" the planner leaves records to the build; the skipped record's
    cause names the draw too."""
    import json

    from conftest import EXAMPLES

    from mdframework.dataset import build_record, load_dataset_config, plan_records

    bvh = EXAMPLES / "data" / "cmu" / "bvh" / "16_21.bvh"
    source = {"label": "walk", "motion": {"kind": "cmu", "file": str(bvh)}, "max_records": 1}
    cfg = {
        "seed": 7,
        "on_error": "skip",
        "sources": [{**source, "record_length": 1.0}],
        "randomize": {"height": {"uniform": [1.5, 1.9]}},
    }
    path = tmp_path / "ds.json"
    path.write_text(json.dumps(cfg))
    (spec,) = plan_records(*load_dataset_config(path))
    row = build_record(spec, str(tmp_path))
    assert "randomize.height drew" in row["skipped"] and "motion.height" in row["skipped"]
    assert not list(tmp_path.rglob("*.npz"))


def test_blamed_draw_prefers_the_most_specific_field() -> None:
    from mdframework.dataset import blamed_draw

    draws = {"radar_range": 5.0, "radar_height": 1.2, "effects.0.snr_db": 3.0, "speed": 1.1}
    assert blamed_draw("scene.radar_position.2", draws) == "radar_height"
    assert blamed_draw("scene.radar_position.0", draws) == "radar_range"
    assert blamed_draw("scene.radar_position", draws) == "radar_height"  # holds both
    assert blamed_draw("effects.0.snr_db", draws) == "effects.0.snr_db"
    assert blamed_draw("effects.0", draws) == "effects.0.snr_db"
    assert blamed_draw("scene", draws) is None  # a check across the section blames no draw
    assert blamed_draw("radar.prf", draws) is None
    assert blamed_draw("motion.duration", {"speed": 2.0}) is None  # augmentations set no field


@pytest.mark.parametrize("warp", [None, [0.25, -0.2, 0.1]])
@pytest.mark.parametrize("speed", [2.0, 1.6, 0.7])
def test_a_sped_up_record_stays_within_its_sources_span(speed: float, warp: list | None) -> None:
    """A source limited to 0.4-2.4 s of a CMU walk, cut into 1 s windows, played `speed` times
    as fast: every record's motion comes from the span (the frames inside the record's window
    carry their original time stamps), never from after 2.4 s, which once held another part of
    the recording; a span too short for the record at that speed is refused, also a span that
    only a start limits."""
    import json

    from conftest import EXAMPLES

    from mdframework.dataset import _augmented, _load_motion
    from mdframework.errors import SceneError

    amc = EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc"
    motion = _load_motion(json.dumps({"kind": "cmu", "file": str(amc)}), str(EXAMPLES))
    t0 = motion.skeleton.time[0]
    original = motion.skeleton.time - t0
    draws = {"speed": speed, **({"time_warp": warp} if warp else {})}
    span = (0.4, 2.4)
    for start in (0.4, 0.9, 1.4):
        out, first = _augmented(motion, draws, start, 1.0, span)
        t = out.skeleton.time - t0
        inside = (t >= first - 1e-9) & (t <= first + 1.0 + 1e-9)
        assert original[inside].max() <= span[1] + 1e-9
        if warp is None:  # a warp shifts the whole motion a little, the window with it
            assert original[inside].min() >= span[0] - 1e-9
        assert first <= start / speed + 1e-12  # a record is only ever moved back
    with pytest.raises(SceneError, match=r"leaves 0\.400 s of the source's span"):
        _augmented(motion, {"speed": 5.0}, 0.4, 1.0, span)
    # a span given by its start alone: the motion after it, sped up, must hold the record (a
    # record was moved back before the start instead)
    late = (float(original[-1]) - 1.5, None)
    with pytest.raises(SceneError, match=r"leaves 0\.750 s of the source's span"):
        _augmented(motion, {"speed": 2.0}, late[0], 1.0, late)
    _augmented(motion, {"speed": 1.2}, late[0], 1.0, late)  # 1.25 s: it fits


def test_height_scaling_keeps_a_raised_floor() -> None:
    """A walker standing on a 0.25 m step (lowest joint at 0.25 m) scaled to 1.2 x: the
    lowest joint stays at 0.25 m (scaled about the floor under it, not about z = 0), and the
    head rises 1.2 x as far above that floor."""
    s = walker()
    raised = s.with_positions(s.positions + np.array([0.0, 0.0, 0.25]))
    tall = scale_height(raised, 1.2)
    assert tall.positions[..., 2].min() == pytest.approx(0.25, abs=1e-12)
    np.testing.assert_allclose(
        tall.joint("head")[:, 2] - 0.25, 1.2 * s.joint("head")[:, 2], atol=1e-12
    )


def test_randomization_mirror_probability_warp_bounds_and_factor_clipping() -> None:
    """mirror = 0.25 mirrors a quarter of the records (2000 draws: 0.22 .. 0.28); time_warp =
    0.9 draws three coefficients each within +-0.3, so sum |c_k| < 0.9 < 1 and the warp stays
    monotone; a normal speed draw far beyond its 4 standard deviations is clipped to the
    factor's range (10 x)."""
    rng = np.random.default_rng(0)
    rz = Randomization(mirror=0.25, time_warp=0.9)
    draws = [rz.sample(rng) for _ in range(2000)]
    assert 0.22 < np.mean([d["mirror"] for d in draws]) < 0.28
    coeffs = np.array([d["time_warp"] for d in draws])
    assert np.abs(coeffs).max() <= 0.3 and np.abs(coeffs).max() > 0.29
    assert np.abs(coeffs).sum(axis=1).max() < 0.9

    class Wild:
        def normal(self, mean: float, sd: float) -> float:
            return mean + 50 * sd

    fast = Randomization.model_validate({"speed": {"normal": [2.0, 0.25]}})
    assert fast.sample(Wild())["speed"] == 10.0  # type: ignore[arg-type]
