"""Labelled datasets of simulated records, built in parallel, resumable, deterministic.

A dataset config lists motion sources with their activity labels, cuts long recordings into
records of a fixed length, and multiplies them by scene variations (aspect angle, radar range and
height, the person's height for sources that have one). Every record is one run of the pipeline
followed by the seven features. ``build_dataset`` writes::

    DIR/records/<id>.npz   one file per record, written atomically (temp file + rename):
                           spectrogram_db (n_doppler, n_frames) float32 [dB re peak],
                           velocity_mps (n_doppler,), time_s (n_frames,), features (7,) [m/s],
                           meta: JSON string (label, source, file, window, scene, radar, units)
    DIR/index.csv          one row per record: id, label, source, file, start_s, duration_s,
                           aspect_deg, radar_x/y/z_m, height_m, seed, then the 7 features
    DIR/dataset.json       the config, the feature names and units, the record count

Records are independent pure functions of their spec (including a seed derived from the
dataset seed and the record's index), so the result is identical whatever the number of workers
or the scheduler. A killed build, run again, keeps every complete record, removes temp files and
redoes records whose file is missing or unreadable.
"""

from __future__ import annotations

import csv
import hashlib
import io
import itertools
import json
import os
import tempfile
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, ValidationError, model_validator

from . import limits
from .config import format_validation_error, read_config_file, validate_run_config
from .errors import ConfigError, MdfError
from .features import FEATURE_NAMES, spectrogram_features
from .interfaces import Motion
from .pipeline import build_stages, load_motion, simulate_motion
from .settings import (
    AngleDeg,
    BelowPeakDb,
    Coordinate,
    Distance,
    Point3,
    PositiveSeconds,
    Seed,
    StrictModel,
    Workers,
)

RECORDS = "records"
#: index.csv columns that hold text (all others are numbers)
TEXT_COLUMNS = ("id", "label", "group", "source", "file")
INDEX = "index.csv"
MANIFEST = "dataset.json"
#: Environment variables that choose a Dask scheduler (when --scheduler is not given) and its
#: connection timeout [s].
SCHEDULER_ENV = "MDF_DASK_SCHEDULER"
SCHEDULER_TIMEOUT_ENV = "MDF_DASK_TIMEOUT"
#: Default connection timeout to a Dask scheduler [s].
SCHEDULER_TIMEOUT_S = 10.0

#: A percentile (0 .. 100).
Percent = Annotated[float, Field(ge=0, le=100)]


class FeatureConfig(StrictModel):
    """How the seven features are extracted (see :mod:`mdframework.features`)."""

    method: Literal["threshold", "percentile"] = Field("threshold", description="Envelopes.")
    threshold_db: BelowPeakDb = Field(-20.0, description="Threshold below each column's peak.")
    floor_db: BelowPeakDb = Field(-40.0, description="Ignore bins this far below the peak.")
    percentiles: tuple[Percent, Percent] = Field((3.0, 97.0), description="Percentile method.")
    torso: Literal["median", "peak"] = Field(
        "median", description="Torso track: the column's power median, or its peak bin."
    )


class SourceEntry(StrictModel):
    """One recording (or generator) and its label."""

    label: str = Field(description="Activity label, e.g. 'walk'.")
    motion: dict[str, Any] = Field(description="A [motion] section (with its kind).")
    group: str | None = Field(
        None, description="Source group for cross-source experiments; default: motion.kind."
    )
    record_length: PositiveSeconds | None = Field(
        None, description="Record length [s]; default: record_lengths[label], else all."
    )
    hop: PositiveSeconds | None = Field(
        None, description="Step between records [s]; default: length."
    )
    max_records: int | None = Field(
        None, ge=1, le=limits.MAX_RECORDS, description="At most this many windows."
    )
    run: dict[str, Any] = Field(
        default_factory=dict,
        description="Run-config sections for this source only, merged over `base` (e.g. "
        "conditioning for Kinect recordings, or its own scene).",
    )


