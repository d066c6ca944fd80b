"""Every installed plugin passes its interface's contract (mdframework.testing)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from conftest import EXAMPLES

from mdframework.config import load_run_config
from mdframework.physics import interpolation
from mdframework.pipeline import build_stages, place_body
from mdframework.plugins import INTERFACES, default_registry
from mdframework.skeleton import Skeleton
from mdframework.testing import (
    check_block_invariance,
    check_effect_class,
    check_motion_source,
    check_plugin_class,
    check_recording_source,
    check_scatterer_model,
    check_waveform,
)

REGISTRY = default_registry()
ALL = [(i, n) for i in INTERFACES for n in REGISTRY.names(i)]

#: an example config that uses each motion source (every source must have one)
SOURCE_EXAMPLES = {
    "boulic": "boulic_walk.toml",
    "bvh": "bvh_mixamo.toml",
    "cmu": "cmu_walk.toml",
    "kinect": "kinect_utkinect_walk.toml",
    "point_targets": "point_target.toml",
}


@pytest.mark.parametrize(("interface", "name"), ALL, ids=[f"{i}:{n}" for i, n in ALL])
def test_plugin_class_contract(interface: str, name: str) -> None:
    cls: Any = REGISTRY.get(interface, name)
    if interface == "effect":
        check_effect_class(cls)
    else:
        check_plugin_class(cls, interface)


@pytest.mark.parametrize("name", REGISTRY.names("motion"))
def test_motion_source_contract(name: str) -> None:
    assert name in SOURCE_EXAMPLES, f"add an example using the {name!r} source"
    config = load_run_config(EXAMPLES / SOURCE_EXAMPLES[name])
    check_motion_source(build_stages(config).source)


#: a recording each recording source reads in its contract check
RECORDING_EXAMPLES = {"radhar": {"file": "data/radhar/radhar_walk_subset.npz"}}


@pytest.mark.parametrize("name", REGISTRY.names("recording"))
def test_recording_source_contract(name: str) -> None:
    assert name in RECORDING_EXAMPLES, f"add an example recording for the {name!r} source"
    cls: Any = REGISTRY.get("recording", name)
    section = {"kind": name, **RECORDING_EXAMPLES[name]}
    config = cls.Config.model_validate(section, context={"base_dir": EXAMPLES})
    check_recording_source(cls(config))


@pytest.fixture(scope="module")
def placed_body() -> tuple[Any, Skeleton]:
    config = load_run_config(EXAMPLES / "cmu_walk.toml")
    motion = build_stages(config).source.load()
    body = place_body(motion.canonical(), config.scene.person, np.array([10.0, 0.0, 1.0]))
    t = interpolation.pulse_times(body.time[0], body.time[0] + 1.0, 2400.0)
    joints = interpolation.resample_tracks(body.time, body.positions, body.valid, t)
    return motion, Skeleton(t, joints, body.joint_names)


@pytest.mark.parametrize("name", REGISTRY.names("scatterers"))
def test_scatterer_model_contract(name: str, placed_body: tuple[Any, Skeleton]) -> None:
    cls: Any = REGISTRY.get("scatterers", name)
    config = cls.Config(body=True) if name == "points" else cls.Config()
    motion, skeleton = placed_body
    check_scatterer_model(cls(config), skeleton, motion)


@pytest.mark.parametrize("name", REGISTRY.names("radar"))
def test_waveform_contract(name: str) -> None:
    cls: Any = REGISTRY.get("radar", name)
    check_waveform(cls(cls.Config()))


def test_the_contracts_catch_broken_plugins() -> None:
    """A waveform with the wrong Doppler sign, and a config whose kind is not its name."""
    from mdf_lfm import LfmPulseDoppler

    from mdframework.interfaces import Received

    class Flipped(LfmPulseDoppler):
        """Conjugates its output: approaching targets come out negative."""

        def receive(self, block: Any) -> Received:
            return Received(np.conj(super().receive(block).signal))

    with pytest.raises(AssertionError, match="approaching target must show"):
        check_waveform(Flipped(Flipped.Config()))

    class Misnamed(LfmPulseDoppler):
        """Registered as 'lfm2' but its config says kind = 'lfm'."""

        name = "lfm2"

    with pytest.raises(AssertionError, match=r"Config\.kind must be Literal\['lfm2'\]"):
        check_plugin_class(Misnamed, "radar")


def _model(name: str) -> Any:
    cls: Any = REGISTRY.get("scatterers", name)
    return cls(cls.Config(body=True) if name == "points" else cls.Config())


@pytest.mark.parametrize("name", REGISTRY.names("scatterers"))
def test_scatterer_model_is_block_invariant(name: str, placed_body: tuple[Any, Skeleton]) -> None:
    """One block or blocks of 37 pulses give the same RCS and signal (streaming contract)."""
    motion, skeleton = placed_body
    lfm: Any = REGISTRY.get("radar", "lfm")
    check_block_invariance(_model(name), lfm(lfm.Config()), skeleton, motion)


@pytest.mark.parametrize("path", ["analytic", "raw"])
def test_waveform_paths_are_block_invariant(path: str, placed_body: tuple[Any, Skeleton]) -> None:
    motion, skeleton = placed_body
    short = skeleton.select_frames(slice(0, 300))
    lfm: Any = REGISTRY.get("radar", "lfm")
    check_block_invariance(_model("ellipsoid"), lfm(lfm.Config(path=path)), short, motion)


@pytest.mark.parametrize(
    ("kind", "fields"),
    [
        ("fmcw", {"beyond_max_range": "alias"}),
        ("fmcw", {"beyond_max_range": "alias", "path": "raw"}),
        ("cw", {}),
    ],
)
def test_other_radars_are_block_invariant(
    kind: str, fields: dict[str, Any], placed_body: tuple[Any, Skeleton]
) -> None:
    """The FMCW radar (blocks of whole frames, receiver noise seeded per frame) and the CW
    radar pass the streaming contract."""
    motion, skeleton = placed_body
    short = skeleton.select_frames(slice(0, 480))
    cls: Any = REGISTRY.get("radar", kind)
    check_block_invariance(_model("ellipsoid"), cls(cls.Config(**fields)), short, motion)


SCATTERER_EFFECTS = [
    n for n in REGISTRY.names("effect") if REGISTRY.get("effect", n).stage == "scatterers"
]


@pytest.mark.parametrize("name", SCATTERER_EFFECTS)
def test_scatterer_effects_are_block_invariant(
    name: str, placed_body: tuple[Any, Skeleton]
) -> None:
    motion, skeleton = placed_body
    cls: Any = REGISTRY.get("effect", name)
    effect = cls(cls.Config())
    effect.start_record(skeleton, np.array([10.0, 0.0, 1.0]))
    lfm: Any = REGISTRY.get("radar", "lfm")
    check_block_invariance(_model("ellipsoid"), lfm(lfm.Config()), skeleton, motion, (effect,))


def test_block_invariance_check_catches_a_per_block_model(
    placed_body: tuple[Any, Skeleton],
) -> None:
    """A model that estimates the body height from each block (not the record) is caught."""
    from mdf_ellipsoid.model import EllipsoidBody

    from mdframework.physics import body as bodymodel

    class PerBlock(EllipsoidBody):
        """Re-estimates the height from every block."""

        def scatterers(self, motion: Any, skeleton: Skeleton, *args: Any) -> Any:
            self._a, self._semi_c = bodymodel.part_semi_axes(
                self._parts, bodymodel.estimate_height(skeleton.positions)
            )
            return super().scatterers(motion, skeleton, *args)

    motion, skeleton = placed_body
    lfm: Any = REGISTRY.get("radar", "lfm")
    with pytest.raises(AssertionError, match="not block-invariant"):
        check_block_invariance(PerBlock(PerBlock.Config()), lfm(lfm.Config()), skeleton, motion)
