"""Body self-shadowing (effect kind ``shadowing``)."""

from __future__ import annotations

from typing import Any

import mdf_ellipsoid.plugin
import mdf_lfm.plugin
import mdf_mujoco.plugin
import mujoco
import numpy as np
import pytest
import synthetic
from mdf_mujoco.shadowing import Shadowing, ShadowingConfig

from mdframework import CANONICAL_JOINTS, Scatterers, SceneContext, SceneError, Skeleton
from mdframework.config import validate_run_config
from mdframework.pipeline import RunResult, simulate
from mdframework.plugins import Registry, build_registry

J = {n: i for i, n in enumerate(CANONICAL_JOINTS)}


@pytest.fixture(scope="module")
def registry() -> Registry:
    return build_registry([mdf_mujoco.plugin, mdf_lfm.plugin, mdf_ellipsoid.plugin], autoload=False)


def context(radar: list[float], skeleton: Skeleton, n: int) -> SceneContext:
    t = np.arange(n) / 2400.0
    return SceneContext(
        np.array(radar, dtype=float), 2400.0, 15e9, t, np.zeros(n), skeleton, None,  # type: ignore[arg-type]
        np.random.default_rng(0),
    )  # fmt: skip


def torso_and_two_balls(n: int = 3) -> Scatterers:
    """An upright torso ellipsoid at the origin, a small ball 0.5 m behind it (-x) and one
    0.5 m in front (+x), both a little above the torso's centre (off its line of sight)."""
    pos = np.array([[0.0, 0.0, 0.0], [-0.5, 0.0, 0.1], [0.5, 0.0, 0.2]])
    semi = np.array([[0.15, 0.15, 0.26], [0.02, 0.02, 0.02], [0.02, 0.02, 0.02]])
    axes = np.array([[0.0, 0.0, 0.26], [0.0, 0.0, 0.02], [0.0, 0.0, 0.02]])
    return Scatterers(
        np.repeat(pos[None], n, 0),
        np.ones((n, 3)),
        ("torso", "behind", "front"),
        semi,
        np.repeat(axes[None], n, 0),
    )


def standing_skeleton(n: int = 3) -> Skeleton:
    joints = np.repeat(synthetic.standing()[None], n, 0)
    return Skeleton(np.arange(n) / 2400.0, joints, CANONICAL_JOINTS)


def test_scatterer_behind_the_torso_is_blocked() -> None:
    scat = torso_and_two_balls()
    skel = standing_skeleton()
    effect = Shadowing(ShadowingConfig(attenuation_db=20.0))
    blocked = effect.visibility(scat, context([10.0, 0.0, 0.0], skel, 3))
    assert blocked.tolist() == [[False, True, False]] * 3
    out = effect.apply(scat, context([10.0, 0.0, 0.0], skel, 3))
    assert np.allclose(out.rcs, [[1.0, 0.01, 1.0]] * 3)
    # from the other side the roles swap
    blocked = effect.visibility(scat, context([-10.0, 0.0, 0.0], skel, 3))
    assert blocked.tolist() == [[False, False, True]] * 3
    assert effect.describe()["blocked_fraction"] == {"torso": 0.0, "behind": 0.0, "front": 1.0}


def test_ray_just_missing_the_torso_is_not_blocked() -> None:
    scat = torso_and_two_balls()
    pos = scat.positions.copy()
    pos[:, 1] = [-0.5, 0.17, 0.1]  # behind, but beside the 0.15 m torso
    blocked = Shadowing(ShadowingConfig()).visibility(
        scat.replace(positions=pos), context([100.0, 0.17, 0.1], standing_skeleton(), 3)
    )
    assert not blocked[:, 1].any()


def test_capsules_around_a_skeleton() -> None:
    """Point scatterers at the joints of a standing body seen from its left: the right elbow
    and hip are hidden behind the torso and pelvis, the left ones are not."""
    skel = standing_skeleton()
    scat = Scatterers(skel.positions.copy(), np.ones((3, 17)), CANONICAL_JOINTS)
    effect = Shadowing(ShadowingConfig())
    blocked = effect.visibility(scat, context([0.0, 10.0, 1.2], skel, 3))
    assert effect.describe()["occluders"] == "capsules"
    assert blocked[:, J["r_elbow"]].all() and blocked[:, J["r_shoulder"]].all()
    assert not blocked[:, J["l_elbow"]].any() and not blocked[:, J["l_shoulder"]].any()
    assert not blocked[:, J["head"]].any()