class Variations(StrictModel):
    """Scene variations; every combination multiplies every record."""

    aspect_deg: list[AngleDeg] | None = Field(
        None,
        description="Facing relative to the radar [deg]; default: as the (base) scene says.",
    )
    radar_range: list[Distance] | None = Field(
        None, description="Horizontal distance radar - person's start [m]; default: base scene."
    )
    radar_height: list[Coordinate] | None = Field(None, description="Radar height [m].")
    radar_position: list[Point3] | None = Field(
        None,
        description="Radar positions (x, y, z) [m]; exclusive with radar_range/radar_height.",
    )
    height: list[Annotated[float, Field(gt=0.5, lt=2.5)]] | None = Field(
        None,
        description="Person's height [m] (0.5 .. 2.5), for sources whose config has a `height`.",
    )

    @model_validator(mode="after")
    def _radar_one_way(self) -> Variations:
        if self.radar_position is not None and (
            self.radar_range is not None or self.radar_height is not None
        ):
            raise ValueError("give radar_position, or radar_range/radar_height, not both")
        return self


class DatasetConfig(StrictModel):
    """A dataset: sources, record lengths, variations, shared run settings, build options."""

    seed: Seed = Field(0, description="Seed of the whole dataset.")
    record_lengths: dict[str, PositiveSeconds] = Field(
        default_factory=dict, description="Record length per label [s]."
    )
    sources: list[SourceEntry] = Field(min_length=1)
    variations: Variations = Field(default_factory=Variations)
    base: dict[str, Any] = Field(
        default_factory=dict,
        description="Run-config sections shared by every record (scatterers, radar, scene, "
        "processing, effects).",
    )
    features: FeatureConfig = Field(default_factory=FeatureConfig)
    workers: Workers | None = Field(None, description="Local processes; default: CPU count.")


@dataclass(frozen=True)
class RecordSpec:
    """Everything one worker needs to build one record (picklable)."""

    index: int
    record_id: str
    label: str
    group: str
    run_config: dict[str, Any]
    base_dir: str
    features: dict[str, Any]


def load_dataset_config(path: str | Path) -> tuple[DatasetConfig, Path]:
    """Read and validate a dataset config; returns it and its folder (for relative paths)."""
    p = Path(path)
    data = read_config_file(p)
    if "scheduler" in data:
        raise ConfigError(
            f"{p}: scheduler: a shared config cannot choose where records are computed; give "
            f"the Dask scheduler with --scheduler or the {SCHEDULER_ENV} environment variable"
        )
    try:
        return DatasetConfig.model_validate(data), p.parent
    except ValidationError as exc:
        raise ConfigError(format_validation_error(exc, str(p), data)) from None


@lru_cache(maxsize=8)
def _load_motion(motion_json: str, base_dir: str) -> Motion:
    """Load a motion once per process (records of one recording share it)."""
    section = json.loads(motion_json)
    config = validate_run_config(
        {"motion": section}, source="dataset motion", base_dir=Path(base_dir)
    )
    return load_motion(build_stages(config).source)


def _record_seed(seed: int, index: int) -> int:
    return int(np.random.SeedSequence([seed, index]).generate_state(1)[0])


def _scene_for(base_scene: dict[str, Any], variation: dict[str, Any]) -> dict[str, Any]:
    """The scene of one record: the (base) scene with only the varied fields replaced."""
    scene: dict[str, Any] = json.loads(json.dumps(base_scene))
    if variation["aspect_deg"] is not None:
        person = dict(scene.get("person", {}))
        person.pop("heading_deg", None)  # the aspect replaces any fixed heading
        person["aspect_deg"] = variation["aspect_deg"]
        scene["person"] = person
    if variation["radar_position"] is not None:
        scene["radar_position"] = list(variation["radar_position"])
    if variation["radar_range"] is not None or variation["radar_height"] is not None:
        start = scene.get("person", {}).get("position", (0.0, 0.0))
        radar = list(scene.get("radar_position", (10.0, 0.0, 2.0)))
        if variation["radar_range"] is not None:
            radar[0], radar[1] = start[0] + variation["radar_range"], start[1]
        if variation["radar_height"] is not None:
            radar[2] = variation["radar_height"]
        scene["radar_position"] = radar
    return scene


def _merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    """Deep merge of config dicts: tables merge key by key, other values are replaced."""
    out: dict[str, Any] = json.loads(json.dumps(base))
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = json.loads(json.dumps(value))
    return out


