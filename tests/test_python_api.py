"""The library as a Python caller (a script or a notebook) uses it: inputs left as they were,
errors that say what is wrong."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mdframework import Skeleton


def test_skeleton_leaves_the_callers_arrays_writeable() -> None:
    t = np.arange(0.0, 1.0, 0.01)
    pos = np.zeros((t.size, 1, 3))
    pos[:, 0, 0] = 10.0
    valid = np.ones((t.size, 1), dtype=bool)
    sk = Skeleton(t, pos, ("p",), valid)
    resampled = Skeleton.resampled(t, pos, ("p",))
    # the caller's arrays stay theirs to change ...
    assert t.flags.writeable and pos.flags.writeable and valid.flags.writeable
    t += 0.0
    pos[0, 0, 0] = 10.0
    # ... while the skeleton's own arrays are read-only (stages share skeletons)
    for skeleton in (sk, resampled):
        with pytest.raises(ValueError, match="read-only"):
            skeleton.positions[0, 0, 0] = 1.0
        with pytest.raises(ValueError, match="read-only"):
            skeleton.time[0] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        sk.valid[0, 0] = False


def test_a_write_to_the_callers_arrays_leaves_a_checked_skeleton_as_it_was() -> None:
    """The caller's writeable arrays are copied, so a later write to them (a NaN where the
    skeleton says valid, a time stamp out of order) cannot break what the skeleton checked; a
    skeleton's own read-only arrays are shared, not copied again."""
    t = np.arange(5) / 100.0
    pos = np.zeros((5, 2, 3))
    pos[:, 1, 0] = np.arange(5)
    sk = Skeleton(t, pos, ("a", "b"))
    pos[2, 1, 0] = np.nan
    t[3] = 0.0
    assert sk.positions[2, 1, 0] == 2.0 and sk.valid[2, 1]
    assert np.all(np.diff(sk.time) > 0)
    moved = sk.with_positions(sk.positions)
    assert moved.positions is sk.positions and moved.time is sk.time


def test_features_of_a_db_map_say_it_is_db_not_silence() -> None:
    from mdframework.features import envelopes, spectrogram_features
    from mdframework.physics.spectrogram import power_to_db

    velocity = np.linspace(-5.0, 5.0, 11)
    power = np.full((11, 6), 1e-6)
    power[7] = 1.0  # a line at +2 m/s
    expected = spectrogram_features(power, velocity)
    assert expected[0] == pytest.approx(2.0)
    db = power_to_db(power, -60.0)
    with pytest.raises(ValueError, match=r"not dB.*10 \*\* \(db / 10\)"):
        spectrogram_features(db, velocity)
    # the way back from dB gives the features of the linear map
    assert np.allclose(spectrogram_features(10 ** (db / 10), velocity), expected)
    for bad in (np.nan, np.inf):
        broken = power.copy()
        broken[0, 0] = bad
        with pytest.raises(ValueError, match="NaN or infinite"):
            envelopes(broken, velocity)


def test_knn_refuses_nan_features_instead_of_answering_one_class() -> None:
    from mdf_knn import Knn

    rng = np.random.default_rng(0)
    x = np.concatenate([rng.normal(0.0, 1.0, (20, 3)), rng.normal(5.0, 1.0, (20, 3))])
    y = np.array(["a"] * 20 + ["b"] * 20)
    assert np.array_equal(Knn(Knn.Config(k=3)).fit(x, y).predict(x), y)
    broken = x.copy()
    broken[0, 0] = np.nan
    with pytest.raises(ValueError, match=r"features.*NaN or infinite.*row 0"):
        Knn(Knn.Config(k=3)).fit(broken, y)
    query = x.copy()
    query[25, 1] = np.inf
    with pytest.raises(ValueError, match=r"features.*NaN or infinite.*row 25"):
        Knn(Knn.Config(k=3)).fit(x, y).predict(query)


def test_figures_keep_the_callers_matplotlib_backend(tmp_path: Path) -> None:
    """A script or notebook that plots with pyplot keeps its backend (an interactive one there;
    svg here) when it draws with mdframework.figures or writes a run's figures; a process
    that has not imported pyplot (the command line) draws with Agg, as before."""
    script = f"""
import matplotlib
matplotlib.use("svg")
import matplotlib.pyplot as plt
import numpy as np
from mdframework.figures import draw_spectrogram, save, style
with style() as p:
    fig, ax = p.subplots(layout="constrained")
    draw_spectrogram(ax, np.zeros((8, 4), np.float32), np.arange(4.0), np.arange(8.0) - 4)
    save(fig, {str(tmp_path / "a.png")!r})
print(matplotlib.get_backend())
"""
    fresh = """
import matplotlib
from mdframework.figures import style
with style() as plt:
    pass
print(matplotlib.get_backend())
"""
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    for code, backend in ((script, "svg"), (fresh, "agg")):
        out = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
        )
        assert out.stdout.strip().lower() == backend
    assert (tmp_path / "a.png").stat().st_size > 0


