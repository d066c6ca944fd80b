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

        def receive(self, ranges: Any, rcs: Any, gate_range: Any) -> Received:
            return Received(np.conj(super().receive(ranges, rcs, gate_range).signal))

    with pytest.raises(AssertionError, match="approaching target must show"):
        check_waveform(Flipped(Flipped.Config()))

    class Misnamed(LfmPulseDoppler):
        """Registered as 'lfm2' but its config says kind = 'lfm'."""

        name = "lfm2"

    with pytest.raises(AssertionError, match=r"Config\.kind must be Literal\['lfm2'\]"):
        check_plugin_class(Misnamed, "radar")