def plan_records(config: DatasetConfig, base_dir: Path) -> list[RecordSpec]:
    """Expand sources x windows x variations into record specs, in a fixed order."""
    v = config.variations
    none: list[Any] = [None]
    grid = list(
        itertools.product(
            v.aspect_deg or none,
            v.radar_range or none,
            v.radar_height or none,
            v.radar_position or none,
            v.height or none,
        )
    )
    specs: list[RecordSpec] = []
    for entry_no, entry in enumerate(config.sources):
        motion = dict(entry.motion)
        if "kind" not in motion:
            raise ConfigError(f"sources[{entry_no}].motion: a kind is required")
        # a source's own start/duration limit the span that records are cut from
        whole = {k: v for k, v in motion.items() if k not in ("start", "duration")}
        loaded = _load_motion(json.dumps(whole, sort_keys=True), str(base_dir))
        span_start = float(motion.get("start", 0.0))
        span_end = loaded.skeleton.duration
        if motion.get("duration") is not None:
            span_end = min(span_end, span_start + float(motion["duration"]))
        duration = span_end - span_start
        length = entry.record_length or config.record_lengths.get(entry.label) or duration
        if length > duration + 1e-9:
            raise ConfigError(
                f"sources[{entry_no}]: record length {length:g} s exceeds the "
                f"{duration:.3f} s recording ({motion.get('file', motion['kind'])})"
            )
        hop = entry.hop or length
        n_windows = int(np.ceil((duration - length + 1e-9) / hop))
        if entry.max_records is not None:
            n_windows = min(n_windows, entry.max_records)
        if len(specs) + n_windows * len(grid) > limits.MAX_RECORDS:
            raise ConfigError(
                f"sources[{entry_no}]: {n_windows:,} windows x {len(grid)} variation(s) take the "
                f"dataset beyond the limit of {limits.MAX_RECORDS:,} records; raise hop or set "
                "max_records"
            )
        starts = float(motion.get("start", 0.0)) + np.arange(n_windows) * hop
        for start in starts:
            for aspect, rng_, rheight, rpos, height in grid:
                section = {**motion, "start": round(float(start), 9), "duration": length}
                if height is not None:
                    section["height"] = height
                run = {**_merge(config.base, entry.run), "motion": section}
                run["scene"] = _scene_for(
                    run.get("scene", {}),
                    {
                        "aspect_deg": aspect,
                        "radar_range": rng_,
                        "radar_height": rheight,
                        "radar_position": rpos,
                    },
                )
                index = len(specs)
                run["seed"] = _record_seed(config.seed, index)
                digest = hashlib.sha1(
                    json.dumps([run, config.features.model_dump()], sort_keys=True).encode()
                ).hexdigest()[:10]
                specs.append(
                    RecordSpec(
                        index,
                        f"{index:05d}-{digest}",
                        entry.label,
                        entry.group or motion["kind"],
                        run,
                        str(base_dir),
                        config.features.model_dump(),
                    )
                )
                # every record's run config is valid before any file is written
                validate_run_config(
                    run, source=f"sources[{entry_no}] record {index}", base_dir=base_dir
                )
    return specs


def build_record(spec: RecordSpec, out_dir: str) -> dict[str, Any]:
    """Simulate one record and write it atomically; returns its index row."""
    config = validate_run_config(
        spec.run_config, source=f"record {spec.record_id}", base_dir=Path(spec.base_dir)
    )
    stages = build_stages(config)
    motion_section = {
        k: v
        for k, v in spec.run_config["motion"].items()
        if k not in ("start", "duration", "height")
    }
    motion_section.update({k: v for k, v in spec.run_config["motion"].items() if k == "height"})
    motion = _load_motion(json.dumps(motion_section, sort_keys=True), spec.base_dir)
    result = simulate_motion(config, stages, motion)
    fcfg = spec.features
    feats = spectrogram_features(
        result.spectrogram.power,
        result.velocity,
        method=fcfg["method"],
        threshold_db=fcfg["threshold_db"],
        floor_db=fcfg["floor_db"],
        percentiles=tuple(fcfg["percentiles"]),
        torso_method=fcfg["torso"],
    )
    cfg: Any = config
    meta = {
        "id": spec.record_id,
        "label": spec.label,
        "group": spec.group,
        "source": result.metadata["motion"].get("source", cfg.motion.kind),
        "file": result.metadata["motion"].get("file", ""),
        "start_s": cfg.motion.start,
        "duration_s": cfg.motion.duration,
        "aspect_deg": cfg.scene.person.aspect_deg,
        "radar_position_m": list(cfg.scene.radar_position),
        "height_m": spec.run_config["motion"].get("height"),
        "seed": cfg.seed,
        "prf_hz": result.metadata["prf_hz"],
        "carrier_frequency_hz": result.metadata["carrier_frequency_hz"],
        "units": {
            "features": "m/s",
            "spectrogram_db": "dB re peak",
            "velocity": "m/s",
            "time": "s",
        },
        "run_config": json.loads(cfg.model_dump_json()),
    }
    _atomic_savez(
        Path(out_dir) / RECORDS / f"{spec.record_id}.npz",
        spectrogram_db=result.spectrogram_db.astype(np.float32),
        velocity_mps=result.velocity,
        time_s=result.spectrogram.time,
        features=feats,
        meta=np.array(json.dumps(meta)),
    )
    return _row(meta, feats)