def test_spectrogram_of_a_2d_signal_names_the_shape() -> None:
    from mdframework.physics.spectrogram import spectrogram

    t = np.arange(4096) / 2400.0
    signal = np.exp(2j * np.pi * 300.0 * t)
    spec = spectrogram(signal, 2400.0)
    assert spec.doppler[np.argmax(spec.power[:, 0])] == pytest.approx(300.0)
    # a row vector from MATLAB; one column per receive channel
    for shaped in (signal[None, :], np.stack([signal, signal], axis=1)):
        with pytest.raises(
            ValueError, match=r"one channel, \(n_samples,\).*" + re.escape(str(shaped.shape))
        ):
            spectrogram(shaped, 2400.0)


def test_sklearn_refusal_says_how_python_allows_other_estimators() -> None:
    from mdf_sklearn import SklearnClassifier
    from pydantic import ValidationError

    for path in ("numpy.linalg.norm", "sklearn.linear_model.LinearRegression"):
        with pytest.raises(ValidationError, match=r"in Python: .*context=\{'allow_import': True\}"):
            SklearnClassifier.Config(estimator=path)  # type: ignore[call-arg]
    path = "sklearn.linear_model.LinearRegression"
    allowed = SklearnClassifier.Config.model_validate(
        {"estimator": path}, context={"allow_import": True}
    )
    assert allowed.estimator == path


def test_mie_sphere_rcs_names_a_nan_or_infinite_size() -> None:
    from mdframework.physics.rcs import sphere_rcs_mie

    # a sphere many wavelengths across: the optical pi r^2 to a few per cent
    assert sphere_rcs_mie(0.1, 0.02) == pytest.approx(np.pi * 0.01, rel=0.03)
    for radius, wavelength in ((np.nan, 0.02), (0.1, np.nan), (np.inf, 0.02), (0.1, 0.0)):
        with pytest.raises(ValueError, match="must be positive and finite"):
            sphere_rcs_mie(radius, wavelength)


def test_a_plugin_made_with_a_dict_says_to_validate_it() -> None:
    from mdf_knn import Knn
    from mdf_noise import ReceiverNoise

    x = np.array([[0.0], [1.0], [10.0], [11.0]])
    y = np.array(["a", "a", "b", "b"])
    assert list(Knn(Knn.Config(k=1)).fit(x, y).predict(x)) == list(y)
    for cls, section in ((Knn, {"k": 1}), (ReceiverNoise, {"snr_db": 10.0})):
        name = cls.__name__
        with pytest.raises(TypeError, match=rf"{name}\.Config\.model_validate.*got dict"):
            cls(section)  # type: ignore[arg-type]


def test_a_plugin_built_from_a_plain_dict_says_to_validate_it() -> None:
    """docs/plugins.md: the base class's __init__ refuses a config section as read (a dict)
    with a TypeError naming the plugin's Config, which validates it."""
    from mdf_lfm import LfmPulseDoppler

    with pytest.raises(TypeError, match=r"^LfmPulseDoppler takes an instance of LfmPulseDoppler"):
        LfmPulseDoppler({"kind": "lfm"})  # type: ignore[arg-type]
    radar = LfmPulseDoppler(LfmPulseDoppler.Config.model_validate({"kind": "lfm"}))
    assert radar.config.kind == "lfm"


def test_a_data_file_error_pickles_with_its_file_line_and_message() -> None:
    """An error raised in a worker process (a dataset build's, or the child that plays an .oni
    recording) reaches the command as it was raised: a DataFileError's own arguments pickle."""
    import pickle

    from mdframework import DataFileError

    error = DataFileError("./walk.bvh", "frame 3 has 5 values", line=12)
    again = pickle.loads(pickle.dumps(error))
    assert type(again) is DataFileError
    assert str(again) == str(error) == "./walk.bvh:12: frame 3 has 5 values"
    assert (again.path, again.line, again.message) == (Path("walk.bvh"), 12, error.message)


def test_a_plugin_made_without_a_config_takes_its_defaults() -> None:
    """`Knn()` is `Knn(Knn.Config())` (it was a TypeError: a missing argument), as a config
    section holding only the kind means; a plugin whose config has required fields says which."""
    from mdf_cmu import CmuSource
    from mdf_knn import Knn
    from mdf_lfm import LfmPulseDoppler

    assert Knn().config == Knn.Config() and Knn().config.k == 5
    radar = LfmPulseDoppler()
    assert (radar.prf, radar.carrier_frequency) == (2400.0, 15e9)  # the paper's radar
    with pytest.raises(TypeError) as info:
        CmuSource()
    assert str(info.value) == (
        "CmuSource() needs a config: file has no default; give CmuSource(CmuSource.Config(...))"
    )
