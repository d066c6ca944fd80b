"""``mdf run`` writes the seven features and the envelope tracks (features.json, result.npz)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES

from mdframework import cli
from mdframework.dataset import FeatureConfig
from mdframework.features import FEATURE_NAMES, spectrogram_features


def test_run_writes_features_and_envelopes(tmp_path: Path) -> None:
    cfg = tmp_path / "walk.toml"
    cfg.write_text(f"""
[motion]
kind = "cmu"
file = "{EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc"}"
activity = "walk"
duration = 2.0
[scatterers]
kind = "ellipsoid"
placement = "joints17"
[radar]
kind = "lfm"
[scene]
radar_position = [10.0, 0.0, 2.0]
person = {{ position = [0.0, 0.0], aspect_deg = 0.0 }}
""")
    out = tmp_path / "out"
    assert cli.main(["run", str(cfg), "--out", str(out)]) == 0
    doc = json.loads((out / "features.json").read_text())
    with np.load(out / "result.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    n = arrays["time_s"].shape[0]
    for key in ("envelope_upper_mps", "envelope_lower_mps", "torso_velocity_mps"):
        assert arrays[key].shape == (n,) and len(doc[key]) == n
    # the same numbers as a dataset record with the default features computes from the same
    # spectrogram, and as the settings written beside them give
    settings = doc["settings"]
    assert settings == {k: v for k, v in FeatureConfig().model_dump().items() if k in settings}
    power = 10 ** (arrays["spectrogram_db"].astype(float) / 10)
    expected = spectrogram_features(
        power,
        arrays["velocity_mps"],
        method=settings["method"],
        threshold_db=settings["threshold_db"],
        floor_db=settings["floor_db"],
        torso_method=settings["torso"],
    )
    np.testing.assert_allclose(arrays["features_mps"], expected, rtol=1e-5, atol=1e-6)
    assert list(doc["features"]) == list(FEATURE_NAMES)
    np.testing.assert_allclose([doc["features"][k] for k in FEATURE_NAMES], arrays["features_mps"])
    up, lo, torso = (
        arrays[k] for k in ("envelope_upper_mps", "envelope_lower_mps", "torso_velocity_mps")
    )
    live = np.isfinite(torso)
    assert live.all() and np.all(lo[live] <= torso[live]) and np.all(torso[live] <= up[live])
    assert doc["features"]["upper_max"] == pytest.approx(float(np.max(up)))
    # a walk toward the radar: the torso comes at about the walking speed (02_01: ~1.2 m/s)
    assert 0.8 < doc["features"]["torso_mean"] < 1.5