def _row(meta: dict[str, Any], feats: NDArray[np.float64]) -> dict[str, Any]:
    radar = meta["radar_position_m"]
    row = {
        "id": meta["id"],
        "label": meta["label"],
        "group": meta["group"],
        "source": meta["source"],
        "file": meta["file"],
        "start_s": meta["start_s"],
        "duration_s": meta["duration_s"],
        "aspect_deg": meta["aspect_deg"],
        "radar_x_m": radar[0],
        "radar_y_m": radar[1],
        "radar_z_m": radar[2],
        "height_m": "" if meta["height_m"] is None else meta["height_m"],
        "seed": meta["seed"],
    }
    row.update({name: float(f) for name, f in zip(FEATURE_NAMES, feats, strict=True)})
    return row


def _atomic_savez(path: Path, **arrays: Any) -> None:
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=".npz", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            np.savez(fh, **arrays)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _atomic_write_text(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", dir=path.parent)
    with os.fdopen(fd, "w") as fh:
        fh.write(text)
    os.replace(tmp, path)


def read_record(path: Path) -> tuple[dict[str, NDArray[Any]], dict[str, Any]]:
    """Arrays and metadata of one record file; raises if it is incomplete or corrupt."""
    with np.load(path) as data:
        arrays = {k: data[k] for k in ("spectrogram_db", "velocity_mps", "time_s", "features")}
        meta = json.loads(str(data["meta"]))
    return arrays, meta


def _complete(path: Path) -> dict[str, Any] | None:
    """The index row of a finished record, or None if it must be (re)built."""
    if not path.exists():
        return None
    try:
        arrays, meta = read_record(path)
    except Exception:
        path.unlink(missing_ok=True)
        return None
    return _row(meta, arrays["features"])


def scheduler_address(given: str | None) -> str | None:
    """The Dask scheduler: ``given`` (the command line), else the :data:`SCHEDULER_ENV`
    environment variable, else ``None`` (local processes). Never a config file: a shared config
    must not send work, or data, to a machine of its author's choosing."""
    return given or os.environ.get(SCHEDULER_ENV) or None


def scheduler_timeout() -> float:
    """Connection timeout to a Dask scheduler [s]: :data:`SCHEDULER_TIMEOUT_ENV`, else
    :data:`SCHEDULER_TIMEOUT_S`."""
    text = os.environ.get(SCHEDULER_TIMEOUT_ENV)
    if text is None:
        return SCHEDULER_TIMEOUT_S
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value <= 3600:
        raise MdfError(
            f"{SCHEDULER_TIMEOUT_ENV}={text!r}: give a timeout in seconds, 0 < t <= 3600"
        )
    return value


def _connect(client_cls: Any, cluster: Any, address: str) -> Any:
    """A Dask client of the local cluster or of the scheduler at ``address``; an unreachable
    scheduler is a one-line error after the connection timeout."""
    if cluster is not None:
        return client_cls(cluster)
    timeout = scheduler_timeout()
    try:
        return client_cls(address, timeout=timeout)
    except (OSError, TimeoutError, ValueError, TypeError) as exc:
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise MdfError(
            f"cannot connect to the Dask scheduler {address!r} within {timeout:g} s ({reason}); "
            f"check --scheduler or {SCHEDULER_ENV}, or set {SCHEDULER_TIMEOUT_ENV}"
        ) from None


def _executor(
    config: DatasetConfig, workers: int | None, scheduler: str | None
) -> Iterator[Callable[[list[RecordSpec], str], Iterator[dict[str, Any]]]]:
    """Yield a map function running records locally or on Dask (a generator so that clusters
    are closed afterwards)."""
    address = scheduler_address(scheduler)
    n = workers or config.workers or os.cpu_count() or 1
    if address is None:
        if n == 1:
            yield lambda specs, out: (build_record(s, out) for s in specs)
            return
        with ProcessPoolExecutor(max_workers=n) as pool:

            def run_local(specs: list[RecordSpec], out: str) -> Iterator[dict[str, Any]]:
                futures = [pool.submit(build_record, s, out) for s in specs]
                for fut in as_completed(futures):
                    yield fut.result()

            yield run_local
        return
    try:
        from distributed import Client, LocalCluster
        from distributed import as_completed as dask_completed
    except ImportError:
        raise MdfError("a Dask scheduler needs `pip install mdframework[dask]`") from None
    cluster = (
        LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None)
        if address == "local"
        else None
    )
    client = _connect(Client, cluster, address)
    try:

        def run_dask(specs: list[RecordSpec], out: str) -> Iterator[dict[str, Any]]:
            futures = client.map(build_record, specs, out_dir=out, pure=False)
            for fut in dask_completed(futures):
                yield fut.result()

        yield run_dask
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def build_dataset(
    config: DatasetConfig,
    base_dir: Path,
    out_dir: Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
) -> list[dict[str, Any]]:
    """Build (or finish building) a dataset; returns the index rows in record order."""
    from tqdm import tqdm

    specs = plan_records(config, base_dir)  # errors in the config stop before any file
    out = Path(out_dir)
    (out / RECORDS).mkdir(parents=True, exist_ok=True)
    for stale in (out / RECORDS).glob(".tmp-*"):
        stale.unlink()
    rows: dict[str, dict[str, Any]] = {}
    todo = []
    for spec in specs:
        row = _complete(out / RECORDS / f"{spec.record_id}.npz")
        if row is None:
            todo.append(spec)
        else:
            rows[spec.record_id] = row
    bar = tqdm(
        total=len(specs), initial=len(rows), desc="records", unit="rec", disable=not progress
    )
    for run in _executor(config, workers, scheduler):
        for row in run(todo, str(out)):
            rows[row["id"]] = row
            bar.update(1)
    bar.close()
    ordered = [rows[s.record_id] for s in specs]
    _write_index(out, ordered, config)
    return ordered


