"""Static scene reflectors (effect ``static_scene``, mdf-static-scene)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import phase_increment_doppler
from mdf_static_scene.static import StaticScene, StaticSceneConfig, room

from mdframework import Scatterers
from mdframework.config import validate_run_config
from mdframework.pipeline import simulate


def test_random_room_is_seeded_and_inside_its_region() -> None:
    cfg = StaticSceneConfig(
        count=500,
        seed=3,
        distance_m=(1.0, 3.0),
        azimuth_deg=180.0,
        spread_deg=30.0,
        height_m=(0.0, 1.5),
        rcs_m2=(0.01, 1.0),
        reflectors=[{"position": (0.0, 0.0, 0.0), "rcs_m2": 2.0}],
    )
    radar = np.array([5.0, 1.0, 1.2])
    pos, sig = room(cfg, radar)
    again, _ = room(cfg, radar)
    np.testing.assert_array_equal(pos, again)
    assert pos.shape == (501, 3) and sig[0] == 2.0
    rel = pos[1:, :2] - radar[:2]
    d = np.hypot(rel[:, 0], rel[:, 1])
    az = np.rad2deg(np.arctan2(rel[:, 1], rel[:, 0])) % 360
    assert d.min() >= 1.0 and d.max() <= 3.0
    assert az.min() >= 150.0 and az.max() <= 210.0
    assert pos[1:, 2].min() >= 0.0 and pos[1:, 2].max() <= 1.5
    assert sig[1:].min() >= 0.01 and sig[1:].max() <= 1.0
    other, _ = room(cfg.model_copy(update={"seed": 4}), radar)
    assert not np.array_equal(pos, other)


def test_reflectors_are_appended_and_fixed_over_pulses() -> None:
    n = 7
    body = Scatterers(
        np.random.default_rng(0).normal(size=(n, 2, 3)),
        np.ones((n, 2)),
        ("a", "b"),
        np.full((2, 3), 0.1),
        np.ones((n, 2, 3)),
    )
    effect = StaticScene(StaticSceneConfig(count=3, seed=1))

    class Ctx:
        radar_position = np.array([10.0, 0.0, 1.0])

    out = effect.apply(body, Ctx())  # type: ignore[arg-type]
    assert out.names[:2] == ("a", "b") and out.positions.shape == (n, 5, 3)
    np.testing.assert_array_equal(out.positions[:, :2], body.positions)
    assert np.all(out.positions[:, 2:] == out.positions[0, 2:])
    assert out.semi_axes is not None and out.semi_axes.shape == (5, 3)
    assert out.axes is not None and out.axes.shape == (n, 5, 3)


def test_a_strong_static_reflector_pulls_the_return_to_zero_doppler() -> None:
    """A target receding at 1 m/s (-100 Hz at 15 GHz) beside a static reflector 20 dB
    stronger at the same range: the slow-time signal's mean Doppler drops to about 0 Hz."""

    def run(effects: list[dict[str, object]]) -> float:
        cfg = {
            "motion": {
                "kind": "point_targets",
                "length": 1.0,
                "targets": [{"position": [100.0, 0.0, 0.0], "velocity": [1.0, 0.0, 0.0]}],
            },
            "scatterers": {"kind": "points"},
            "radar": {"kind": "lfm"},
            "scene": {"radar_position": [0.0, 0.0, 0.0]},
            "effects": effects,
        }
        result = simulate(validate_run_config(cfg))
        return phase_increment_doppler(result.received.signal, result.metadata["prf_hz"])

    assert run([]) == pytest.approx(-100.07, abs=0.5)
    reflector = {"position": [100.2, 0.0, 0.0], "rcs_m2": 100.0}
    assert abs(run([{"kind": "static_scene", "reflectors": [reflector]}])) < 10.0


def test_the_documented_config_is_valid() -> None:
    import re
    import tomllib

    from conftest import ROOT

    text = (ROOT / "docs" / "effects.md").read_text()
    block = next(b for b in re.findall(r"```toml\n(.*?)```", text, re.S) if "static_scene" in b)
    [section] = tomllib.loads(block)["effects"]
    cfg = StaticSceneConfig.model_validate(section)
    pos, _ = room(cfg, np.array([10.0, 0.0, 1.0]))
    assert pos.shape == (21, 3)


def test_a_reflector_takes_its_ground_bounces_gains_and_losses_over_its_own_paths() -> None:
    """The documented order static_scene, multipath, antenna, attenuation: a reflector at ``p``
    (radar at 1 m, ground at 0) and its bounced paths carry, in closed form, the gains of their
    own directions (``g(u_d)^2``, ``g(u_b)^2``, ``g(u_d) g(u_b)``) and the losses of their own
    lengths (``2 R_d``, ``2 R_b``, ``R_d + R_b``), with ``|Gamma|^4`` and ``4 |Gamma|^2`` and the
    bounce's spreading ``R_m^4 / (R_d^2 R_b^2)``."""
    from mdf_antenna import one_way_gain

    radar_at, p = np.array([0.0, 0.0, 1.0]), np.array([6.0, 2.0, 0.5])
    gamma_db, refl, bw = 200.0, 0.5, np.deg2rad(30.0)
    effects = [
        {"kind": "static_scene", "reflectors": [{"position": p.tolist(), "rcs_m2": 1.0}]},
        {"kind": "multipath", "reflection_magnitude": refl, "reflection_phase_deg": 0.0},
        {"kind": "antenna", "beamwidth_az_deg": 30.0, "pointing": "angles", "azimuth_deg": 0.0},
        {"kind": "attenuation", "gas_db_per_km": gamma_db},
    ]
    target = [{"position": [10.0, 0.0, 1.5], "velocity": [-1.0, 0.0, 0.0], "rcs": 1.0}]
    cfg = {
        "motion": {"kind": "point_targets", "length": 0.2, "targets": target},
        "scatterers": {"kind": "points"},
        "radar": {"kind": "lfm"},
        "scene": {"radar_position": radar_at.tolist()},
        "processing": {"keep_scatterers": True},
        "effects": effects,
    }
    scat = simulate(validate_run_config(cfg)).scatterers
    assert scat is not None
    image = p * np.array([1.0, 1.0, -1.0])
    r_d, r_b = np.linalg.norm(p - radar_at), np.linalg.norm(image - radar_at)
    r_m = (r_d + r_b) / 2

    def g(d: np.ndarray) -> float:
        boresight = np.array([1.0, 0.0, 0.0])
        return float(
            one_way_gain(d, boresight, pattern="gaussian", beamwidth_az=bw, beamwidth_el=bw)
        )

    def loss(path: float) -> float:  # two-way over a round trip of 2 path [m]
        return float(10 ** (-2 * gamma_db * path / 1e4))

    g_d, g_b = g(p - radar_at), g(image - radar_at)
    expected = {
        "static0": g_d**2 * loss(r_d),
        "static0~image": refl**4 * g_b**2 * loss(r_b),
        "static0~bounce": 4 * refl**2 * r_m**4 / (r_d * r_b) ** 2 * g_d * g_b * loss(r_m),
    }
    for name, rcs in expected.items():
        assert scat.rcs[:, scat.names.index(name)] == pytest.approx(rcs, rel=1e-12, abs=0)
