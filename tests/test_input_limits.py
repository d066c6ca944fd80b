"""Input limits (issue 10): every numeric config field finite and bounded, config files decoded
and size/depth-limited, readers that check declared counts before they allocate, classifiers and
Dask schedulers that a shared config cannot choose."""

from __future__ import annotations

import json
import math
import os
import socket
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import EXAMPLES, project_distributions
from pydantic import BaseModel

from mdframework import ConfigError, DataFileError, MdfError, SceneError, limits
from mdframework.cluster import (
    SCHEDULER_ENV,
    SCHEDULER_TIMEOUT_ENV,
    check_scheduler_address,
    connect,
    scheduler_address,
    scheduler_timeout,
)
from mdframework.config import read_config_file, run_config_model, validate_run_config
from mdframework.dataset import DatasetConfig
from mdframework.docgen import numeric_ranges
from mdframework.experiment import ExperimentConfig
from mdframework.interfaces import PluginConfig
from mdframework.plugins import default_registry
from mdframework.settings import StrictModel

#: Fields that may be infinite on purpose (documented in their description).
INFINITE_ALLOWED = {("ShadowingConfig", "attenuation_db")}


def _config_models() -> list[type[BaseModel]]:
    """The project's config models (a third party's plugins installed beside ours keep their
    own rules)."""
    reg = default_registry().provided_by(project_distributions())
    classifiers = [reg.plugins["classifier"][n].cls.Config for n in reg.names("classifier")]
    return [run_config_model(reg), DatasetConfig, ExperimentConfig, *classifiers]


def _schemas() -> list[tuple[str, str, dict[str, Any]]]:
    out = []
    for model in _config_models():
        schema = model.model_json_schema()
        for name, definition in [(model.__name__, schema), *schema.get("$defs", {}).items()]:
            for field, prop in definition.get("properties", {}).items():
                out.append((name, field, prop))
    return out


def test_every_numeric_config_field_is_bounded_on_both_sides() -> None:
    numeric = 0
    for model, field, prop in _schemas():
        ranges = numeric_ranges(prop)
        numeric += bool(ranges)
        if (model, field) in INFINITE_ALLOWED:
            continue
        assert ranges == [r for r in ranges if "inf" not in r], (model, field, ranges)
    assert numeric > 80  # the walk found the numbers (radar, scene, effects, datasets, ...)


def _all_models(model: type[BaseModel], seen: set[type[BaseModel]]) -> None:
    if model in seen:
        return
    seen.add(model)
    for field in model.model_fields.values():
        stack = [field.annotation]
        while stack:
            t = stack.pop()
            if isinstance(t, type) and issubclass(t, BaseModel):
                _all_models(t, seen)
            stack.extend(getattr(t, "__args__", ()))


def test_every_config_model_refuses_inf_and_nan() -> None:
    seen: set[type[BaseModel]] = set()
    for model in _config_models():
        _all_models(model, seen)
    assert len(seen) > 20
    for model in seen:
        assert model.model_config.get("allow_inf_nan") is False, model
    # a field-level exception must be one of the documented ones
    for model in seen:
        for name, field in model.model_fields.items():
            allow = [m for m in field.metadata if getattr(m, "allow_inf_nan", None) is True]
            if allow:
                assert (model.__name__, name) in INFINITE_ALLOWED


@pytest.mark.parametrize("value", [math.inf, -math.inf, math.nan])
def test_non_finite_values_are_refused_in_every_section(value: float) -> None:
    base = {
        "motion": {"kind": "point_targets", "length": 1.0, "targets": [{"position": [50, 0, 0]}]},
        "scatterers": {"kind": "points"},
    }
    for path in (
        ("radar", "prf"),
        ("radar", "carrier_frequency"),
        ("radar", "bandwidth"),
        ("motion", "length"),
        ("scene", "min_range"),
        ("processing", "floor_db"),
        ("conditioning", "max_speed_mps"),
    ):
        cfg = json.loads(json.dumps(base))
        cfg.setdefault(path[0], {"kind": "lfm"} if path[0] == "radar" else {})[path[1]] = value
        with pytest.raises(ConfigError, match=rf"{path[0]}\.{path[1]}:"):
            validate_run_config(cfg)