def test_capsules_need_a_canonical_body() -> None:
    skel = Skeleton(np.arange(3.0), np.zeros((3, 1, 3)), ("target0",))
    scat = Scatterers(np.zeros((3, 1, 3)), np.ones((3, 1)), ("target0",))
    with pytest.raises(SceneError, match="canonical"):
        Shadowing(ShadowingConfig()).apply(scat, context([10.0, 0.0, 0.0], skel, 3))


def run(registry: Registry, effects: list[dict[str, Any]], **scatterers: Any) -> RunResult:
    cfg = {
        "motion": {"kind": "boulic", "rv": 1.0, "duration": 2.0},
        "scatterers": {"kind": "mujoco_body", **scatterers},
        "radar": {"kind": "lfm"},
        "scene": {
            "radar_position": [10.0, 0.0, 2.0],
            "person": {"position": [0.0, -1.0], "aspect_deg": 90.0},
        },
        "effects": effects,
        "processing": {"keep_scatterers": True},
    }
    return simulate(validate_run_config(cfg, registry=registry), registry)


def test_no_ray_is_cast_when_shadowing_is_off(
    registry: Registry, monkeypatch: pytest.MonkeyPatch
) -> None:
    def fail(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("a ray was cast")

    monkeypatch.setattr(mujoco, "mj_multiRay", fail)
    monkeypatch.setattr(mujoco, "mj_ray", fail)
    res = run(registry, [])
    assert res.metadata["effects"] == []
    with pytest.raises(AssertionError, match="a ray was cast"):  # the patch does catch casts
        run(registry, [{"kind": "shadowing"}])


def test_walker_seen_from_the_side(registry: Registry) -> None:
    """Crossing the beam with the radar on the walker's right: the left (far) limbs are hidden
    far more often than the right (near) ones, whose returns are untouched."""
    plain = run(registry, [])
    shadow = run(registry, [{"kind": "shadowing", "attenuation_db": 30.0}])
    frac = shadow.metadata["effects"][0]["blocked_fraction"]
    far = np.mean([frac[f"l_{p}"] for p in ("upper_arm", "lower_arm", "upper_leg", "hip")])
    near = np.mean([frac[f"r_{p}"] for p in ("upper_arm", "lower_arm", "upper_leg")])
    assert far > 0.3 and near < 0.05
    names = plain.scatterers.names
    ratio = shadow.scatterers.rcs / plain.scatterers.rcs
    assert np.all(np.isclose(ratio, 1.0) | np.isclose(ratio, 1e-3))
    assert np.allclose(ratio[:, names.index("r_upper_arm")], 1.0)


def test_decimation_holds_the_result(registry: Registry) -> None:
    plain = run(registry, []).scatterers.rcs
    every = run(registry, [{"kind": "shadowing"}])
    fourth = run(registry, [{"kind": "shadowing", "decimation": 4}])
    assert np.any(every.scatterers.rcs < 0.5 * plain)
    agree = np.mean(np.isclose(every.scatterers.rcs, fourth.scatterers.rcs, rtol=1e-12, atol=0))
    assert agree > 0.99
    assert fourth.metadata["effects"][0]["rays_cast"] * 4 == pytest.approx(
        every.metadata["effects"][0]["rays_cast"], rel=1e-3
    )


def test_works_with_the_ellipsoid_model(registry: Registry) -> None:
    cfg = {
        "motion": {"kind": "boulic", "rv": 1.0, "duration": 1.0},
        "scatterers": {"kind": "ellipsoid", "placement": "joints17"},
        "scene": {"radar_position": [10.0, 0.0, 2.0], "person": {"aspect_deg": 90.0}},
        "effects": [{"kind": "shadowing"}],
    }
    res = simulate(validate_run_config(cfg, registry=registry), registry)
    eff = res.metadata["effects"][0]
    assert eff["occluders"] == "ellipsoids"
    assert max(eff["blocked_fraction"].values()) > 0.0


def test_bounced_paths_keep_their_scatterers_visibility_and_multipath_first_is_refused() -> None:
    """Shadowing before multipath: each bounced path (image, single bounce) is made from its
    scatterer's shadowed RCS, so it is hidden exactly when the direct path is (the documented
    approximation). Multipath before shadowing would cast rays to the virtual places and take
    the copies for occluders (hiding the direct scatterers more often): refused."""
    import mdf_multipath.plugin

    reg = build_registry(
        [mdf_mujoco.plugin, mdf_lfm.plugin, mdf_ellipsoid.plugin, mdf_multipath.plugin],
        autoload=False,
    )
    shadow = {"kind": "shadowing", "attenuation_db": 20.0, "decimation": 8}
    cfg = {
        "motion": {"kind": "boulic", "rv": 1.0, "duration": 0.5},
        "scatterers": {"kind": "ellipsoid", "placement": "joints17"},
        "scene": {"radar_position": [10.0, 0.0, 2.0], "person": {"aspect_deg": 90.0}},
        "processing": {"keep_scatterers": True, "window_length": 128},
    }

    def run_with(effects: list[dict[str, Any]]) -> RunResult:
        return simulate(validate_run_config({**cfg, "effects": effects}, registry=reg), reg)

    plain = run_with([{"kind": "multipath"}]).scatterers
    hidden = run_with([shadow, {"kind": "multipath"}]).scatterers
    assert plain is not None and hidden is not None and plain.names == hidden.names
    assert np.all(hidden.rcs[plain.rcs == 0] == 0)  # no bounced paths of a part on the ground
    ratio = hidden.rcs / np.where(plain.rcs > 0, plain.rcs, np.nan)
    n = len(plain.names) // 3  # direct, ~image, ~bounce
    ratio[:, n:] = np.where(np.isnan(ratio[:, n:]), np.tile(ratio[:, :n], 2), ratio[:, n:])
    assert set(np.round(ratio[:, :n], 12).ravel()) == {0.01, 1.0}  # some hidden, some not
    np.testing.assert_allclose(ratio[:, n : 2 * n], ratio[:, :n], rtol=1e-12)
    np.testing.assert_allclose(ratio[:, 2 * n :], ratio[:, :n], rtol=1e-12)
    with pytest.raises(
        SceneError,
        match=r"^effects: multipath \(effects\[0\]\) is listed before shadowing \(effects\[1\]\)"
        r", so .*: list multipath after shadowing$",
    ):
        run_with([{"kind": "multipath"}, shadow])


def test_the_body_hides_a_reflector_behind_it_and_shadowing_before_static_scene_is_refused() -> (
    None
):
    """static_scene before shadowing: a room reflector straight behind the walker's torso, at
    the radar's height, is hidden at every pulse (the torso always lies on its ray), and one
    beside the path never is. Shadowing listed first would never hide the room (it ran before
    the reflectors existed): refused, naming both places."""
    import mdf_static_scene.plugin

    reg = build_registry(
        [mdf_mujoco.plugin, mdf_lfm.plugin, mdf_ellipsoid.plugin, mdf_static_scene.plugin],
        autoload=False,
    )
    shadow = {"kind": "shadowing", "attenuation_db": 20.0, "decimation": 8}
    room = {
        "kind": "static_scene",
        "reflectors": [
            {"position": [-3.0, 0.0, 1.2], "rcs_m2": 1.0},  # behind the torso
            {"position": [-3.0, 4.0, 1.2], "rcs_m2": 1.0},  # off to the side
        ],
    }
    cfg = {
        "motion": {"kind": "boulic", "rv": 1.0, "duration": 0.5},
        "scatterers": {"kind": "mujoco_body"},
        "scene": {
            "radar_position": [10.0, 0.0, 1.2],
            "person": {"motion": "treadmill", "aspect_deg": 90.0},
        },
        "processing": {"window_length": 128},
    }

    def run_with(effects: list[dict[str, Any]]) -> RunResult:
        return simulate(validate_run_config({**cfg, "effects": effects}, registry=reg), reg)

    blocked = run_with([room, shadow]).metadata["effects"][1]["blocked_fraction"]
    assert (blocked["static0"], blocked["static1"]) == (1.0, 0.0)
    with pytest.raises(
        SceneError,
        match=r"^effects: shadowing \(effects\[0\]\) is listed before static_scene "
        r"\(effects\[1\]\), so the room's reflectors would never be hidden .*: list shadowing "
        r"after static_scene$",
    ):
        run_with([shadow, room])