def _write_index(out: Path, rows: list[dict[str, Any]], config: DatasetConfig) -> None:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    _atomic_write_text(out / INDEX, buf.getvalue())
    manifest = {
        "n_records": len(rows),
        "feature_names": list(FEATURE_NAMES),
        "feature_units": "m/s",
        "labels": sorted({r["label"] for r in rows}),
        "config": json.loads(config.model_dump_json()),
    }
    _atomic_write_text(out / MANIFEST, json.dumps(manifest, indent=2) + "\n")


@dataclass(frozen=True)
class Dataset:
    """A loaded dataset.

    ``features`` (n_records, 7) float64 [m/s]; ``labels`` (n_records,) str; ``groups``
    (n_records,) str; ``table``: column name -> (n_records,) array (all of index.csv, ready for
    ``pandas.DataFrame(table)``); ``spectrograms``: (n_records, n_doppler, n_frames) float32
    [dB] when all records have the same shape, else a list; ``velocity`` (n_doppler,) [m/s] of
    the first record.
    """

    features: NDArray[np.float64]
    labels: NDArray[np.str_]
    groups: NDArray[np.str_]
    table: dict[str, NDArray[Any]]
    spectrograms: NDArray[np.float32] | list[NDArray[np.float32]] | None
    velocity: NDArray[np.float64] | None


def load_dataset(path: str | Path, *, spectrograms: bool = True) -> Dataset:
    """Load a built dataset in one call (arrays plus the index table)."""
    root = Path(path)
    index = root / INDEX
    if not index.exists():
        raise MdfError(f"{root}: not a built dataset (no {INDEX}); run `mdf dataset build`")
    with index.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        raise MdfError(f"{index}: the dataset has no records")
    table: dict[str, NDArray[Any]] = {}
    for key in rows[0]:
        col = [r[key] for r in rows]
        if key in TEXT_COLUMNS:
            table[key] = np.array(col, dtype=str)
        else:
            table[key] = np.array([float(c) if c != "" else np.nan for c in col])
    feats = np.stack([table[n].astype(np.float64) for n in FEATURE_NAMES], axis=1)
    specs: NDArray[np.float32] | list[NDArray[np.float32]] | None = None
    velocity = None
    if spectrograms:
        maps = []
        for rid in table["id"]:
            arrays, _ = read_record(root / RECORDS / f"{rid}.npz")
            maps.append(arrays["spectrogram_db"])
            velocity = arrays["velocity_mps"] if velocity is None else velocity
        same = len({m.shape for m in maps}) == 1
        specs = np.stack(maps) if same else maps
    return Dataset(
        feats, table["label"].astype(str), table["group"].astype(str), table, specs, velocity
    )