def test_the_pulse_limit_names_the_memory_a_run_would_take() -> None:
    cfg = {
        "motion": {
            "kind": "point_targets",
            "length": 3000.0,
            "targets": [{"position": [50, 0, 0]}],
        },
        "scatterers": {"kind": "points"},
        "radar": {"kind": "lfm", "prf": 2400.0},
    }
    with pytest.raises(ConfigError) as exc:
        validate_run_config(cfg)
    n = math.floor(3000.0 * 2400.0) + 1  # 7.2e6 pulses
    mib = n * (8 + 8 + 16 + 8) / 1024**2  # time, gate, complex signal, STFT input
    assert f"{n:.4g} pulses" in str(exc.value)
    assert f"about {mib:.3g} MiB of memory)" in str(exc.value)
    assert "motion.duration" in str(exc.value)
    # keeping every scatterer adds what a block holds per scatterer and pulse (mdf check's)
    cfg["processing"] = {"keep_scatterers": True}
    with pytest.raises(ConfigError) as exc:
        validate_run_config(cfg)
    gib = n * (8 + 8 + 16 + 8 + 160 * 1) / 1024**3
    assert f"about {gib:.3g} GiB of memory, keeping 1 scatterer(s) per pulse" in str(exc.value)
    del cfg["processing"]
    # just below the limit the config is valid
    cfg["motion"]["length"] = (limits.MAX_PULSES - 2) / 2400.0
    validate_run_config(cfg)
    # a window of a recording whose length is known only once it is loaded: checked by the run
    with pytest.raises(SceneError, match="pulses"):
        limits.check_pulses(1000.0, 1e7, 17, "motion.duration")


# ----------------------------------------------------------------------------- config files

GOOD = 'seed = 1\n[motion]\nkind = "point_targets"\nlength = 1.0\n'


def test_utf8_with_or_without_bom_is_read(tmp_path: Path) -> None:
    for name, data in (
        ("plain.toml", GOOD.encode("utf-8")),
        ("bom.toml", GOOD.encode("utf-8-sig")),
        ("accents.toml", ("# café, Δt\n" + GOOD).encode("utf-8")),
        ("bom.json", json.dumps({"seed": 1}).encode("utf-8-sig")),
        ("bom.yaml", "seed: 1\n".encode("utf-8-sig")),
    ):
        (tmp_path / name).write_bytes(data)
        assert read_config_file(tmp_path / name)["seed"] == 1


def test_other_encodings_are_refused_naming_the_file(tmp_path: Path) -> None:
    for name, data, msg in (
        ("u16.toml", GOOD.encode("utf-16"), "UTF-16"),
        ("u16be.toml", GOOD.encode("utf-16-be"), "NUL byte"),
        ("latin1.toml", ("# caf\xe9\n" + GOOD).encode("latin-1"), "line 1: not UTF-8"),
    ):
        (tmp_path / name).write_bytes(data)
        with pytest.raises(ConfigError, match=msg) as exc:
            read_config_file(tmp_path / name)
        assert str(exc.value).startswith(str(tmp_path / name))


@pytest.mark.parametrize("fmt", ["json", "toml", "yaml"])
def test_nesting_is_limited_at_the_documented_depth(tmp_path: Path, fmt: str) -> None:
    def nested(depth: int) -> str:  # the top-level table is depth 1
        inner = "[" * (depth - 1) + "]" * (depth - 1)
        return {"json": f'{{"x": {inner}}}', "toml": f"x = {inner}\n", "yaml": f"x: {inner}\n"}[fmt]

    ok = tmp_path / f"ok.{fmt}"
    ok.write_text(nested(limits.MAX_CONFIG_DEPTH))
    read_config_file(ok)
    deep = tmp_path / f"deep.{fmt}"
    deep.write_text(nested(limits.MAX_CONFIG_DEPTH + 1))
    with pytest.raises(ConfigError, match="nested more than"):
        read_config_file(deep)
    deeper = tmp_path / f"deeper.{fmt}"
    deeper.write_text(nested(100_000))  # would overflow the parser's stack
    with pytest.raises(ConfigError, match="nested more than"):
        read_config_file(deeper)


