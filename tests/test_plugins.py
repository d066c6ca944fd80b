"""Plugin discovery through real entry points, and the registry's rules."""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
import synthetic

from mdframework import cli
from mdframework.plugins import DISABLE_ENV, PluginError, build_registry, default_registry


def _make_distribution(root: Path, dist: str, module: str, body: str, ep_name: str) -> None:
    """Write an installed distribution (package + .dist-info with an entry point) into root."""
    (root / module).mkdir()
    (root / module / "__init__.py").write_text(textwrap.dedent(body))
    info = root / f"{dist.replace('-', '_')}-0.0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 0.0.1\n")
    (info / "entry_points.txt").write_text(f"[mdframework]\n{ep_name} = {module}\n")


THIRD_PARTY = """
    from typing import Literal
    import numpy as np
    from mdframework import MotionConfig, MotionSource, Motion, Skeleton, hookimpl

    class StillConfig(MotionConfig):
        kind: Literal["still_point"] = "still_point"

    class StillPoint(MotionSource):
        '''One point that does not move.'''
        name = "still_point"
        Config = StillConfig
        def load(self):
            t = np.linspace(0, 1, 11)
            return Motion(Skeleton(t, np.zeros((11, 1, 3)) + 5.0, ("p",)), {"source": "still"})

    @hookimpl
    def mdframework_register_motion_sources():
        return [StillPoint]
"""


@pytest.fixture
def clean_modules() -> object:
    before = set(sys.modules)
    yield None
    for name in set(sys.modules) - before:
        if name.startswith("mdf_test"):
            del sys.modules[name]


def test_builtin_plugins_come_from_their_distributions() -> None:
    reg = build_registry(autoload=True)
    assert reg.plugins["radar"]["lfm"].provider.startswith("mdf-lfm ")
    assert reg.plugins["scatterers"]["ellipsoid"].provider.startswith("mdf-ellipsoid ")
    assert reg.plugins["motion"]["point_targets"].provider.startswith("mdf-point-targets ")


def test_third_party_distribution_is_discovered(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_modules: object
) -> None:
    _make_distribution(tmp_path, "mdf-test-still", "mdf_test_still", THIRD_PARTY, "still")
    monkeypatch.syspath_prepend(str(tmp_path))
    reg = build_registry(autoload=True)
    info = reg.plugins["motion"]["still_point"]
    assert info.provider == "mdf-test-still 0.0.1"
    motion = info.cls(info.cls.Config()).load()  # type: ignore[call-arg]
    assert motion.skeleton.positions[0, 0, 0] == 5.0


def test_documented_example_distribution_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_modules: object
) -> None:
    """The plugin author's guide's example (examples/plugin-example) loads through a real entry
    point and runs end to end: a target circling 1 m around a point 10 m from the radar has
    radial speed up to 2 pi r / T."""
    from conftest import EXAMPLES

    from mdframework.config import validate_run_config
    from mdframework.pipeline import simulate

    source = EXAMPLES / "plugin-example" / "src" / "mdf_example_circle" / "__init__.py"
    _make_distribution(
        tmp_path, "mdf-example-circle", "mdf_test_circle", source.read_text(), "example_circle"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    reg = build_registry(autoload=True)
    assert reg.plugins["motion"]["circle"].provider == "mdf-example-circle 0.0.1"
    cfg = {
        "motion": {"kind": "circle", "centre": [10.0, 0.0, 0.0], "radius": 1.0, "period": 2.0},
        "scatterers": {"kind": "points"},
        "scene": {"radar_position": [0.0, 0.0, 0.0]},
    }
    res = simulate(validate_run_config(cfg, registry=reg), reg)
    v = res.velocity[np.argmax(res.spectrogram.power, axis=0)]
    dv = res.velocity[1] - res.velocity[0]
    assert v.max() == pytest.approx(np.pi, abs=0.1 + dv)
    assert v.min() == pytest.approx(-np.pi, abs=0.1 + dv)


def test_broken_plugin_error_reaches_the_user(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    clean_modules: object,
) -> None:
    _make_distribution(
        tmp_path, "mdf-test-broken", "mdf_test_broken", "import no_such_module_xyz\n", "broken"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(PluginError, match=r"'broken' from mdf-test-broken 0\.0\.1 failed to load"):
        build_registry(autoload=True)
    default_registry.cache_clear()
    try:
        assert cli.main(["plugins"]) == 2
    finally:
        default_registry.cache_clear()
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no_such_module_xyz" in err[0]


def test_duplicate_names_are_rejected() -> None:
    other = ModuleType("other")
    other.mdframework_register_motion_sources = (  # type: ignore[attr-defined]
        synthetic.mdframework_register_motion_sources
    )
    with pytest.raises(PluginError, match="two motion plugins are named 'synthetic_walker'"):
        build_registry([synthetic, other], autoload=False)


def test_wrong_class_is_rejected() -> None:
    bad = ModuleType("bad")

    def mdframework_register_waveforms() -> list[type]:
        return [synthetic.SyntheticWalker]

    bad.mdframework_register_waveforms = synthetic.hookimpl(  # type: ignore[attr-defined]
        mdframework_register_waveforms
    )
    with pytest.raises(PluginError, match="not a RadarWaveform subclass"):
        build_registry([bad], autoload=False)


def test_misspelled_hook_fails_loudly() -> None:
    typo = ModuleType("typo")

    def mdframework_register_motion_source() -> list[type]:
        return []

    typo.mdframework_register_motion_source = synthetic.hookimpl(  # type: ignore[attr-defined]
        mdframework_register_motion_source
    )
    with pytest.raises(Exception, match="unknown hook"):
        build_registry([typo], autoload=False)


def test_environment_variable_disables_autoload(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(DISABLE_ENV, "1")
    reg = build_registry([synthetic])
    assert reg.names("motion") == ["synthetic_walker"]
    assert reg.names("radar") == []
    with pytest.raises(KeyError, match="no radar plugin named 'lfm'"):
        reg.get("radar", "lfm")