def test_yaml_aliases_that_expand_exponentially_are_refused_at_once(tmp_path: Path) -> None:
    """A "billion laughs" YAML config (aliases of aliases: 10 ** 10 values in 400 bytes) is
    refused in seconds naming the file (the nesting check walked every expanded value, and
    hung); aliases that a config may reasonably use still read."""
    lines = ["a0: &a0 [" + ", ".join(["1"] * 10) + "]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, 10)]
    laughs = tmp_path / "laughs.yaml"
    laughs.write_text("\n".join(lines) + "\nseed: *a9\n")
    t0 = time.perf_counter()
    with pytest.raises(ConfigError, match="YAML aliases") as exc:
        read_config_file(laughs)
    assert time.perf_counter() - t0 < 30
    assert str(exc.value).startswith(f"{laughs}: more than {limits.MAX_CONFIG_BYTES:,} values")
    few = tmp_path / "few.yaml"
    few.write_text("\n".join(lines[:3]) + "\nseed: *a2\n")  # 1,000 values
    assert len(read_config_file(few)["seed"]) == 10


def test_config_size_is_limited(tmp_path: Path) -> None:
    big = tmp_path / "big.toml"
    big.write_text(GOOD + "# " + "x" * limits.MAX_CONFIG_BYTES + "\n")
    with pytest.raises(ConfigError, match="at most"):
        read_config_file(big)


# ------------------------------------------------------------------------------------ readers


def test_a_huge_declared_frame_count_allocates_nothing(tmp_path: Path) -> None:
    """A BVH header announcing the maximum frame count over 20 frames of data: the error comes
    without allocating the (10^7 x 96 float64 = 7.7 GB) array the header asks for."""
    from helpers import data_error_and_peak
    from mdf_cmu.bvh import read_bvh

    lines = (EXAMPLES / "data" / "cmu" / "bvh" / "16_21.bvh").read_text().splitlines(True)
    at = next(i for i, ln in enumerate(lines) if ln.startswith("Frames:"))
    lines[at] = f"Frames: {limits.MAX_FRAMES}\n"
    path = tmp_path / "16_21.bvh"
    path.write_text("".join(lines[: at + 22]))
    error, peak = data_error_and_peak(lambda: read_bvh(path))
    assert "truncated: 20 frames found" in str(error)
    assert peak < 50e6
    lines[at] = f"Frames: {limits.MAX_FRAMES + 1}\n"
    path.write_text("".join(lines))
    with pytest.raises(DataFileError, match=rf"16_21\.bvh:{at + 1}: 'Frames:' .* exceeds"):
        read_bvh(path)


def test_check_values_names_the_first_bad_line() -> None:
    values = np.zeros((5, 3))
    values[3, 1] = 2e4
    with pytest.raises(DataFileError, match=r"f\.txt:14: coordinate 20000\.0 is beyond"):
        limits.check_values("f.txt", values, 1e4, "coordinate", [10, 11, 12, 14, 15])
    values[1, 2] = np.nan
    with pytest.raises(DataFileError, match=r"f\.txt:11: coordinate nan is not finite"):
        limits.check_values("f.txt", values, 1e4, "coordinate", lambda k: 10 + k)
    values[3, 1] = 0.0
    limits.check_values("f.txt", values, 1e4, "coordinate", allow_nan=True)
    values[2, 0] = -np.inf
    with pytest.raises(DataFileError, match="-inf is not finite"):
        limits.check_values("f.txt", values, 1e4, "coordinate", allow_nan=True)


def test_time_stamps_need_two_distinct_finite_values() -> None:
    limits.check_time_stamps("t", np.array([0.0, 0.0, 0.1]))
    for t, msg in (
        ([0.5], "only 1 frame"),
        ([0.5, 0.5, 0.5], "same time stamp"),
        ([0.0, np.inf], "not finite"),
        ([0.0, 1e6], "beyond"),
    ):
        with pytest.raises(DataFileError, match=msg):
            limits.check_time_stamps("t", np.array(t))


# ------------------------------------------------------------------- code and hosts from configs


def test_dask_scheduler_comes_from_the_command_line_or_the_environment(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.delenv(SCHEDULER_ENV, raising=False)
    assert scheduler_address(None) is None
    monkeypatch.setenv(SCHEDULER_ENV, "tcp://10.0.0.1:8786")
    assert scheduler_address(None) == "tcp://10.0.0.1:8786"
    assert scheduler_address("local") == "local"  # the command line wins
    cfg = tmp_path / "ds.toml"
    cfg.write_text('scheduler = "tcp://10.0.0.1:8786"\n[[sources]]\nlabel = "a"\nmotion = {}\n')
    from mdframework.dataset import load_dataset_config

    with pytest.raises(ConfigError, match="scheduler: a shared config cannot choose"):
        load_dataset_config(cfg)


def test_an_unreachable_scheduler_is_a_clear_error_after_the_timeout(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from distributed import Client

    with socket.socket() as s:  # a port with nothing listening
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    monkeypatch.setenv(SCHEDULER_TIMEOUT_ENV, "1.5")
    t0 = time.monotonic()
    with pytest.raises(MdfError, match=r"cannot connect to the Dask scheduler .* within 1\.5 s"):
        connect(Client, None, f"tcp://127.0.0.1:{port}")
    assert time.monotonic() - t0 < 20  # not the 30 s default
    monkeypatch.setenv(SCHEDULER_TIMEOUT_ENV, "soon")
    with pytest.raises(MdfError, match=SCHEDULER_TIMEOUT_ENV):
        connect(Client, None, f"tcp://127.0.0.1:{port}")


@pytest.mark.parametrize(
    ("text", "seconds"),
    [(None, 10.0), ("0.5", 0.5), ("3600", 3600.0), ("0", None), ("3601", None), ("nan", None)],
)
def test_the_scheduler_timeout_is_a_positive_number_up_to_an_hour(
    monkeypatch: pytest.MonkeyPatch, text: str | None, seconds: float | None
) -> None:
    """MDF_DASK_TIMEOUT: 0 < t <= 3600 s (0 would give up on every scheduler at once; the
    default 10 s when it is not set)."""
    if text is None:
        monkeypatch.delenv(SCHEDULER_TIMEOUT_ENV, raising=False)
    else:
        monkeypatch.setenv(SCHEDULER_TIMEOUT_ENV, text)
    if seconds is not None:
        assert scheduler_timeout() == seconds
        return
    with pytest.raises(MdfError) as err:
        scheduler_timeout()
    assert str(err.value) == (
        f"MDF_DASK_TIMEOUT={text!r}: give a timeout in seconds, 0 < t <= 3600"
    )


def test_a_malformed_scheduler_address_is_refused_before_any_connection(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Hard case: `--scheduler nonsense` used to start a Dask client (and its event-loop
    thread, left running) and fail inside it, after the output folder was made."""
    import threading

    before = set(threading.enumerate())
    for good in (None, "local", "tcp://10.0.0.1:8786", "10.0.0.1:8786", "tcp://[::1]:8786"):
        check_scheduler_address(good)
    for bad in ("nonsense", "tcp://host", "tls://:x", "tpc://10.0.0.1:8786"):
        with pytest.raises(MdfError, match="not an address"):
            check_scheduler_address(bad)
    assert set(threading.enumerate()) == before  # nothing was started
    monkeypatch.setenv(SCHEDULER_TIMEOUT_ENV, "soon")
    check_scheduler_address("local")  # no connection, no timeout
    with pytest.raises(MdfError, match=SCHEDULER_TIMEOUT_ENV):
        check_scheduler_address("tcp://10.0.0.1:8786")


def test_a_server_that_is_not_a_dask_scheduler_is_a_clear_error(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Hard case: an address where something else answers (here a web server's reply; a proxy
    did this to an unreachable address) made Dask read a frame length of 3.5e18 bytes, a
    MemoryError and an internal error. Now a one-line error names the address."""
    import threading

    from distributed import Client

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(4)
    port = server.getsockname()[1]

    def answer() -> None:
        while True:
            try:
                conn, _ = server.accept()
            except OSError:
                return
            with conn:
                conn.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n" * 4)

    threading.Thread(target=answer, daemon=True).start()
    monkeypatch.setenv(SCHEDULER_TIMEOUT_ENV, "3")
    try:
        with pytest.raises(MdfError, match=rf"127\.0\.0\.1:{port}"):
            connect(Client, None, f"tcp://127.0.0.1:{port}")
    finally:
        server.close()


def test_plugin_configs_inherit_the_finite_rule() -> None:
    class Mine(PluginConfig):
        kind: str = "mine"
        gain: float = 1.0

    with pytest.raises(ValueError, match="finite"):
        Mine(gain=math.inf)

    class Strict(StrictModel):
        x: float = 0.0

    with pytest.raises(ValueError, match="finite"):
        Strict(x=math.nan)


def test_a_spectrogram_beyond_the_limit_is_refused_before_any_pulse(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A config asking for a spectrogram of trillions of values (1 MHz PRF, a hop of 1 pulse,
    2**20 Doppler bins): `mdf check` called it valid and `mdf run` simulated every pulse, then
    failed with an internal MemoryError (or, short of that, filled the memory). Both refuse it
    with one line naming processing.hop, and the --set that gave it; the largest allowed one
    passes."""
    from mdframework import cli

    walk = str(EXAMPLES / "cmu_walk.toml")
    huge = ["radar.prf=1000000", "radar.pulse_width=1e-7", "processing.nfft=1048576",
            "processing.window_length=65536", "processing.hop=1"]  # fmt: skip
    sets = [a for kv in huge for a in ("--set", kv)]
    out = tmp_path / "out"
    for argv in (["check", walk, *sets], ["run", walk, "--out", str(out), *sets]):
        assert cli.main(argv) == 2
        (line,) = capsys.readouterr().err.strip().splitlines()
        assert "error: --set processing.hop=1: processing.hop: the spectrogram of 1048576 " in line
        assert f"the limit is {limits.MAX_SPECTROGRAM_CELLS:,}" in line
    assert not out.exists()
    fields = ("processing.hop", "raise processing.hop")
    limits.check_spectrogram_cells(2**20, 2**10, 4, fields)  # at the limit
    with pytest.raises(SceneError, match=r"1\.075e\+09 values \(about 4 GiB of memory\)"):
        limits.check_spectrogram_cells(2**20, 2**10 + 1, 4, fields)  # a frame over it


def test_an_fmcw_spectrogram_beyond_the_limit_names_the_fields_that_set_its_size(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An FMCW radar with gaps between its frames makes one spectrum per frame of
    processing.nfft bins: processing.hop does not change its size, so the limit's message names
    radar.frame_period (one column per frame) and processing.nfft instead (40 s of 33.3 ms
    frames, 2**20 bins: 1.26e9 values)."""
    from mdframework import cli

    cfg = tmp_path / "fmcw.toml"
    cfg.write_text(
        '[motion]\nkind = "point_targets"\nlength = 40.0\n'
        "targets = [{ position = [3.0, 0.0, 0.0], velocity = [0.0, 0.0, 0.0], rcs = 1.0 }]\n"
        '[scatterers]\nkind = "points"\n'
        '[radar]\nkind = "fmcw"\npreset = "iwr1443_short_range_3d"\n'
        "[scene]\nradar_position = [0.0, 0.0, 0.0]\ngate = 3.0\n"
        "[processing]\nnfft = 1048576\n"
    )
    assert cli.main(["check", str(cfg)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith(
        f"mdf: error: {cfg}: radar.frame_period: the spectrogram of 1048576 Doppler bins x "
        "1200 frames is 1.258e+09 values"
    )
    assert line.endswith("raise radar.frame_period, lower processing.nfft or shorten the record")
    assert "hop" not in line


def test_check_regular_file_follows_links_and_names_a_folder(tmp_path: Path) -> None:
    """A link to a regular file is read as that file; a folder and a missing file are
    refused naming the path and what is wrong."""
    (tmp_path / "walk.bvh").write_text("HIERARCHY\n")
    (tmp_path / "link.bvh").symlink_to(tmp_path / "walk.bvh")
    limits.check_regular_file(tmp_path / "link.bvh")
    with pytest.raises(DataFileError, match="cannot read: a folder"):
        limits.check_regular_file(tmp_path)
    with pytest.raises(DataFileError, match="cannot read: No such file"):
        limits.check_regular_file(tmp_path / "gone.bvh")


@pytest.mark.parametrize(
    ("kind", "name"),
    [("cmu", "walk.bvh"), ("table", "walk.csv"), ("table", "walk.npz"), ("c3d", "walk.c3d")],
)
@pytest.mark.parametrize("special", ["fifo", "dev-zero"])
def test_a_motion_file_that_is_a_pipe_or_a_device_is_refused_unread(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], kind: str, name: str, special: str
) -> None:
    """A received folder's motion file that is a named pipe, or a link to ``/dev/zero``: the
    run waited forever on the pipe, or read zeros until the memory ran out (an internal
    MemoryError); a binary one (table .npz, C3D) waited on the pipe too. It is one line naming
    the file, exit 2, before the file is opened."""
    from mdframework import cli

    path = tmp_path / name
    if special == "fifo":
        os.mkfifo(path)
    else:
        path.symlink_to("/dev/zero")
    out = tmp_path / "out"
    argv = ["run", str(EXAMPLES / "cmu_walk.toml"), "--out", str(out)]
    assert cli.main([*argv, "--set", f"motion.kind={kind}", "--set", f"motion.file={path}"]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line == f"mdf: error: {path}: cannot read: not a regular file (a pipe or a device?)"
    assert not out.exists()


def test_the_documented_limits_are_the_code_s() -> None:
    import re

    from conftest import ROOT

    from mdframework.cluster import SCHEDULER_TIMEOUT_S, scheduler_timeout

    page = (ROOT / "docs" / "input-rules.md").read_text()
    rows = re.findall(r"^\| `([A-Z0-9_]+)` \| ([0-9.e+-]+) \|", page, flags=re.M)
    names = {n for n in dir(limits) if n.isupper() and not n.startswith("_")}
    assert {name for name, _ in rows} == names  # every limit documented, nothing else
    for name, value in rows:
        assert float(value) == getattr(limits, name), name
    assert f"`MDF_DASK_TIMEOUT` seconds (default {SCHEDULER_TIMEOUT_S:g})" in page
    assert scheduler_timeout() == SCHEDULER_TIMEOUT_S == 10


def test_a_numerical_warning_in_our_code_stops_the_command(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """An overflow inside mdframework (or a plugin) is never a bare warning followed by a
    result: the command stops with one line and exit 1 (an internal error: valid inputs never
    cause one)."""
    from mdframework import cli

    namespace: dict[str, Any] = {"__name__": "mdframework.stage", "np": np}
    exec("def stage(args):\n    return int(np.float64(1e308) * 10.0 > 0)\n", namespace)
    monkeypatch.setattr(cli, "_cmd_plugins", namespace["stage"])
    assert cli.main(["plugins"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "overflow encountered" in err[0], err
    assert "Traceback" not in err[0]


@pytest.mark.parametrize("name", ["points.txt", "points.txt.gz", "points.npz"])
def test_a_radar_recording_that_is_a_pipe_is_refused_unread(tmp_path: Path, name: str) -> None:
    """A real radar's recording (RadHAR text, gzip text, compact NPZ) that is a named pipe:
    reading it waited forever; it is refused naming the file before it is opened."""
    from mdf_radhar.source import npz_recordings, read_rostopic_text

    from mdframework.errors import DataFileError

    path = tmp_path / name
    os.mkfifo(path)
    reader = npz_recordings if name.endswith(".npz") else read_rostopic_text
    with pytest.raises(DataFileError, match="not a regular file") as caught:
        reader(path)
    assert str(path) in str(caught.value)


def test_an_oni_recording_that_is_a_pipe_is_refused_unread(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`mdf kinect info` on an .oni "recording" that is a named pipe waited forever in the
    structure scan; one line naming it, exit 2."""
    from mdframework import cli

    path = tmp_path / "take.oni"
    os.mkfifo(path)
    assert cli.main(["kinect", "info", str(path)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line == f"mdf: error: {path}: cannot read: not a regular file (a pipe or a device?)"


@pytest.mark.parametrize(
    ("name", "what"),
    [
        ("big.bvh", "a BVH file"),
        ("big.asf", "an ASF file"),
        ("big.amc", "an AMC file"),
        ("big.trc", "a TRC text file"),
        ("joints_s01_e01.txt", "a text skeleton file"),
        ("big.csv", "a text table"),
    ],
)
def test_a_motion_capture_text_file_beyond_the_size_limit_is_refused_unread(
    tmp_path: Path, name: str, what: str
) -> None:
    """A BVH, ASF, AMC, TRC, Kinect text or text table file had no size limit: a huge one was
    read whole (about 13 times its size in memory for an AMC) and ended in an internal
    MemoryError. One over MAX_MOTION_TEXT_BYTES (a sparse file, holding nothing) is refused
    naming the file and the limit, before it is read; the shipped files are far below it."""
    from helpers import data_error_and_peak
    from mdf_c3d.trc import read_trc
    from mdf_cmu.asfamc import read_amc, read_asf
    from mdf_cmu.bvh import read_bvh
    from mdf_kinect.formats import read_utkinect
    from mdf_table.reader import read_table

    cmu = EXAMPLES / "data" / "cmu"
    path = tmp_path / name
    with path.open("wb") as fh:
        fh.truncate(limits.MAX_MOTION_TEXT_BYTES + 1)
    read = {
        ".bvh": read_bvh,
        ".asf": read_asf,
        ".amc": lambda p: read_amc(p, read_asf(cmu / "asf-amc" / "02.asf")),
        ".trc": read_trc,
        ".txt": read_utkinect,
        ".csv": read_table,
    }[path.suffix]
    error, peak = data_error_and_peak(lambda: read(path))
    assert str(error) == (
        f"{path}: {limits.MAX_MOTION_TEXT_BYTES + 1:,} bytes is beyond the limit of "
        f"{limits.MAX_MOTION_TEXT_BYTES:,} bytes for {what}"
    )
    assert peak < 10 * 2**20
    motion_text = {".bvh", ".asf", ".amc", ".trc", ".txt", ".csv"}
    shipped = [p for p in (EXAMPLES / "data").rglob("*") if p.suffix in motion_text]
    assert max(p.stat().st_size for p in shipped) < limits.MAX_MOTION_TEXT_BYTES / 50


def test_a_radars_wrong_spectrogram_fields_are_named_as_its_bug() -> None:
    """A radar plugin whose ``smaller_spectrogram`` returns something other than a field and
    an advice (one string) is named, as its bug, by the error that its spectrogram beyond the
    limit raises (the tuple was unpacked outside the plugin's blame: an anonymous ValueError)."""
    from mdf_fmcw.waveform import FmcwConfig, FmcwRadar

    from mdframework.pipeline import spectrogram_geometry
    from mdframework.settings import ProcessingConfig

    class Sloppy(FmcwRadar):
        def smaller_spectrogram(self, processing: Any) -> Any:
            return "radar.frame_period"

    wf = Sloppy(FmcwConfig(preset="iwr1443_short_range_3d"))
    n_pulses = 1200 * wf.sequence.chirps_per_frame
    with pytest.raises(ValueError) as caught:
        spectrogram_geometry(wf, n_pulses, ProcessingConfig(nfft=2**20))
    assert "in smaller_spectrogram() of the radar plugin" in caught.value.__notes__[0]
    from mdframework.testing import check_radar_waveform

    with pytest.raises(AssertionError, match=r"smaller_spectrogram\(\) must give"):
        check_radar_waveform(wf)  # the check that the note points to finds it
    check_radar_waveform(FmcwRadar(FmcwConfig(preset="iwr1443_short_range_3d")))


def test_check_file_size_allows_the_limit_itself_and_names_a_file_it_cannot_examine(
    tmp_path: Path,
) -> None:
    """limits.check_file_size refuses a file of more than max_bytes: one of exactly max_bytes
    passes, one byte more is refused naming the file, its size and the limit; a file that
    cannot be examined (missing) is a DataFileError naming it too, not an OSError."""
    from mdframework import DataFileError, limits

    path = tmp_path / "m.bvh"
    path.write_bytes(b"x" * 100)
    limits.check_file_size(path, "a BVH file", 100)
    with pytest.raises(DataFileError) as err:
        limits.check_file_size(path, "a BVH file", 99)
    assert str(err.value) == f"{path}: 100 bytes is beyond the limit of 99 bytes for a BVH file"
    with pytest.raises(DataFileError, match=r"missing\.bvh: cannot read"):
        limits.check_file_size(tmp_path / "missing.bvh", "a BVH file", 100)


def test_the_echo_power_limits_are_inclusive_and_refuse_nan() -> None:
    """limits.check_echo_power takes echoes from MIN_ECHO_POWER_W to MAX_ECHO_POWER_W, both
    included, and refuses anything beyond either (1.01 times the largest, 0.99 times the
    smallest) and NaN, naming the field it is given."""
    for power in (limits.MAX_ECHO_POWER_W, limits.MIN_ECHO_POWER_W, 1.0):
        limits.check_echo_power(power)
    for power in (1.01 * limits.MAX_ECHO_POWER_W, 0.99 * limits.MIN_ECHO_POWER_W, math.nan):
        with pytest.raises(SceneError, match=r"^radar\.transmit_power: the echo of 1 m\^2 at 1 m"):
            limits.check_echo_power(power, "radar.transmit_power")
