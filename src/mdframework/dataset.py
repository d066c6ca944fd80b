"""Labelled datasets of simulated records, built in parallel, resumable, deterministic.

A dataset config lists motion sources with their activity labels, cuts long recordings into
records of a fixed length, and multiplies them by scene variations (aspect angle, radar range and
height, the person's height for sources that have one) on a fixed grid and by per-record random
draws (``[randomize]``, :mod:`mdframework.randomize`: scene parameters and motion augmentation).
Every record is one run of the pipeline followed by the seven features. Sources can also be
recordings of a real radar (``recording = {kind = ...}``, point clouds): their records are
windows of frames turned into per-frame Doppler histograms (:mod:`mdframework.pointcloud`), the
representation simulated records get with ``representation = "histogram"``.
``build_dataset`` writes::

    DIR/records/<id>.npz   one file per record, written atomically (temp file + rename):
                           spectrogram_db (n_doppler, n_frames) float32 [dB re peak],
                           velocity_mps (n_doppler,), time_s (n_frames,), features (7,) [m/s],
                           meta: JSON string (label, source, file, window, scene, radar, units);
                           histogram records also: histograms (n_frames, n_bins) float32
                           (points, or intensity weights, per velocity bin and frame)
    DIR/index.csv          one row per record: id, label, source, file, start_s, duration_s,
                           aspect_deg, radar_x/y/z_m, height_m, seed, band_edge_frames
                           (:func:`~mdframework.features.band_edge_frames`), the 7 features, then
                           draw.<name> for every randomised parameter
    DIR/dataset.json       the config, the feature names and units, the record count, the
                           SHA-256 of index.csv (load_dataset refuses an index changed since)

Records are independent pure functions of their spec (including a seed derived from the dataset
seed and what the record is: its source's motion, window, grid point and draw), so the result is
identical whatever the number of workers or the scheduler. A record's id is its index and a
digest of what makes its arrays, the contents of the motion or recording it is cut from included
(:func:`motion_fingerprint`); its label, group, subject and dataset are not in it and are
rewritten into a kept record when the config changes them. A killed build, run again, keeps
every complete record, removes temp files and redoes records whose file is missing, cut short or
corrupt. It resumes only into a folder built from the same config (the marker
``.mdf-dataset.json`` holds it; a different config is an error naming the difference, or with
``force`` a rebuild that keeps the old dataset whole until the new index is written). The folder
rules are those of :mod:`mdframework.outdir`.
"""

from __future__ import annotations

import csv
import errno
import hashlib
import io
import itertools
import json
import os
import re
import warnings
from collections.abc import Callable, Generator, Iterable, Iterator, Mapping, Sequence
from concurrent.futures import CancelledError, as_completed
from contextlib import AbstractContextManager, closing, contextmanager
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, ValidationError, field_validator, model_validator

from . import limits
from .augment import augment_motion, warp_function
from .cluster import (
    LOCAL_DASK_CONFIG,
    SCHEDULER_ENV,
    Workerless,
    check_paths,
    check_scheduler_address,
    check_workers,
    cluster_failure,
    connect,
    quiet_dask_logs,
    quiet_dask_worker,
    scheduler_address,
)
from .config import (
    blaming_overrides,
    format_validation_error,
    read_config_file,
    validate_run_config,
)
from .errors import ConfigError, DataFileError, MdfError, OutputError, SceneError, SettingError
from .features import FEATURE_NAMES, band_edge_frames, envelopes, features_from_envelopes
from .fingerprint import motion_fingerprint, recording_fingerprint
from .interfaces import Motion, Recording, RecordingSource
from .outdir import (
    OutputFolder,
    atomic_savez,
    atomic_write_text,
    describe_holder,
    lock_holder,
    marker_name,
    output_folder,
    read_marker_text,
    safe_name,
    wait_for_files,
)
from .pipeline import build_stages, load_motion, simulate_motion
from .plugins import PluginWarning, blame, default_registry, is_plugin_bug, versions
from .pointcloud import (
    IWR1443_BIN_WIDTH,
    HistogramSettings,
    PointCloud,
    cloud_histograms,
    histogram_features,
    velocity_bins,
)
from .progress import note, printed, progress_enabled, tqdm_bar
from .randomize import Randomization, set_path
from .settings import (
    AngleDeg,
    BelowPeakDb,
    Coordinate,
    Distance,
    Point3,
    PositiveSeconds,
    RunConfigBase,
    Seed,
    StrictModel,
    Workers,
)


class DatasetWarning(UserWarning):
    """A source or record of a dataset was left out (too short, or failed with on_error =
    'skip')."""


RECORDS = "records"
SKIPPED = "skipped.csv"
#: index.csv columns that hold text (all others are numbers)
TEXT_COLUMNS = ("id", "label", "group", "source", "file", "subject", "recording", "dataset")
INDEX = "index.csv"
MANIFEST = "dataset.json"
#: the key of dataset.json that holds the SHA-256 of index.csv as the build wrote it
INDEX_DIGEST = "index_sha256"
#: the version of the dataset folder's format (``format_version`` in dataset.json; the
#: datasets page describes it): raised when a file, column, key or array that a reader of an
#: earlier version relies on is removed or changes its meaning, not when one is added
DATASET_FORMAT = 1
#: Records a worker task builds at most, and the share of the records left that a task takes
#: (``1 / (threads * TASKS_PER_THREAD)``): see :func:`record_chunks`.
MAX_RECORDS_PER_TASK = 8
TASKS_PER_THREAD = 4

#: A percentile (0 .. 100).
Percent = Annotated[float, Field(ge=0, le=100)]

#: the units of a record's arrays, as its ``meta["units"]`` gives them (``histograms`` only in
#: the records that have them)
RECORD_UNITS = {
    "features": "m/s",
    "spectrogram_db": "dB re peak",
    "histograms": "points (or weights) per bin and frame",
    "velocity": "m/s",
    "time": "s",
}
#: every name a dataset build writes in its folder
DATASET_FILES = (RECORDS, INDEX, MANIFEST, SKIPPED)
#: build options that do not change a record (ignored when comparing configs): a build stopped
#: by a failing record resumes with ``on_error = "skip"``, keeping the records it finished
BUILD_OPTIONS = ("workers", "scheduler", "on_error")


class FeatureConfig(StrictModel):
    """How the seven features are extracted (see :mod:`mdframework.features`)."""

    method: Literal["threshold", "percentile"] = Field(
        "threshold",
        description="How the upper and lower envelopes are found in each time column: "
        "threshold (the highest and lowest bins within threshold_db of the column's peak) or "
        "percentile (the velocities where the cumulative power reaches percentiles).",
    )
    threshold_db: BelowPeakDb = Field(
        -20.0, description="method threshold: envelope bins are within this of the column's peak."
    )
    floor_db: BelowPeakDb = Field(
        -40.0, description="Ignore bins this far below the whole spectrogram's peak."
    )
    percentiles: tuple[Percent, Percent] = Field(
        (3.0, 97.0),
        description="method percentile: the cumulative power [%] of the lower and the upper "
        "envelope (van Dorp & Groen 2008).",
    )
    torso: Literal["median", "peak"] = Field(
        "median", description="Torso track: the column's power median, or its peak bin."
    )


class HistogramConfig(StrictModel):
    """Per-frame Doppler histograms of point clouds (:mod:`mdframework.pointcloud`)."""

    bin_width: float = Field(
        IWR1443_BIN_WIDTH, gt=0, le=100, description="Velocity bin [m/s] (default: the IWR1443's)."
    )
    n_bins: int = Field(17, ge=1, le=10_001, description="Number of bins (odd), centred on 0 m/s.")
    weighting: Literal["count", "intensity", "power"] = Field(
        "count", description="Point weight: 1, intensity [dB] (>= 0), or linear power."
    )
    min_range: float = Field(
        0.5, ge=0, le=limits.MAX_COORDINATE_M, description="Ignore points nearer than this [m]."
    )
    max_range: Distance = Field(3.0, description="Ignore points farther than this [m].")

    @model_validator(mode="after")
    def _check(self) -> HistogramConfig:
        if self.n_bins % 2 == 0:
            raise ValueError("n_bins must be odd (a bin centred on 0 m/s)")
        if self.max_range <= self.min_range:
            raise ValueError("max_range must exceed min_range")
        return self

    def settings(self) -> HistogramSettings:
        """As the pure-function settings."""
        return HistogramSettings(**self.model_dump())


class SourceEntry(StrictModel):
    """One recording (or generator) and its label: a motion to simulate, or recordings of a
    real radar."""

    label: str = Field(description="Activity label, e.g. 'walk'.")
    motion: dict[str, Any] | None = Field(None, description="A [motion] section (with its kind).")
    recording: dict[str, Any] | None = Field(
        None, description="A real radar's recordings (with its kind, e.g. 'radhar')."
    )
    group: str | None = Field(
        None, description="Source group for cross-source experiments; default: the kind."
    )
    subject: str | None = Field(
        None,
        description="Subject recorded with every record (of a motion or of a real radar's "
        "recordings); default: the motion's own (CMU: the subject number; UTKinect and MSR: "
        "s01 ...), else empty.",
    )
    dataset: str | None = Field(
        None,
        description="Dataset name recorded with every record; default: the motion's format "
        "(e.g. asf/amc, bvh, utkinect, msr-action3d) or its source (recordings: e.g. radhar).",
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
        "conditioning for Kinect recordings, or its own scene); not motion or seed.",
    )
    randomize: Randomization | None = Field(
        None,
        description="Random draws for this source: the fields given here replace the "
        "dataset's (e.g. its own speed range); the others stay as the dataset's.",
    )

    @model_validator(mode="after")
    def _one_kind(self) -> SourceEntry:
        if (self.motion is None) == (self.recording is None):
            raise ValueError("give exactly one of motion and recording")
        return self

    @field_validator("label", "group")
    @classmethod
    def _printable(cls, value: str | None) -> str | None:
        if value is not None and (not value.strip() or not value.isprintable()):
            raise ValueError(
                "must be a non-empty name without control characters (tabs, line breaks)"
            )
        return value


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
    def _no_empty_list(self) -> Variations:
        for name in type(self).model_fields:
            if getattr(self, name) == []:  # would silently mean "no variation"
                raise ValueError(f"{name}: an empty list; give at least one value, or leave it out")
        return self

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
        default_factory=dict,
        description="Record length per label [s]; a label that no source has is refused.",
    )
    sources: list[SourceEntry] = Field(min_length=1)
    variations: Variations = Field(default_factory=Variations)
    base: dict[str, Any] = Field(
        default_factory=dict,
        description="Run-config sections shared by every record (scatterers, radar, scene, "
        "processing, effects); not motion or seed, which each record takes from its source "
        "and the dataset's seed.",
    )
    features: FeatureConfig = Field(default_factory=FeatureConfig)
    representation: Literal["spectrogram", "histogram"] = Field(
        "spectrogram",
        description="Simulated records: the spectrogram, or per-frame Doppler histograms of the "
        "radar's point clouds (as recordings of a real radar always are).",
    )
    histogram: HistogramConfig = Field(default_factory=HistogramConfig)
    randomize: Randomization = Field(default_factory=Randomization)
    workers: Workers | None = Field(None, description="Local processes; default: CPU count.")
    on_error: Literal["stop", "skip"] = Field(
        "stop",
        description="A record that fails: stop the build (naming the record, its source file, "
        "window and cause), or skip it and list it in skipped.csv and dataset.json.",
    )
    place: Literal["recording", "record"] = Field(
        "recording",
        description="What scene.person.position places: the recording's start (every record "
        "is a window of the one placed recording), or each record's start (a long walk's "
        "late records start where its first one does, at the same heading).",
    )


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
    #: values drawn for this record (scene and augmentation), for the table
    draws: dict[str, Any] | None = None
    #: ``{"histogram": settings}`` for histogram records, else None
    histogram: dict[str, Any] | None = None
    #: record metadata for the table
    subject: str = ""
    recording: str = ""
    dataset: str = ""
    on_error: str = "stop"
    #: the config section each draw's distribution comes from (``randomize`` or
    #: ``sources[N].randomize``), to name it when a drawn value does not fit its field
    draw_origins: dict[str, str] | None = None
    #: the source's span ``(start, end)`` [s from the motion's first frame] when the source
    #: gives a ``start`` or a ``duration`` (``end``: None without a duration, the motion's end):
    #: a record sped up or warped by its draws stays within it
    span: tuple[float, float | None] | None = None
    #: the aspect [deg] asked for (variation or draw) when ``place = "record"`` turned it into
    #: a fixed heading, for the table
    aspect_deg: float | None = None
    #: the dataset config field that sets the record's length (``record_lengths.<label>`` or
    #: ``sources[N].record_length``; None: the whole source), named by a record's errors
    length_field: str | None = None
    #: a recorded record's (file, start [s], duration [s]), named by its errors and skip row
    window: tuple[str, float, float] | None = None
    #: a simulated record's source: its number in ``sources`` (``mdf dataset check`` plans the
    #: first record of each)
    source: int | None = None


def load_dataset_config(
    path: str | Path, overrides: Sequence[str] = ()
) -> tuple[DatasetConfig, Path]:
    """Read and validate a dataset config, with ``overrides`` (``KEY=VALUE``, the command
    line's ``--set``) applied; returns it and its folder (for relative paths)."""
    p = Path(path)
    data = read_config_file(p, "dataset", overrides)
    with blaming_overrides(str(p), overrides):
        if "scheduler" in data:
            raise ConfigError(
                f"{p}: scheduler: a shared config cannot choose where records are computed; "
                f"give the Dask scheduler with --scheduler or the {SCHEDULER_ENV} environment "
                "variable"
            )
        try:
            return DatasetConfig.model_validate(data), p.parent
        except ValidationError as exc:
            message = format_validation_error(exc, str(p), data, DatasetConfig)
            raise ConfigError(message) from None


_MOTIONS: dict[tuple[str, str], Motion] = {}  # this process's motions, oldest first
_MAX_MOTIONS = 64  # far more recordings than a dataset config lists
#: A warning raised while loading a motion: message, category, file name, line.
_Caught = tuple[str, type[Warning], str, int]
#: warnings raised while motions were loaded in other processes, to be shown here
_PENDING: dict[tuple[str, str], list[_Caught]] = {}


def build_workers(config: DatasetConfig, workers: int | None = None) -> int:
    """The number of workers of a build: ``workers`` (the command line), else the config's,
    else the CPU count."""
    return workers or config.workers or os.cpu_count() or 1


_MOTION_WHERE = "dataset motion"


def _load_motion(motion_json: str, base_dir: str) -> Motion:
    """Load a motion once per process (records of one recording share it). Local worker
    processes are forked after planning and inherit the motions the planner loaded (in
    parallel, :func:`_preload_motions`); local workers that are not forked (macOS,
    :func:`mdframework.workers.start_method`) and Dask workers are sent them when the build
    starts (:func:`_receive_motions`), and load any other motion they meet once. The cache
    holds far more recordings than a dataset config lists, so records scheduled in any order
    never evict one. A motion loaded by another process shows its warnings here, when first
    asked for."""
    key = (motion_json, base_dir)
    motion = _MOTIONS.get(key)
    if motion is None:
        section = json.loads(motion_json)
        config = validate_run_config(
            {"motion": section}, source=_MOTION_WHERE, base_dir=Path(base_dir)
        )
        motion = load_motion(build_stages(config).source)
        _keep_motion(key, motion)
    for text, category, filename, lineno in _PENDING.pop(key, ()):
        # shown, not warned again: the loading process has applied this process's filters
        warnings.showwarning(_warning(text, category), category, filename, lineno)
    return motion


def _warning(text: str, category: type[Warning]) -> Warning | str:
    """The warning ``category(text)`` (as raised), or its text for a class made otherwise."""
    try:
        return category(text)
    except Exception:
        return text


def _keep_motion(key: tuple[str, str], motion: Motion) -> None:
    while len(_MOTIONS) >= _MAX_MOTIONS:
        del _MOTIONS[next(iter(_MOTIONS))]
    _MOTIONS[key] = motion


def _motion_key(section: dict[str, Any]) -> str:
    """The cache key of a source's motion: its section without the span that records are cut
    from (``start``, ``duration``)."""
    return json.dumps(
        {k: v for k, v in section.items() if k not in ("start", "duration")}, sort_keys=True
    )


def _load_elsewhere(key: tuple[str, str]) -> tuple[Motion | None, list[_Caught]]:
    """Load a motion in a planning worker: the motion and the warnings that the filters (the
    planner's, inherited) let through, or (None, []) if it fails (a warning filtered as an
    error included): the planner then loads it itself and raises the error there (a worker
    that is not forked is given the planner's filters, :func:`mdframework.workers.worker_pool`)."""
    with warnings.catch_warnings(record=True) as caught:
        try:
            motion = _load_motion(*key)
        except Exception:
            return None, []
    return motion, [(str(w.message), w.category, w.filename, w.lineno) for w in caught]


def _preload_motions(config: DatasetConfig, base_dir: Path, workers: int) -> None:
    """Load the distinct motions of the sources in up to ``workers`` processes at once (at most
    one per CPU), so that planning takes the time of the slowest share rather than of all.
    Every result is the motion the planner would load itself; the warnings raised while
    loading one are shown once, when the planner comes to its source (in source order)."""
    keys = [
        (_motion_key(e.motion), str(base_dir))
        for e in config.sources
        if e.motion is not None and "kind" in e.motion
    ]
    todo = [k for k in dict.fromkeys(keys) if k not in _MOTIONS]
    n = min(workers, len(todo), os.cpu_count() or 1)
    if n < 2:
        return
    import scipy.interpolate  # noqa: F401  # heavy: imported when used

    from .workers import worker_pool

    # Once, before the workers fork, what they would each load or import: the plugins, and the
    # splines that make the Boulic walkers and resample every body motion in every record (the
    # build's workers fork from this process later and inherit it too).
    default_registry()
    with worker_pool(n, _start_fresh_worker, ({},)) as pool:
        for key, (motion, caught) in zip(todo, pool.map(_load_elsewhere, todo), strict=True):
            if motion is not None:
                _keep_motion(key, motion)
                _PENDING[key] = caught


def _receive_motions(motions: dict[tuple[str, str], Motion]) -> None:
    """Keep the motions the planner loaded (run on each Dask worker, and each local worker
    that is not forked, as a build starts): they replace any this worker kept from an earlier
    build, whose files may have changed since, and so do the recordings it loads afresh."""
    _load_recordings.cache_clear()
    _MOTIONS.update(motions)


def _start_fresh_worker(motions: dict[tuple[str, str], Motion]) -> None:
    """Give a local worker that is not forked what a forked one inherits: the plugins, loaded
    without their warnings (the build's process has shown them once; each worker repeated
    them), and the ``motions`` planning loaded (:func:`_receive_motions`)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PluginWarning)
        default_registry()
    _receive_motions(motions)


def _forget_loaded() -> None:
    """Forget the motions and recordings this process loaded: a build reads its files afresh,
    so a file changed since an earlier build in this process is seen (and fingerprinted)."""
    _MOTIONS.clear()
    _PENDING.clear()
    _load_recordings.cache_clear()


def _record_key(seed: int, what: Sequence[Any]) -> list[int]:
    """The entropy of a record's random numbers: the dataset's ``seed`` and a digest of what
    the record is (``what``: its source's motion fingerprint and the number of earlier sources
    of the same motion, its window's start, its grid point, its draw; and, for a grid point
    given twice, how many records alike come before it), never its number in the
    dataset or its file's path, so that records added to or left out of a config leave the
    others' draws, and a copy of the config and data elsewhere draws the same."""
    text = json.dumps(list(what), sort_keys=True, separators=(",", ":"), default=str)
    digest = hashlib.sha256(text.encode()).digest()
    return [seed, *(int.from_bytes(digest[i : i + 4], "little") for i in range(0, 16, 4))]


def _record_seed(key: list[int]) -> int:
    """A record's run seed (32 bits) from its :func:`_record_key`."""
    return int(np.random.SeedSequence(key).generate_state(1)[0])


def _scene_for(base_scene: Any, variation: dict[str, Any]) -> Any:
    """The scene of one record: the (base) scene with only the varied fields replaced. A scene,
    person, position or radar position of the wrong shape is left as it is, for the record's
    validation to name."""
    if not isinstance(base_scene, dict):
        return base_scene
    scene: dict[str, Any] = json.loads(json.dumps(base_scene))
    person = scene.get("person", {})
    if variation["aspect_deg"] is not None and isinstance(person, dict):
        person = dict(person)
        person.pop("heading_deg", None)  # the aspect replaces any fixed heading
        person["aspect_deg"] = variation["aspect_deg"]
        scene["person"] = person
    if variation["radar_position"] is not None:
        scene["radar_position"] = list(variation["radar_position"])
    if variation["radar_range"] is not None or variation["radar_height"] is not None:
        start: Any = person.get("position", [0.0, 0.0]) if isinstance(person, dict) else None
        radar = scene.get("radar_position", [10.0, 0.0, 2.0])
        if not _numbers(radar, 3) or (
            variation["radar_range"] is not None and not _numbers(start, 2)
        ):
            return scene
        radar = list(radar)
        if variation["radar_range"] is not None:
            radar[0], radar[1] = start[0] + variation["radar_range"], start[1]
        if variation["radar_height"] is not None:
            radar[2] = variation["radar_height"]
        scene["radar_position"] = radar
    return scene


def _numbers(value: Any, n: int) -> bool:
    """Whether ``value`` is a list of ``n`` numbers (not flags)."""
    return (
        isinstance(value, list | tuple)
        and len(value) == n
        and all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
    )


def _merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    """Deep merge of config dicts: tables merge key by key, other values are replaced."""
    out: dict[str, Any] = json.loads(json.dumps(base))
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = json.loads(json.dumps(value))
    return out


@lru_cache(maxsize=8)
def _load_recordings(section_json: str, base_dir: str) -> tuple[Recording, ...]:
    """Load a real radar's recordings once per process."""
    section = json.loads(section_json)
    kind = section.get("kind")
    try:
        cls = default_registry().get("recording", str(kind))
    except KeyError as exc:
        raise ConfigError(f"recording.kind: {exc.args[0]}") from None
    try:
        cfg = cls.Config.model_validate(section, context={"base_dir": Path(base_dir)})
    except ValidationError as exc:
        raise ConfigError(format_validation_error(exc, "recording", section)) from None
    with blame(cls, "__init__"):
        source: Any = cls(cfg)
    assert isinstance(source, RecordingSource)
    with blame(source, "load"):
        return tuple(source.load())


def _plan_recordings(
    config: DatasetConfig, entry_no: int, entry: SourceEntry, base_dir: Path, first_index: int
) -> tuple[list[RecordSpec], list[str]]:
    """Records of a real radar's recordings: windows of whole frames; and the recordings
    shorter than the record length, skipped with a warning (as a short motion source is)."""
    section = dict(entry.recording or {})
    where = f"sources[{entry_no}]"
    if "kind" not in section:
        raise ConfigError(f"{where}.recording: a kind is required")
    try:
        recordings = _load_recordings(json.dumps(section, sort_keys=True), str(base_dir))
    except ConfigError as exc:
        raise ConfigError(f"{where}.{exc}") from None
    hist = config.histogram.model_dump()
    specs: list[RecordSpec] = []
    short: list[str] = []
    for rec in recordings:
        content = recording_fingerprint(rec)
        period = rec.cloud.frame_period
        length_s = entry.record_length or config.record_lengths.get(entry.label)
        length = rec.cloud.n_frames if length_s is None else round(length_s / period)
        hop = length if entry.hop is None else max(1, round(entry.hop / period))
        field = _length_field(config, entry_no, entry) or where
        if length < 1:
            raise ConfigError(
                f"{field}: {length_s:g} s is shorter than one {period * 1e3:.1f} ms frame of "
                f"{rec.name}: give at least {period:.4g} s"
            )
        if length > rec.cloud.n_frames:
            warnings.warn(
                f"{where} ({rec.name}): the {rec.cloud.n_frames} frames of {period * 1e3:.1f} ms "
                f"are fewer than the {length} frames of the {length_s:g} s record length "
                f"({field}); skipped",
                DatasetWarning,
                stacklevel=3,
            )
            short.append(rec.name)
            continue
        starts = range(0, rec.cloud.n_frames - length + 1, hop)
        for n, first in enumerate(starts):
            if entry.max_records is not None and n >= entry.max_records:
                break
            run = {"recording": section, "name": rec.name, "first_frame": first, "frames": length}
            spec = _spec(
                config,
                first_index + len(specs),
                entry,
                section["kind"],
                run,
                base_dir,
                None,
                hist,
                _naming(entry, rec.metadata, rec.name, section["kind"]),
                content=content,
            )
            window = (rec.name, first * period, length * period)
            specs.append(
                replace(spec, length_field=_length_field(config, entry_no, entry), window=window)
            )
    return specs, short


def _generated_recording(motion: Mapping[str, Any]) -> str:
    """The recording of a motion read from no file (a generator such as the Boulic walker): its
    kind and parameters, ``boulic(n_cycles=7 rv=0.7)``, so that walkers of other parameters
    are other recordings (they were all one, ``boulic``, which experiments holding out
    recordings could not hold out) and sources of one walker (spans of it) are one. Sources
    whose motions hold the same data (written otherwise: an activity label, a default written
    out) take the first one's name (:func:`plan_records`)."""
    params = " ".join(
        f"{k}={json.dumps(v, sort_keys=True, separators=(',', ':'))}"
        for k, v in sorted(motion.items())
        if k not in ("kind", "start", "duration")
    )
    return f"{motion['kind']}({params})" if params else str(motion["kind"])


def _naming(
    entry: SourceEntry, md: Mapping[str, Any], recording: str, kind: str
) -> tuple[str, str, str]:
    """A record's subject, recording and dataset: the source entry's ``subject`` and
    ``dataset`` where given, else what the motion's or recording's metadata ``md`` says (its
    ``subject``; its ``format`` or ``source``, else the source ``kind``)."""
    subject = entry.subject if entry.subject is not None else md.get("subject")
    return (
        "" if subject is None else str(subject),
        recording,
        entry.dataset or str(md.get("format") or md.get("source") or kind),
    )


def _length_field(config: DatasetConfig, entry_no: int, entry: SourceEntry) -> str | None:
    """The dataset config field that sets a source's record length (None: the whole source)."""
    if entry.record_length is not None:
        return f"sources[{entry_no}].record_length"
    if entry.label in config.record_lengths:
        return f"record_lengths.{entry.label}"
    return None


def _spec(
    config: DatasetConfig,
    index: int,
    entry: SourceEntry,
    kind: str,
    run: dict[str, Any],
    base_dir: Path,
    draws: dict[str, Any] | None,
    hist: dict[str, Any] | None,
    meta: tuple[str, str, str] = ("", "", ""),
    draw_origins: dict[str, str] | None = None,
    span: tuple[float, float | None] | None = None,
    aspect_deg: float | None = None,
    content: str | None = None,
) -> RecordSpec:
    """A record's spec; its id ends with a digest of everything that makes the record's
    arrays: its run config, the feature and histogram settings, its draws and ``content``, the
    fingerprint of the motion or recording it is cut from (:func:`motion_fingerprint`), so a
    file whose contents changed makes new records. Label, group, subject and dataset are not
    in it: a record whose only change is one of them is kept and relabelled (:func:`_complete`).
    ``meta``: the record's subject, recording and dataset; ``span``: the source's span when
    it gives a start or a duration (:attr:`RecordSpec.span`)."""
    features = config.features.model_dump()
    payload = [run, features] + [x for x in (draws, hist) if x is not None]
    if content is not None:
        payload.append({"content": content})
    # where the span ends moves a sped-up or warped record (its start only refuses one)
    if span is not None and span[1] is not None and draws and {"speed", "time_warp"} & set(draws):
        payload.append({"span_end": span[1]})
    digest = hashlib.sha1(json.dumps(payload, sort_keys=True).encode()).hexdigest()[:10]
    return RecordSpec(
        index,
        f"{index:05d}-{digest}",
        entry.label,
        entry.group or kind,
        run,
        str(base_dir),
        features,
        draws,
        None if hist is None else {"histogram": hist},
        *meta,
        config.on_error,
        draw_origins,
        span,
        aspect_deg,
    )


def _apply_draws(
    run: dict[str, Any], section: dict[str, Any], draws: dict[str, Any], where: str
) -> None:
    """Put one record's drawn scene values into its run config (in place)."""
    scene_keys = {k: draws.get(k) for k in ("aspect_deg", "radar_range", "radar_height")}
    if any(v is not None for v in scene_keys.values()):
        run["scene"] = _scene_for(run.get("scene", {}), {**scene_keys, "radar_position": None})
    if "height" in draws:
        section["height"] = draws["height"]
    for path, value in draws.items():
        if "." in path:
            try:
                set_path(run, path, value)
            except KeyError as exc:
                raise ConfigError(f"{where}: randomize.params: {exc.args[0]}") from None


#: the run-config field that each named scene draw sets (``params`` draws name their own)
DRAWN_FIELDS = {
    "aspect_deg": "scene.person.aspect_deg",
    "radar_range": "scene.radar_position",  # x and y
    "radar_height": "scene.radar_position.2",
    "height": "motion.height",
}


def _drawn_field(name: str) -> str | None:
    """The run-config field a draw sets (None for the motion augmentations)."""
    return DRAWN_FIELDS.get(name) or (name if "." in name else None)


def blamed_draw(field: str, draws: dict[str, Any]) -> str | None:
    """The draw that set the run-config ``field`` (dotted, as a config error names it), or
    None: the draw whose field is ``field``, holds it or lies inside it, the most specific
    first (``scene.radar_position.2`` is ``radar_height``'s, ``.0`` ``radar_range``'s)."""
    best: str | None = None
    for name in draws:
        own = _drawn_field(name)
        if own is None:
            continue
        inside = "." in field and own.startswith(field + ".")
        if field == own or field.startswith(own + ".") or inside:
            if best is None or len(own) > len(_drawn_field(best) or ""):
                best = name
    return best


def _draw_origins(config: DatasetConfig, entry_no: int, entry: SourceEntry) -> dict[str, str]:
    """The config section of each draw of a source: its own ``randomize`` for the fields it
    gives, else the dataset's."""
    own = set() if entry.randomize is None else entry.randomize.model_fields_set
    rz = _randomize(config, entry)
    names = [*DRAWN_FIELDS, *rz.params]
    return {
        name: f"sources[{entry_no}].randomize"
        if (name if name in DRAWN_FIELDS else "params") in own
        else "randomize"
        for name in names
    }


#: the numbers-and-flags check's message (``a number, not text ("2000")``)
_WRONG_TYPE = re.compile(r"(a number\b.*|true or false), not (text|a flag|\w+) \(")


def validate_record(
    run: dict[str, Any],
    source: str,
    base_dir: Path | str,
    draws: dict[str, Any] | None,
    origins: dict[str, str] | None = None,
) -> RunConfigBase:
    """:func:`validate_run_config` of a record's run config; a field that a ``[randomize]``
    draw set and that refuses the drawn value is blamed on the draw: the error names the
    distribution (``randomize.height``), the drawn value, the record and the field's rule."""
    try:
        return validate_run_config(run, source=source, base_dir=Path(base_dir))
    except ConfigError as exc:
        text = str(exc)
        rest = text.removeprefix(f"{source}: ")
        field, _, problem = rest.partition(": ")
        name = None if rest == text else blamed_draw(field, draws or {})
        if name is None or draws is None:
            raise
        section = (origins or {}).get(name, "randomize")
        what = f"{section}.{name}" if name in DRAWN_FIELDS else f'{section}.params."{name}"'
        value = draws[name]
        shown = f"{value:.6g}" if isinstance(value, float) else repr(value)
        if problem.startswith("unknown field"):
            todo = "this source's config has no such field: remove the draw"
        elif _WRONG_TYPE.match(problem):
            todo = "give the distribution values of the field's type"
        else:
            todo = "keep the distribution within the field's range"
        raise ConfigError(f"{source}: {what} drew {shown} for {field}: {problem}; {todo}") from None


def _has_path(node: Any, parts: list[str]) -> bool:
    """Whether ``node["a"][0]["b"]`` exists for ``parts = ["a", "0", "b"]``."""
    for part in parts:
        if isinstance(node, dict) and part in node:
            node = node[part]
        elif isinstance(node, list) and part.isdigit() and int(part) < len(node):
            node = node[int(part)]
        else:
            return False
    return True


def _as_written(
    exc: ConfigError, record: str, config: DatasetConfig, entry_no: int, entry: SourceEntry
) -> ConfigError:
    """A record's config error with the field named where the dataset config wrote it:
    ``base.radar.prf``, ``sources[0].run.radar.prf`` or ``sources[0].motion.file`` rather than
    the record's ``radar.prf``; a height that ``variations.height`` set is named so. Scene
    fields (which variations and placement rewrite), the window's ``start``/``duration`` and
    draws keep the record's name."""
    text = str(exc)
    rest = text.removeprefix(f"{record}: ")
    field, _, problem = rest.partition(": ")
    parts = field.split(".")
    if rest == text or not problem or parts[0] == "scene":
        return exc
    if parts[0] == "motion":
        if parts[1:] == ["height"] and config.variations.height is not None:
            return ConfigError(f"{record}: variations.height (for {field}): {problem}")
        if len(parts) < 2 or parts[1] in ("start", "duration", "height"):
            return exc
        where = f"sources[{entry_no}]."
    elif _has_path(entry.run, parts):
        where = f"sources[{entry_no}].run."
    elif _has_path(config.base, parts):
        where = "base."
    else:
        return exc
    return ConfigError(f"{record}: {where}{field}: {problem}")


def _validate_planned(
    run: dict[str, Any],
    record: str,
    draws: dict[str, Any] | None,
    origins: dict[str, str],
    entry_no: int,
    plan: tuple[DatasetConfig, Path],
) -> RunConfigBase:
    """A planned record's run config, validated (:func:`validate_record`); an error names the
    field where the dataset config (``plan``: it and its folder) wrote it (:func:`_as_written`)."""
    config, base_dir = plan
    try:
        return validate_record(run, record, base_dir, draws, origins)
    except ConfigError as exc:
        raise _as_written(exc, record, config, entry_no, config.sources[entry_no]) from None


def _check_points(config: Any, entry_no: int) -> None:
    """``representation = 'histogram'``: refuse, before any record is simulated, a source
    whose radar (``config``: one of its records' run configs, validated) gives no point clouds
    frame by frame (:func:`_simulated_cloud` needs its ``points`` product and ``frame_period``)."""
    radar = config.radar
    if getattr(radar, "frame_period", None) is None or getattr(radar, "points", True) is False:
        raise ConfigError(
            f"representation = 'histogram': the radar of sources[{entry_no}] "
            f"(kind = {radar.kind!r}) gives no point clouds frame by frame; histogram records "
            "need one that does (e.g. kind = 'fmcw' with points = true), or set "
            "representation = 'spectrogram'"
        )


def _randomize(config: DatasetConfig, entry: SourceEntry) -> Randomization:
    """The draws of one source: the dataset's, with the fields the source gives replaced."""
    if entry.randomize is None:
        return config.randomize
    own = {k: getattr(entry.randomize, k) for k in entry.randomize.model_fields_set}
    return config.randomize.model_copy(update=own)


#: run-config sections that a build sets for every record itself, and where to give them
#: instead: in ``base`` or a source's ``run`` they would be replaced without a word
_PER_RECORD = {
    "motion": "each record's motion is its source's own `motion` table; give settings such as "
    "`sanity` there",
    "seed": "each record's seed derives from the dataset's top-level `seed` and what the "
    "record is; set that one",
}


def _check_sections(config: DatasetConfig) -> None:
    """Refuse what a build would silently ignore: a ``base`` or source ``run`` section that it
    sets itself, and a ``record_lengths`` entry of a label that no source has."""
    tables = [("base", config.base)]
    tables += [(f"sources[{n}].run", e.run) for n, e in enumerate(config.sources)]
    for where, table in tables:
        for key, instead in _PER_RECORD.items():
            if key in table:
                raise ConfigError(f"{where}.{key}: {instead}")
    labels = sorted({e.label for e in config.sources})
    for label in config.record_lengths:
        if label not in labels:
            raise ConfigError(
                f"record_lengths.{label}: no source has the label {label!r} (labels: "
                f"{', '.join(map(repr, labels))})"
            )


def _drawn_motion(
    section: dict[str, Any], base_dir: Path, prints: dict[str, str]
) -> tuple[str, Motion] | None:
    """The motion a record's draws chose and its fingerprint (``prints``: motion key ->
    fingerprint, filled in); None if it cannot be loaded (the record's validation, or its
    build, names why)."""
    key = _motion_key(section)
    try:
        drawn = _load_motion(key, str(base_dir))  # loaded once per process
    except MdfError:
        return None
    if key not in prints:
        prints[key] = motion_fingerprint(drawn)
    return prints[key], drawn


def _source_span(motion: dict[str, Any], entry_no: int, loaded: Motion) -> tuple[float, float]:
    """The span ``(start, end)`` [s] that a source's records are cut from: its motion's own
    ``start`` and ``duration`` (checked here: the loaded motion is shared by every span of
    it), within the loaded motion."""
    where = f"sources[{entry_no}].motion"
    for name in ("start", "duration"):
        value = motion.get(name)
        if value is None:
            continue
        if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(value):
            raise ConfigError(f"{where}.{name}: a number of seconds, not {json.dumps(value)}")
        if value < 0 or (name == "duration" and value == 0):
            rule = "at least 0" if name == "start" else "greater than 0"
            raise ConfigError(f"{where}.{name}: must be {rule} (got {value:g})")
    start = float(motion.get("start", 0.0))
    end = loaded.skeleton.duration
    if start >= end:
        raise ConfigError(
            f"{where}.start: {start:g} s is not before the end of the {end:.3f} s motion"
        )
    if motion.get("duration") is not None:
        end = min(end, start + float(motion["duration"]))
    return start, end


def plan_records(config: DatasetConfig, base_dir: Path, *, workers: int = 1) -> list[RecordSpec]:
    """Expand sources x windows x variations x random draws into record specs, in a fixed
    order. With ``workers`` > 1 the sources' motions are first loaded in that many processes
    (:func:`_preload_motions`); the specs are the same."""
    _check_sections(config)
    v = config.variations
    for rz in [config.randomize] + [_randomize(config, e) for e in config.sources]:
        for name in ("aspect_deg", "radar_range", "radar_height", "height"):
            if getattr(v, name) is not None and getattr(rz, name) is not None:
                raise ConfigError(f"{name}: give it as a variation or as a random draw, not both")
        if (rz.radar_range is not None or rz.radar_height is not None) and v.radar_position:
            raise ConfigError("randomize.radar_range/height cannot combine with radar_position")
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
    hist = config.histogram.model_dump() if config.representation == "histogram" else None
    if workers > 1:
        _preload_motions(config, base_dir, workers)
    specs: list[RecordSpec] = []
    short: list[str] = []
    plan = (config, base_dir)
    prints: dict[str, str] = {}  # motion key -> fingerprint
    generated: dict[str, str] = {}  # fingerprint -> recording of a motion read from no file
    sources_of: dict[str, int] = {}  # fingerprint -> sources of that motion so far
    keys_of: dict[tuple[int, ...], int] = {}  # a record's key -> records of that key so far
    for entry_no, entry in enumerate(config.sources):
        if entry.recording is not None:
            recorded, too_short = _plan_recordings(config, entry_no, entry, base_dir, len(specs))
            specs += recorded
            short += too_short
            continue
        motion = dict(entry.motion or {})
        if "kind" not in motion:
            raise ConfigError(f"sources[{entry_no}].motion: a kind is required")
        # a source's own start/duration limit the span that records are cut from
        key = _motion_key(motion)
        try:
            loaded = _load_motion(key, str(base_dir))
        except ConfigError as exc:  # named where the dataset config wrote it
            text = str(exc)
            if not text.startswith(f"{_MOTION_WHERE}: "):
                raise  # names its file already
            raise ConfigError(f"sources[{entry_no}].{text[len(_MOTION_WHERE) + 2 :]}") from None
        if key not in prints:  # once per loaded motion
            prints[key] = motion_fingerprint(loaded)
        span_start, span_end = _source_span(motion, entry_no, loaded)
        duration = span_end - span_start
        length = entry.record_length or config.record_lengths.get(entry.label) or duration
        where = motion.get("file", motion["kind"])
        if length > duration + 1e-9:
            warnings.warn(
                f"sources[{entry_no}] ({where}): the {duration:.3f} s recording is shorter "
                f"than the {length:g} s record length; skipped",
                DatasetWarning,
                stacklevel=2,
            )
            short.append(str(where))
            continue
        md = loaded.metadata
        named = md.get("file") or motion.get("file")
        if not named:  # a generated motion: one recording per motion data, however written
            named = generated.setdefault(prints[key], _generated_recording(motion))
        meta = _naming(entry, md, str(named), motion["kind"])
        hop = entry.hop or length
        rz = _randomize(config, entry)
        origins = _draw_origins(config, entry_no, entry)

        windows = float(np.ceil((duration - length + 1e-9) / hop))  # inf for a hop of 1e-308
        if entry.max_records is not None:
            windows = min(windows, entry.max_records)
        n_draws = rz.draws if rz.active() else 1
        if len(specs) + windows * len(grid) * n_draws > limits.MAX_RECORDS:
            shown = f"{windows:,.0f}" if windows < 1e15 else f"{windows:.3g}"
            raise ConfigError(
                f"sources[{entry_no}]: {shown} windows x {len(grid)} variation(s) x "
                f"{n_draws} draw(s) take the dataset beyond the limit of "
                f"{limits.MAX_RECORDS:,} records; raise hop or set max_records"
            )
        n_windows = int(windows)
        starts = span_start + np.arange(n_windows) * hop
        # a source is known by its motion's contents, wherever its file lies (and among
        # sources of one motion, by its place)
        same = sources_of.get(prints[key], 0)
        sources_of[prints[key]] = same + 1
        source_key = [prints[key], same]
        points_checked = hist is None  # histograms need a radar with point clouds: checked once
        for start in starts:
            for (aspect, rng_, rheight, rpos, height), draw_no in itertools.product(
                grid, range(n_draws)
            ):
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
                record = f"sources[{entry_no}] record {index}"
                point = [aspect, rng_, rheight, rpos, height]
                what = [*source_key, section["start"], point, draw_no]
                entropy = _record_key(config.seed, what)
                # a grid point given twice (an aspect listed twice) is another record alike
                same_key = keys_of.get(tuple(entropy), 0)
                keys_of[tuple(entropy)] = same_key + 1
                if same_key:
                    entropy = _record_key(config.seed, [*what, same_key])
                draws = None
                if rz.active():
                    rng = np.random.default_rng(np.random.SeedSequence([*entropy, 1]))
                    draws = rz.sample(rng)
                    _apply_draws(run, section, draws, f"sources[{entry_no}]")
                asked = None
                if config.place == "record":  # after the draws: it fixes the drawn aspect
                    placing = _validate_planned(run, record, draws, origins, entry_no, plan)
                    run["scene"] = _place_record(run, placing, loaded)
                    asked = placing.scene.person.aspect_deg
                    if asked is None and placing.scene.person.heading_deg is None:
                        asked = 0.0  # the scene's default: facing the radar
                run["seed"] = _record_seed(entropy)
                content, naming = prints[key], meta
                if draws and any(
                    p.startswith("motion.") and isinstance(d, str) for p, d in draws.items()
                ):  # a drawn file (or a part of one): the record is cut from its contents,
                    # and is that file's subject and recording
                    chosen = _drawn_motion(section, base_dir, prints)
                    if chosen is not None:
                        content, drawn_md = chosen[0], chosen[1].metadata
                        drawn_file = str(drawn_md.get("file") or section.get("file") or where)
                        naming = _naming(entry, drawn_md, drawn_file, motion["kind"])
                spec = _spec(
                    config,
                    index,
                    entry,
                    motion["kind"],
                    run,
                    base_dir,
                    draws,
                    hist,
                    naming,
                    origins if draws else None,
                    _span(motion, span_start, span_end),
                    asked,
                    content,
                )
                length_field = _length_field(config, entry_no, entry)
                specs.append(replace(spec, length_field=length_field, source=entry_no))
                # every record's run config is valid before any file is written (with
                # on_error = "skip" an invalid record is skipped by the build instead)
                if config.on_error == "stop" or not points_checked:
                    try:
                        planned = _validate_planned(run, record, draws, origins, entry_no, plan)
                    except ConfigError:
                        if config.on_error == "stop":
                            raise
                        continue  # skipped by the build, which names why
                    if not points_checked:  # on the first record whose config is valid
                        _check_points(planned, entry_no)
                        points_checked = True
    if not specs:
        raise ConfigError(
            f"no records: every source is shorter than its record length ({', '.join(short)})"
        )
    return _distinct_recordings(specs)


def _record_file_of(spec: RecordSpec) -> tuple[str, Path] | None:
    """The motion or recording file a record is cut from: as its config gives it, and joined
    to the config's folder as the config's paths are (``~`` expanded, as
    :data:`~mdframework.settings.DataPath` does); ``None`` for a motion read from no file."""
    run = spec.run_config
    given = (run.get("recording") or run.get("motion") or {}).get("file")
    if given is None:
        return None
    return str(given), Path(spec.base_dir) / Path(str(given)).expanduser()


def _distinct_recordings(specs: list[RecordSpec]) -> list[RecordSpec]:
    """Records named by distinct recordings: where two different motion files share a name
    (``alice/walk.bvh``, ``bob/walk.bvh``), their records' ``recording`` is the file as the
    config first gives it, and where two different files of a real radar's recordings hold a
    recording of one name, it is ``<file as the config gives it>:<name>``, so that experiments
    holding out recordings do not take them for one."""
    first: dict[Path, str] = {}  # each file as the config first gives it
    files: dict[str, set[Path]] = {}
    paths: list[Path | None] = []  # each record's file
    for spec in specs:
        read = _record_file_of(spec)
        path = None
        if read is not None:
            given, joined = read
            path = joined.resolve()
            first.setdefault(path, given)
            files.setdefault(spec.recording, set()).add(path)
        paths.append(path)
    shared = {name for name, held in files.items() if len(held) > 1}
    out = []
    for spec, path in zip(specs, paths, strict=True):
        if path is not None and spec.recording in shared:
            given = first[path]
            name = f"{given}:{spec.recording}" if "recording" in spec.run_config else given
            spec = replace(spec, recording=name)
        out.append(spec)
    return out


def _place_record(run: dict[str, Any], config: RunConfigBase, motion: Motion) -> dict[str, Any]:
    """The scene of a record placed at ``person.position`` (``place = "record"``): the position
    moved back by the placed recording's travel up to the record's start, and the heading the
    recording's placement gives fixed, so that the record starts at the configured position.
    ``config``: ``run`` validated."""
    from .physics.scene import scene_heading_deg
    from .pipeline import body_placement, condition_body
    from .sanity import motion_file

    scene: dict[str, Any] = json.loads(json.dumps(run.get("scene", {})))
    if motion.canonical_map is None:
        return scene
    body, _ = condition_body(motion.canonical(), config.conditioning)
    person = config.scene.person
    # only the hip centre's track is placed: the placement comes from the whole recording
    radar = np.asarray(config.scene.radar_position, np.float64)
    where = body_placement(body, person, radar, motion_file(motion))
    base = where.apply(body.time, body.joint("base"))
    start = body.time[0] + float(run["motion"].get("start", 0.0))
    at = np.array([np.interp(start, body.time, base[:, k]) for k in (0, 1)])
    shift = at - np.asarray(person.position)
    heading = scene_heading_deg(
        np.asarray(person.position, dtype=np.float64),
        np.asarray(config.scene.radar_position, dtype=np.float64),
        aspect_deg=person.aspect_deg,
        heading_deg=person.heading_deg,
    )
    new_person = dict(scene.get("person", {}))
    new_person.pop("aspect_deg", None)
    new_person["heading_deg"] = heading
    new_person["position"] = [
        float(person.position[0] - shift[0]),
        float(person.position[1] - shift[1]),
    ]
    scene["person"] = new_person
    return scene


def _feature_options(fcfg: dict[str, Any]) -> dict[str, Any]:
    return {
        "method": fcfg["method"],
        "threshold_db": fcfg["threshold_db"],
        "floor_db": fcfg["floor_db"],
        "percentiles": tuple(fcfg["percentiles"]),
        "torso_method": fcfg["torso"],
    }


def _histogram_arrays(
    cloud: PointCloud, hist: dict[str, Any], fcfg: dict[str, Any], record: str
) -> dict[str, Any]:
    """The arrays of a histogram record: histograms, their dB map, axes and features."""
    settings = HistogramSettings(**hist)
    h = cloud_histograms(cloud, settings)
    centres, _ = velocity_bins(settings.bin_width, settings.n_bins)
    try:
        feats = histogram_features(h, centres, **_feature_options(fcfg))
    except ValueError:
        raise SceneError(
            f"record {record}: no point within {settings.min_range:g}-{settings.max_range:g} m "
            "in any frame (widen histogram.min_range/max_range)"
        ) from None
    peak = float(h.max())
    with np.errstate(divide="ignore"):
        db = 10.0 * np.log10(np.maximum(h.T / peak, 1e-12))
    return {
        "spectrogram_db": db.astype(np.float32),
        "velocity_mps": centres,
        "time_s": np.arange(cloud.n_frames) * cloud.frame_period,
        "features": feats,
        "histograms": h.astype(np.float32),
    }


def _build_recorded(spec: RecordSpec, out_dir: str) -> dict[str, Any]:
    run = spec.run_config
    recordings = _load_recordings(json.dumps(run["recording"], sort_keys=True), spec.base_dir)
    rec = next(r for r in recordings if r.name == run["name"])
    cloud = rec.cloud.frames(run["first_frame"], run["frames"])
    assert spec.histogram is not None
    arrays = _histogram_arrays(cloud, spec.histogram["histogram"], spec.features, spec.record_id)
    meta = {
        "id": spec.record_id,
        "label": spec.label,
        "group": spec.group,
        "source": run["recording"]["kind"],
        "file": rec.name,
        "subject": spec.subject,
        "dataset": spec.dataset,
        "start_s": run["first_frame"] * cloud.frame_period,
        "duration_s": run["frames"] * cloud.frame_period,
        "aspect_deg": None,
        "radar_position_m": None,
        "height_m": None,
        "seed": None,
        "frame_period_s": cloud.frame_period,
        "first_frame": run["first_frame"],
        "histogram": spec.histogram["histogram"],
        "recording": dict(rec.metadata),
        "recording_name": spec.recording,  # index.csv's recording (``<file>:<name>`` where
        # two files hold a recording of one name, see _distinct_recordings)
        "units": RECORD_UNITS,
    }
    return _write_record(out_dir, spec, meta, arrays)


def _span(motion: dict[str, Any], start: float, end: float) -> tuple[float, float | None] | None:
    """A source's span for :attr:`RecordSpec.span`: None when it gives neither ``start`` nor
    ``duration`` (the whole motion)."""
    if motion.get("start") is None and motion.get("duration") is None:
        return None
    return start, None if motion.get("duration") is None else end


def _augmented(
    motion: Motion,
    draws: dict[str, Any],
    start: float,
    duration: float,
    span: tuple[float, float | None] | None = None,
) -> Any:
    """The augmented motion and the record's start in its time [s] (speed changes the
    timeline: the record keeps the motion phase where it can, else ends at the end of the
    motion, or of the source's ``span`` (start, end or None) [s]: that end is carried through
    the time warp and the speed, so a sped-up record never takes motion from beyond it, and a
    span whose start leaves too little motion at that speed is refused. The record's start is
    its window's divided by the speed; a time warp shifts what it shows by a fraction of the
    warp's strength, as it shifts the whole motion)."""
    speed = float(draws.get("speed", 1.0))
    warp = draws.get("time_warp")
    out = augment_motion(
        motion,
        speed=speed,
        height=float(draws.get("body_scale", 1.0)),
        mirror=bool(draws.get("mirror", False)),
        warp=None if warp is None else np.asarray(warp, dtype=np.float64),
    )
    first, end = 0.0, out.skeleton.duration
    what = "of motion"
    if span is not None:
        first = span[0] / speed
        what = "of the source's span"
        if span[1] is not None:
            whole = motion.skeleton.duration
            at = span[1]
            if warp is not None:
                at = whole * float(warp_function(np.array([span[1] / whole]), warp)[0])
            end = at / speed
    if duration > end - first + 1e-9:
        raise SceneError(
            f"randomize.speed: a speed factor of {speed:.3f} leaves {end - first:.3f} s {what}, "
            f"shorter than the {duration:g} s record"
        )
    return out, min(start / speed, end - duration)


def build_record(spec: RecordSpec, out_dir: str) -> dict[str, Any]:
    """Simulate one record and write it atomically; returns its index row once the file is
    on the disk and in place.

    A record that fails raises :class:`MdfError` naming the record, its source file, window
    and cause; with ``on_error = "skip"`` it returns a row with a ``skipped`` cause instead
    (and writes no file)."""
    return build_records([spec], out_dir)[0]


def record_failure(spec: RecordSpec, exc: Exception) -> tuple[str, str, tuple[str, float, float]]:
    """How a record's failure is named: the record with its label, source file and window
    (``record 00003-<digest> (walk; source file ..., window 1.500-2.500 s)``), the cause (with
    the dataset's length field for ``motion.duration``) and the window (file, start [s],
    length [s])."""
    if spec.window is not None:
        file, start, length = spec.window
    else:
        motion = spec.run_config.get("motion", {})
        file = str(motion.get("file", motion.get("kind", "?")))
        start = float(motion.get("start", 0.0))
        length = float(motion.get("duration") or 0.0)
    where = (
        f"record {spec.record_id} ({spec.label}; source file {file}, window "
        f"{start:.3f}-{start + length:.3f} s)"
    )
    # named once: the record's own errors start with its name too
    cause = " ".join(str(exc).split()).removeprefix(f"record {spec.record_id}: ")
    if spec.length_field is not None:  # the record's duration is the dataset's length
        cause = cause.replace("motion.duration", spec.length_field)
    return where, cause, (file, start, length)


def is_record_failure(exc: Exception) -> bool:
    """Whether ``exc``, raised while a record was built or planned, is the record's own failure
    (its config or data: named with :func:`record_failure`, or skipped with ``on_error =
    "skip"``), not a bug: mdframework's errors, and a ``ValueError`` not out of a plugin."""
    return isinstance(exc, MdfError) or (isinstance(exc, ValueError) and not is_plugin_bug(exc))


def _record_or_skip(spec: RecordSpec, out_dir: str) -> dict[str, Any]:
    """:func:`build_record` but for its wait: the file may still be on its way to the disk."""
    try:
        return _build_record(spec, out_dir)
    except (MdfError, ValueError) as exc:
        if not is_record_failure(exc):  # not the config's: a bug
            exc.add_note(f"while building record {spec.record_id} of {spec.recording}")
            raise
        where, cause, (file, start, length) = record_failure(spec, exc)
        if spec.on_error != "skip":
            raise MdfError(f"{where}: {cause}") from None
        return {
            "id": spec.record_id,
            "label": spec.label,
            "group": spec.group,
            "file": file,
            "start_s": start,
            "duration_s": length,
            "skipped": cause,
        }
    except Exception as exc:
        exc.add_note(f"while building record {spec.record_id} of {spec.recording}")
        raise


def record_motion(spec: RecordSpec) -> Motion:
    """The motion a simulated record is cut from, before its augmentations: loaded once per
    process (:func:`_load_motion`; the records of one recording share it)."""
    section = {k: v for k, v in spec.run_config["motion"].items() if k not in ("start", "duration")}
    return _load_motion(json.dumps(section, sort_keys=True), spec.base_dir)


def _build_record(spec: RecordSpec, out_dir: str) -> dict[str, Any]:
    if "recording" in spec.run_config:
        return _build_recorded(spec, out_dir)
    run_config = spec.run_config
    where = f"record {spec.record_id}"
    # the record's config first: a drawn value its field refuses is named as the draw
    config = validate_record(run_config, where, spec.base_dir, spec.draws, spec.draw_origins)
    motion = record_motion(spec)
    draws = spec.draws or {}
    if any(k in draws for k in ("speed", "body_scale", "mirror", "time_warp")):
        motion, start = _augmented(
            motion,
            draws,
            float(run_config["motion"]["start"]),
            run_config["motion"]["duration"],
            spec.span,
        )
        run_config = {**run_config, "motion": {**run_config["motion"], "start": round(start, 9)}}
        config = validate_run_config(run_config, source=where, base_dir=Path(spec.base_dir))
    stages = build_stages(config)
    result = simulate_motion(config, stages, motion)
    fcfg = spec.features
    extra: dict[str, Any] = {}
    extra_meta: dict[str, Any] = {}
    if spec.histogram is not None:
        cloud = _simulated_cloud(result, config, spec.record_id)
        arrays = _histogram_arrays(cloud, spec.histogram["histogram"], fcfg, spec.record_id)
        feats = arrays["features"]
        extra = {"histograms": arrays["histograms"]}
        spectrogram = {k: arrays[k] for k in ("spectrogram_db", "velocity_mps", "time_s")}
    else:
        options = _feature_options(fcfg)
        env = envelopes(result.spectrogram.power, result.velocity, **options)
        feats = features_from_envelopes(env)
        # counted on the threshold envelope whatever the method: the percentile envelopes of a
        # spectrogram of noise lie a few bins inside the band's edges, not on them
        edge = env
        if options["method"] != "threshold":
            options["method"] = "threshold"
            edge = envelopes(result.spectrogram.power, result.velocity, **options)
        extra_meta["band_edge_frames"] = band_edge_frames(edge, result.velocity)
        spectrogram = {
            "spectrogram_db": result.spectrogram_db.astype(np.float32),
            "velocity_mps": result.velocity,
            "time_s": result.spectrogram.time,
        }
    cfg: Any = config
    meta = {
        "id": spec.record_id,
        "label": spec.label,
        "group": spec.group,
        "source": result.metadata["motion"].get("source", cfg.motion.kind),
        "file": result.metadata["motion"].get("file", ""),
        "subject": spec.subject,
        "recording": spec.recording,
        "dataset": spec.dataset,
        "start_s": cfg.motion.start,
        "duration_s": cfg.motion.duration,
        "aspect_deg": _aspect(
            spec.aspect_deg, cfg.scene.person.aspect_deg, cfg.scene.person.heading_deg
        ),
        "radar_position_m": list(cfg.scene.radar_position),
        "height_m": run_config["motion"].get("height"),
        "seed": cfg.seed,
        "draws": spec.draws,
        "prf_hz": result.metadata["prf_hz"],
        "carrier_frequency_hz": result.metadata["carrier_frequency_hz"],
        "units": {k: v for k, v in RECORD_UNITS.items() if k != "histograms" or extra},
        "run_config": json.loads(cfg.model_dump_json()),
        **extra_meta,
    }
    return _write_record(out_dir, spec, meta, {**spectrogram, "features": feats, **extra})


def _aspect(asked: float | None, aspect: float | None, heading: float | None) -> float | None:
    """A simulated record's aspect angle [deg]: its scene's ``aspect`` (a variation or draw),
    else the one its placement was ``asked`` for (``place = "record"``), else 0 (the scene's
    default, facing the radar) unless the scene gives a ``heading`` instead (None)."""
    if aspect is not None:
        return float(aspect)
    if asked is not None:
        return float(asked)
    return 0.0 if heading is None else None


def _write_record(
    out_dir: str, spec: RecordSpec, meta: dict[str, Any], arrays: dict[str, Any]
) -> dict[str, Any]:
    """Write a record's ``arrays`` (``features`` among them) and ``meta``, with the versions of
    the software that computed it, to its file (in the background, :func:`atomic_savez`), and
    return its index row."""
    meta["versions"] = versions(used=_used_plugins(meta))
    atomic_savez(
        Path(out_dir) / RECORDS / f"{spec.record_id}.npz",
        in_background=True,
        **arrays,
        meta=np.array(json.dumps(meta)),
    )
    return _row(meta, arrays["features"])


def _simulated_cloud(result: Any, config: Any, record: str) -> PointCloud:
    """The point cloud a simulated radar produced: ``received.products["points"]``
    (n_points, 7) with columns frame (from 0 in the record), t [s], x, y, z [m, sensor frame],
    v [m/s, positive approaching], intensity [dB]; the frame period is the radar's
    ``frame_period`` [s]. It holds every frame of the record, up to that of its last pulse, the
    last frames too when they hold no point."""
    products = getattr(result.received, "products", None) or {}
    points = products.get("points")
    period = getattr(config.radar, "frame_period", None)
    if points is None or period is None:
        raise SceneError(
            f"record {record}: representation = 'histogram' needs a radar that outputs point "
            "clouds frame by frame (e.g. kind = 'fmcw' with points = true); this one does not"
        )
    pts = np.asarray(points, dtype=np.float64)
    frame = pts[:, 0].astype(np.int64)
    times = np.asarray(result.pulse_times, dtype=np.float64)  # from the first pulse
    last = int(np.floor(float(times[-1]) / float(period) + 1e-9)) if times.size else 0
    n_frames = max(last + 1, int(frame.max()) + 1 if frame.size else 1)
    return PointCloud(frame, pts[:, 2:5], pts[:, 5], pts[:, 6], float(period), n_frames)


def _blank(value: Any) -> Any:
    return "" if value is None else value


def _draw_columns(draws: dict[str, Any] | None) -> dict[str, Any]:
    """Table columns ``draw.<name>`` of a record's drawn values (lists spread over
    ``draw.<name>.<i>``, booleans as 0/1)."""
    out: dict[str, Any] = {}
    for name, value in (draws or {}).items():
        if isinstance(value, list):
            out.update({f"draw.{name}.{i}": v for i, v in enumerate(value, start=1)})
        else:
            out[f"draw.{name}"] = int(value) if isinstance(value, bool) else value
    return out


def _row(meta: dict[str, Any], feats: NDArray[np.float64]) -> dict[str, Any]:
    radar = meta["radar_position_m"] or (None, None, None)
    row = {
        "id": meta["id"],
        "label": meta["label"],
        "group": meta["group"],
        "source": meta["source"],
        "file": meta["file"],
        "subject": meta.get("subject", ""),
        "recording": meta.get("recording", meta["file"])
        if isinstance(meta.get("recording", ""), str)
        else meta.get("recording_name", meta["file"]),  # a recorded record's: its metadata
        "dataset": meta.get("dataset", meta["source"]),
        "start_s": meta["start_s"],
        "duration_s": meta["duration_s"],
        "aspect_deg": _blank(meta["aspect_deg"]),
        "radar_x_m": _blank(radar[0]),
        "radar_y_m": _blank(radar[1]),
        "radar_z_m": _blank(radar[2]),
        "height_m": _blank(meta["height_m"]),
        "seed": _blank(meta["seed"]),
        "band_edge_frames": _blank(meta.get("band_edge_frames")),
    }
    row.update({name: float(f) for name, f in zip(FEATURE_NAMES, feats, strict=True)})
    row.update(_draw_columns(meta.get("draws")))
    return row


def read_record(path: Path) -> tuple[dict[str, NDArray[Any]], dict[str, Any]]:
    """Arrays and metadata of one record file; raises if it is incomplete or corrupt.

    A build stores a record's arrays uncompressed, so the file holds every byte they take: a
    compressed member (a few megabytes of a crafted file could expand into gigabytes) is a
    corrupt record (``ValueError``), refused before anything is read from it, and so is a
    file that is not a regular one (a pipe, a device)."""
    with _record_file(path) as data:
        arrays = {k: data[k] for k in ("spectrogram_db", "velocity_mps", "time_s", "features")}
        if "histograms" in data.files:
            arrays["histograms"] = data["histograms"]
        meta = json.loads(str(data["meta"]))
    return arrays, meta


@contextmanager
def _record_file(path: Path) -> Iterator[Any]:
    """A record file opened (``np.load``) once it is known to be a regular file with no
    compressed member (see :func:`read_record`)."""
    import stat
    import zipfile

    if not stat.S_ISREG(os.stat(path).st_mode):  # a pipe would never end, a device fill memory
        raise ValueError(f"{path}: not a regular file")
    with np.load(path) as data:
        packed = [i.filename for i in data.zip.infolist() if i.compress_type != zipfile.ZIP_STORED]
        if packed:
            raise ValueError(f"{path}: {packed[0]} is compressed")
        yield data


def _planned_meta(spec: RecordSpec) -> dict[str, Any]:
    """What a record stores of its source's naming (label, group and, for simulated records,
    subject, recording and dataset) as the config now asks for it: not part of the record's
    id, so a build keeps a record whose only change is one of them and relabels it."""
    planned = {
        "label": spec.label,
        "group": spec.group,
        "subject": spec.subject,
        "dataset": spec.dataset,
    }
    if "recording" not in spec.run_config:
        planned["recording"] = spec.recording
    else:  # a recorded record's "recording" holds the recording's metadata
        planned["recording_name"] = spec.recording
    return planned


def _complete(
    path: Path, spec: RecordSpec, other_versions: dict[str, Any]
) -> dict[str, Any] | None:
    """The index row of a finished record, or None if it must be (re)built: a record cut
    short, corrupt, or whose metadata lacks a field or names another record is removed. A
    record whose label, group, subject, recording or dataset differ from ``spec``'s (the
    config changed only those) is kept and rewritten with the new ones (atomically; its arrays
    are not recomputed), and so is its row; so is one written before dataset format 1 whose
    ``aspect_deg`` is null for the scene's default aspect (now 0). A record that cannot be
    read for want of permission, or because the disk fails to give it (an ``OSError`` with an
    errno, such as EIO or NFS's ESTALE), is an error (it is not removed). A record computed by
    other software versions than this process's is kept, its id, its versions (``None``: a record
    written before records named theirs) and this process's added to ``other_versions``."""
    import zipfile

    if path.is_dir() and not path.is_symlink():  # not ours to delete
        raise OutputError(
            f"{path}: a folder where the dataset has a record's file; move it away and run the "
            "build again"
        )
    if not path.exists():
        return None
    try:
        arrays, meta = read_record(path)
        if meta["id"] != spec.record_id:  # another record's file, copied or renamed here
            raise ValueError(f"{path}: holds record {meta['id']}")
        made_by = meta.get("versions")  # None: by a version before records named theirs
        now = versions(used=_used_plugins(meta))
        if made_by != now:
            other_versions[spec.record_id] = (made_by, now)
        planned = _planned_meta(spec)
        run = meta.get("run_config")
        if meta["aspect_deg"] is None and run is not None:  # written before format 1, which
            person = run["scene"]["person"]  # writes the scene's default aspect as 0
            aspect = _aspect(spec.aspect_deg, person["aspect_deg"], person["heading_deg"])
            if aspect is not None:
                planned["aspect_deg"] = aspect
        renamed = any(meta.get(k) != v for k, v in planned.items())
        meta.update(planned)
        row = _row(meta, arrays["features"])  # (a field missing: a corrupt record)
    except PermissionError as exc:
        raise _not_yours(path, exc) from None
    except OSError as exc:
        if exc.errno not in (None, errno.ENOENT):  # the disk failed (EIO, NFS's ESTALE), not
            raise  # the record: keep it, and the command says what failed
        path.unlink(missing_ok=True)
        return None
    except (EOFError, ValueError, KeyError, TypeError, zipfile.BadZipFile):
        path.unlink(missing_ok=True)
        return None
    if renamed:  # a failure to write (a full disk) stops the build; the record stays as it was
        stored: dict[str, Any] = {**arrays, "meta": np.array(json.dumps(meta))}
        try:
            atomic_savez(path, **stored)
        except PermissionError as exc:
            raise _not_yours(path, exc) from None
    return row


def _not_yours(path: Path, exc: PermissionError) -> OutputError:
    return OutputError(
        f"{path}: {exc.strerror or exc}: a record of this dataset must be readable and "
        "writable by you to resume it; fix its permissions or build into another --out"
    )


def build_records(specs: list[RecordSpec], out_dir: str) -> list[dict[str, Any]]:
    """Build several records in one task, in order (:func:`build_record` each); their rows.
    Each record's file is flushed to the disk while the next one is computed; every file is in
    place before the rows are returned (:func:`mdframework.outdir.wait_for_files`)."""
    try:
        rows = [_record_or_skip(spec, out_dir) for spec in specs]
    except BaseException:
        wait_for_files(raise_errors=False)  # the records written so far land; this error wins
        raise
    wait_for_files()
    return rows


def record_chunks(specs: list[RecordSpec], threads: int) -> list[list[RecordSpec]]:
    """Consecutive records grouped into tasks for ``threads`` worker threads, in order. Each
    task takes a share of the records still left: ``1 / (threads * TASKS_PER_THREAD)`` of
    them, at most :data:`MAX_RECORDS_PER_TASK` and at least one, so that tasks shrink to single
    records towards the end and the workers finish together (guided self-scheduling)."""
    share = max(threads, 1) * TASKS_PER_THREAD
    chunks: list[list[RecordSpec]] = []
    start = 0
    while start < len(specs):
        size = max(1, min(MAX_RECORDS_PER_TASK, (len(specs) - start) // share))
        chunks.append(specs[start : start + size])
        start += size
    return chunks


def _executor(
    config: DatasetConfig, workers: int | None, scheduler: str | None
) -> Generator[Callable[[list[RecordSpec], str], Iterator[dict[str, Any]]], None, None]:
    """Yield a map function running records locally or on Dask (a generator so that clusters
    are closed afterwards). Local worker processes end when this process ends, however it ends
    (:func:`mdframework.workers.die_with_parent` for the process pool; a local Dask cluster's
    workers watch their parent themselves; both tested by killing the parent)."""
    from .workers import warning_filters, worker_pool

    address = scheduler_address(scheduler)
    n = build_workers(config, workers)
    if address is None:
        if n == 1:  # in this process, in tasks too (rows come a task at a time)
            yield lambda specs, out: (
                row for chunk in record_chunks(specs, 1) for row in build_records(chunk, out)
            )
            return
        # Ctrl-C or an error (the generator closed): the queued records are dropped. Workers
        # that are not forked (macOS) are sent the motions planning loaded, as Dask's are.
        with worker_pool(n, _start_fresh_worker, (dict(_MOTIONS),)) as pool:

            def run_local(specs: list[RecordSpec], out: str) -> Iterator[dict[str, Any]]:
                chunks = record_chunks(specs, n)
                futures = [pool.submit(build_records, chunk, out) for chunk in chunks]
                for fut in as_completed(futures):
                    yield from fut.result()

            yield run_local
        return
    try:
        from distributed import Client, LocalCluster
        from distributed import as_completed as dask_completed
        from distributed.scheduler import KilledWorker
    except ImportError:
        raise SettingError("a Dask scheduler needs `pip install mdframework[dask]`") from None
    import dask

    with quiet_dask_logs():  # Dask's log of a failure or Ctrl-C would surround the line
        with dask.config.set(LOCAL_DASK_CONFIG):
            # no dashboard; the scheduler's HTTP server (health and metrics routes) still
            # starts, by default on port 8787 (and warns when another cluster has it): on a free
            # port of the loopback interface instead
            cluster = (
                LocalCluster(
                    n_workers=n,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
                    scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                )
                if address == "local"
                else None
            )
        client = connect(Client, cluster, address)
        try:
            if cluster is not None:
                client.run(quiet_dask_worker, warnings.showwarning, warning_filters())
            else:
                check_workers(client, address, DatasetWarning)
            # each worker gets what planning loaded; one that left meanwhile (killed,
            # restarting) does without: a worker loads what it was not given itself
            client.run(_receive_motions, dict(_MOTIONS), on_error="ignore")

            def run_dask(specs: list[RecordSpec], out: str) -> Iterator[dict[str, Any]]:
                if cluster is None:  # workers of one's own: on other machines, maybe
                    check_paths(client, [str(Path(out) / RECORDS), *_data_files(specs)])
                threads = sum(client.nthreads().values()) or n
                chunks = record_chunks(specs, threads)
                futures = client.map(build_records, chunks, out_dir=out, pure=False)
                first = {
                    fut.key: chunk[0].record_id for fut, chunk in zip(futures, chunks, strict=True)
                }
                watch = Workerless(client, futures, address)
                watch.start()
                try:
                    for fut in dask_completed(futures):
                        try:
                            rows = fut.result()
                        except (CancelledError, KilledWorker) as exc:
                            error = watch.error or cluster_failure(
                                exc, address, first[fut.key], out
                            )
                            raise error from None
                        yield from rows
                finally:
                    watch.stop()

            yield run_dask
        finally:
            client.close()
            if cluster is not None:
                cluster.close()


def _data_files(specs: list[RecordSpec]) -> list[str]:
    """The motion and recording files the ``specs`` read, by the absolute paths the workers
    open."""
    files: dict[str, None] = {}
    for spec in specs:
        read = _record_file_of(spec)
        if read is not None:
            files[os.path.abspath(read[1])] = None
    return list(files)


def dataset_folder(out: str | Path, *, force: bool = False) -> AbstractContextManager[OutputFolder]:
    """Open ``out`` for a dataset build (see :func:`mdframework.outdir.output_folder`)."""
    return output_folder(out, "dataset", DATASET_FILES, force=force)


def _comparable(config: DatasetConfig) -> dict[str, Any]:
    """The config as JSON, without the build options that do not change the dataset."""
    data: dict[str, Any] = json.loads(config.model_dump_json())
    return {k: v for k, v in data.items() if k not in BUILD_OPTIONS}


def _built_from(folder: OutputFolder) -> dict[str, Any] | None:
    """The config the folder's dataset was (or is being) built from; None for a new folder."""
    if not folder.previous:
        return None
    built = folder.marker.get("config")
    if built is None and (folder.path / MANIFEST).exists():  # built before markers existed
        try:
            built = json.loads(read_marker_text(folder.path / MANIFEST)).get("config")
        except (OSError, ValueError, AttributeError):
            built = None
    if not isinstance(built, dict):
        return None
    return {k: v for k, v in built.items() if k not in BUILD_OPTIONS}


def _indexed_configs(folder: OutputFolder, built: dict[str, Any] | None) -> list[dict[str, Any]]:
    """The configs that the folder's ``index.csv`` (and ``dataset.json``) may have been written
    from (``built``: the marker's config): the marker's config once its build completed; while
    a build runs, the configs its marker lists under ``indexed`` (the earlier, complete
    dataset's, kept whole until the new index is written, then also the new one's, while the
    new index and manifest are written and the old records removed). Empty for a folder
    without a complete dataset."""
    if not folder.previous:
        return []
    if folder.marker.get("complete") is True or not folder.marker:  # not folder.marker: legacy
        return [] if built is None else [built]
    listed = folder.marker.get("indexed")
    if not isinstance(listed, list):
        return []
    return [
        {k: v for k, v in c.items() if k not in BUILD_OPTIONS}
        for c in listed
        if isinstance(c, dict)
    ]


def config_differences(old: Any, new: Any, where: str = "") -> list[str]:
    """Dotted names of the fields that differ between two JSON-like configs, with both values
    (``"variations.aspect_deg: [0.0, 45.0] -> [0.0, 30.0]"``)."""
    if isinstance(old, dict) and isinstance(new, dict):
        out = []
        for key in sorted(set(old) | set(new), key=str):
            name = f"{where}.{key}" if where else str(key)
            if key not in old:
                out.append(f"{name}: new")
            elif key not in new:
                out.append(f"{name}: removed")
            else:
                out += config_differences(old[key], new[key], name)
        return out
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        out = []
        for i, (a, b) in enumerate(zip(old, new, strict=True)):
            out += config_differences(a, b, f"{where}[{i}]")
        return out
    if old == new:
        return []
    return [f"{where or 'config'}: {json.dumps(old)} -> {json.dumps(new)}"]


def _used_plugins(meta: dict[str, Any]) -> list[tuple[str, str]]:
    """The (interface, kind) of every plugin a record ran, from its metadata: a real radar's
    recording source, or the motion source, scatterers, radar and effects of its run config."""
    run = meta.get("run_config")
    if run is None:
        return [("recording", str(meta["source"]))]
    return [(s, run[s]["kind"]) for s in ("motion", "scatterers", "radar")] + [
        ("effects", e["kind"]) for e in run.get("effects", [])
    ]


def _warn_other_ids(out: Path, specs: list[RecordSpec], kept: int) -> None:
    """Warn once when a folder resumed with its own config holds records of other ids than
    the build's (``kept`` of its records are the build's): an earlier version of mdframework
    whose records had other ids (0.2.0's seeds came from the records' numbers), or motion
    files changed since; every record of the folder was computed afresh without a word, and
    a dataset of days of compute looked resumed."""
    ours = {f"{s.record_id}.npz" for s in specs}
    others = [p.name for p in (out / RECORDS).glob("*.npz") if p.name not in ours]
    others = sorted(name for name in others if _RECORD_NAME.fullmatch(name))
    if not others:
        return
    warnings.warn(
        f"{len(others)} records in {out / RECORDS} (e.g. {others[0][:-4]}) are not records of "
        f"this config as this version computes it (an earlier version of mdframework gave "
        f"records other ids and seeds, or their motion files changed since): {kept} of the "
        f"build's {len(specs)} records are there, the others are computed afresh, and those "
        "of other ids are removed when the build ends",
        DatasetWarning,
        stacklevel=3,
    )


def _warn_other_versions(made_by: dict[str, Any], n_records: int) -> None:
    """Warn once when records kept from the folder were computed by other software versions
    (``made_by``: record id -> its ``versions``, ``None`` for a record written before records
    named theirs, and this process's for the same plugins): a record's id covers its config,
    not the software, so a build after an upgrade keeps them."""
    if not made_by:
        return
    first = next(iter(made_by))
    unnamed = sum(old is None for old, _ in made_by.values())
    said = [f"{unnamed} by a version from before records named their versions"] if unnamed else []
    named = next(((old, now) for old, now in made_by.values() if old is not None), None)
    if named is not None:
        diff = config_differences(*named)
        said.append("; ".join(diff[:3]) + (f" and {len(diff) - 3} more" if len(diff) > 3 else ""))
    shown = "; ".join(said)
    warnings.warn(
        f"{len(made_by)} of {n_records} records (e.g. {first}) were computed by other "
        f"software versions ({shown}) and are kept, as their config is the same: the dataset "
        "mixes versions; build into a new folder to compute every record with these",
        DatasetWarning,
        stacklevel=3,
    )


def _warn_band_edges(rows: list[dict[str, Any]]) -> None:
    """One warning for the records whose features' envelope reaches the edge of the Doppler
    band in some frame (``band_edge_frames`` > 0 in ``index.csv``; blank for histogram and
    recorded records)."""
    edged = [
        r for r in rows if isinstance(r.get("band_edge_frames"), int) and r["band_edge_frames"]
    ]
    if edged:
        warnings.warn(
            f"{len(edged)} of {len(rows)} records (e.g. {edged[0]['id']}) have frames where the "
            "features' envelope reaches the edge of the Doppler band (index.csv column "
            "band_edge_frames): their upper_max, lower_min and bandwidths are the band's, not "
            "the body's: the body's Doppler aliases, or the spectrograms stand too little above "
            "the noise (raise the pulse rate or the signal-to-noise ratio)",
            DatasetWarning,
            stacklevel=3,
        )


def build_dataset(
    config: DatasetConfig,
    base_dir: Path,
    out_dir: Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    force: bool = False,
) -> list[dict[str, Any]]:
    """Build (or finish building) a dataset; returns the index rows in record order.

    ``out_dir`` must be new, empty, or hold a dataset of the same config (resumed); ``force``
    also accepts other folders (writing only the dataset's files) and other configs (rebuilt;
    the old dataset stays whole until the new index is written, then its records are removed).
    """
    check_scheduler_address(scheduler_address(scheduler))
    with dataset_folder(out_dir, force=force) as folder:
        _refuse_names_in_the_way(folder.path)
        _refuse_newer_format(folder.path)
        note("planning the records (reading each recording once)", progress)
        _forget_loaded()  # every file is read afresh: one changed since is seen
        # errors in the config stop before any file. Records name their files, and are
        # written, by absolute paths: a Dask cluster's workers have working folders of their own
        base_dir = Path(os.path.abspath(base_dir))
        specs = plan_records(config, base_dir, workers=build_workers(config, workers))
        out = folder.path
        wanted = _comparable(config)
        built = _built_from(folder)
        indexed = _indexed_configs(folder, built)
        ours = folder.previous  # the folder holds an earlier build: its files are ours
        # the config of the build under way (resumed), or of the complete dataset that a
        # stopped rebuild left in place (finished from its records, any missing one recomputed)
        if built is not None and built != wanted and wanted not in indexed and not force:
            diff = config_differences(built, wanted)
            shown = "; ".join(diff[:3]) + (f" and {len(diff) - 3} more" if len(diff) > 3 else "")
            raise OutputError(
                f"--out {out}: holds a dataset built from a different config ({shown}); "
                "choose another folder, or add --force to rebuild it"
            )
        # the marker names the config being built and the ones the index in place may be of,
        # so that a build killed at any moment can be resumed, or undone with the old config
        folder.write_marker(config=wanted, complete=False, indexed=indexed)
        (out / RECORDS).mkdir(exist_ok=True)
        if ours:
            _remove_partials(out)
        rows: dict[str, dict[str, Any]] = {}
        todo = []
        other_versions: dict[str, Any] = {}
        for spec in specs:
            row = _complete(out / RECORDS / f"{spec.record_id}.npz", spec, other_versions)
            if row is None:
                todo.append(spec)
            else:
                rows[spec.record_id] = row
        _warn_other_versions(other_versions, len(specs))
        if built == wanted and all(c == wanted for c in indexed):
            _warn_other_ids(out, specs, len(rows))
        printed()
        bar = tqdm_bar(
            total=len(specs),
            initial=len(rows),
            desc="records",
            unit="rec",
            disable=not progress_enabled(progress),
        )
        skipped: dict[str, dict[str, Any]] = {}
        executor = _executor(config, workers, scheduler)
        try:
            with closing(executor), bar:  # closing: workers stop at once on Ctrl-C or an error
                for run in executor:
                    for row in run(todo, os.path.abspath(out)):
                        if "skipped" in row:
                            skipped[row["id"]] = row
                            warnings.warn(
                                f"record {row['id']} ({row['file']}, window "
                                f"{row['start_s']:.3f} s + {row['duration_s']:g} s) skipped: "
                                f"{row['skipped']}",
                                DatasetWarning,
                                stacklevel=2,
                            )
                        else:
                            rows[row["id"]] = row
                        bar.update(1)
        except BaseException:
            _remove_partials(out)  # of records that stopped workers were writing
            raise
        _remove_partials(out)  # of Dask workers killed while writing (their tasks ran again)
        ordered = [rows[s.record_id] for s in specs if s.record_id in rows]
        if not ordered:
            first = next(iter(skipped.values()))["skipped"]
            raise MdfError(f"every record failed; the first: {first}")
        dropped = [skipped[s.record_id] for s in specs if s.record_id in skipped]
        _warn_band_edges(ordered)
        # three files, each replaced whole: a kill between them leaves them not matching, and
        # the marker says so until the build ends (load_dataset refuses such a folder)
        if wanted not in indexed:  # from now on the index may be the new one
            indexed = [*indexed, wanted]
        folder.write_marker(config=wanted, complete=False, indexed=indexed, index=INDEX_WRITING)
        _write_index(out, ordered, config, dropped)
        if ours:  # records of an earlier config, now that the new index is in place
            keep = {f"{s.record_id}.npz" for s in specs}
            for old in (out / RECORDS).glob("*.npz"):
                if old.name not in keep and _RECORD_NAME.fullmatch(old.name):
                    old.unlink()
        folder.write_marker(config=wanted, complete=True, indexed=[wanted])
    return ordered


#: a record's file name (``{index:05d}-{digest}.npz``) and a record being written
#: (:func:`atomic_savez`'s temporary file): the only files of ``records/`` a build removes
_RECORD_NAME = re.compile(r"\d{5,}-[0-9a-f]{10}\.npz")
_PARTIAL_NAME = re.compile(r"\.tmp-\w+\.(part|npz)")  # .npz: earlier versions


def _refuse_newer_format(out: Path) -> None:
    """:class:`OutputError` for a folder whose ``dataset.json`` a newer mdframework wrote (a
    ``format_version`` above :data:`DATASET_FORMAT`), with ``--force`` too: a build would keep
    its records, which this version cannot read, and relabel the folder as its own format."""
    try:
        manifest = json.loads(limits.read_file_bytes(out / MANIFEST).decode("utf-8"))
    except (OSError, DataFileError, ValueError):  # none, or not the file a build writes
        return
    made = manifest.get("format_version") if isinstance(manifest, dict) else None
    if isinstance(made, int) and not isinstance(made, bool) and made > DATASET_FORMAT:
        raise OutputError(
            f"--out {out}: holds a dataset of format_version {made}, newer than this mdframework "
            f"writes ({DATASET_FORMAT}); upgrade mdframework, or build into another folder"
        )


def _refuse_names_in_the_way(out: Path) -> None:
    """:class:`OutputError` for a name the build writes that holds the other kind of entry: a
    file (anything but a folder) named ``records``, a folder named as one of the index files;
    and for ``records`` that is a link to a folder (outside ``out``; one to a file, or to
    nothing, is a file in the way).
    Checked before anything is written, with ``--force`` too (which replaces files of the
    dataset's names, never a folder, and needs ``records`` to be one)."""
    records = out / RECORDS  # a link to a folder: records written, and removed, elsewhere
    if records.is_symlink() and records.is_dir():
        raise OutputError(
            f"--out {out}: its {RECORDS!r} is a link to another folder, where `mdf dataset` "
            "would write and remove records; replace it with a folder or choose another folder"
        )
    for name in DATASET_FILES:
        path = out / name
        if not os.path.lexists(path) or path.is_dir() == (name == RECORDS):
            continue
        kind, writes = ("file", "folder") if name == RECORDS else ("folder", "file")
        raise OutputError(
            f"--out {out}: holds the {kind} {name!r}, where `mdf dataset` writes a {writes}; "
            "move it away or choose another folder"
        )


def _remove_partials(out: Path) -> None:
    """Remove the records that were being written when a build stopped."""
    for partial in (out / RECORDS).glob(".tmp-*"):
        if _PARTIAL_NAME.fullmatch(partial.name):
            partial.unlink(missing_ok=True)


#: the marker's ``index`` while the index files are being replaced
INDEX_WRITING = "writing"


def _index_half_written(root: Path) -> bool:
    """Whether the build of the dataset at ``root`` stopped while it wrote its index files."""
    try:
        marker = json.loads(read_marker_text(root / marker_name("dataset")))
    except (OSError, ValueError):
        return False
    return isinstance(marker, dict) and marker.get("index") == INDEX_WRITING


def _write_index(
    out: Path,
    rows: list[dict[str, Any]],
    config: DatasetConfig,
    skipped: list[dict[str, Any]] | None = None,
) -> None:
    buf = io.StringIO()
    fields = list(dict.fromkeys(k for row in rows for k in row))  # draws vary by source
    writer = csv.DictWriter(buf, fieldnames=fields, lineterminator="\n", restval="")
    writer.writeheader()
    writer.writerows(rows)
    index_text = buf.getvalue()
    atomic_write_text(out / INDEX, index_text)
    skipped = skipped or []
    if skipped:
        sbuf = io.StringIO()
        swriter = csv.DictWriter(sbuf, fieldnames=list(skipped[0]), lineterminator="\n")
        swriter.writeheader()
        swriter.writerows(skipped)
        atomic_write_text(out / SKIPPED, sbuf.getvalue())
    else:
        (out / SKIPPED).unlink(missing_ok=True)
    manifest = {
        "format_version": DATASET_FORMAT,
        "n_records": len(rows),
        "n_skipped": len(skipped),
        "skipped": skipped,
        "feature_names": list(FEATURE_NAMES),
        "feature_units": "m/s",
        "labels": sorted({r["label"] for r in rows}),
        "config": json.loads(config.model_dump_json()),
        "versions": versions(),  # of the build that wrote the index (records may be older)
        # what load_dataset checks the index against: one cut short or edited is refused
        INDEX_DIGEST: hashlib.sha256(index_text.encode("utf-8")).hexdigest(),
    }
    atomic_write_text(out / MANIFEST, json.dumps(manifest, indent=2) + "\n")


@dataclass(frozen=True)
class Dataset:
    """A loaded dataset.

    ``features`` (n_records, 7) float64 [m/s]; ``labels`` (n_records,) str; ``groups``
    (n_records,) str; ``table``: column name -> (n_records,) array (all of index.csv, ready for
    ``pandas.DataFrame(table)``); ``spectrograms``: (n_records, n_doppler, n_frames) float32
    [dB] when all records have the same shape, else a list; ``velocity`` (n_doppler,) [m/s] of
    the first record; ``histograms`` (when asked for): per record its per-frame Doppler
    histograms (n_frames, n_bins) float32, or None for a spectrogram record.
    """

    features: NDArray[np.float64]
    labels: NDArray[np.str_]
    groups: NDArray[np.str_]
    table: dict[str, NDArray[Any]]
    spectrograms: NDArray[np.float32] | list[NDArray[np.float32]] | None
    velocity: NDArray[np.float64] | None
    histograms: list[NDArray[np.float32] | None] | None = None


def _load_record(path: Path, names: Sequence[str] | None = None) -> dict[str, NDArray[Any]]:
    """The arrays of one record of a built dataset (those ``names``, else all); a record file
    that is missing or damaged (deleted or changed since the build) is a
    :class:`DataFileError` naming it. ``histograms`` is left out where the record has none."""
    import zipfile

    try:
        if names is None:
            return read_record(path)[0]
        with _record_file(path) as data:  # the others are not read at all
            return {k: data[k] for k in names if k != "histograms" or k in data.files}
    except FileNotFoundError:
        problem = "missing"
    except PermissionError as exc:
        raise DataFileError(path, exc.strerror or str(exc)) from None
    except (OSError, EOFError, ValueError, KeyError, TypeError, zipfile.BadZipFile):
        problem = "not a complete record file"
    raise DataFileError(
        path,
        f"{problem}, though index.csv lists it; run the `mdf dataset build` that made the "
        "dataset again to rebuild it",
    )


def _verified_index(root: Path) -> str:
    """The text of the dataset's ``index.csv``, checked against what the build wrote: the digest
    in ``dataset.json`` (builds since November 2026; an index cut short or edited since the build
    would otherwise give an experiment wrong records, labels or features without a word), and a
    header's number of fields on every row. Anything else is a :class:`DataFileError` that says
    how to fix it: the same ``mdf dataset build``, run again, rewrites both files from the
    records."""
    index = root / INDEX
    rebuild = "run the same `mdf dataset build` again to rewrite it from the records"
    data = limits.read_file_bytes(index)  # (a received pipe or device: refused unread)
    manifest_path = root / MANIFEST
    if not manifest_path.exists():
        raise DataFileError(manifest_path, f"missing, though {INDEX} is there; {rebuild}")
    try:
        manifest = json.loads(limits.read_file_bytes(manifest_path).decode("utf-8"))
    except (ValueError, UnicodeDecodeError) as exc:
        raise DataFileError(
            manifest_path, f"not valid JSON ({' '.join(str(exc).split())}); {rebuild}"
        ) from None
    digest = manifest.get(INDEX_DIGEST) if isinstance(manifest, dict) else None
    if not isinstance(manifest, dict) or (digest is not None and not isinstance(digest, str)):
        raise DataFileError(manifest_path, f"not the file a build writes; {rebuild}")
    made = manifest.get("format_version", DATASET_FORMAT)  # absent: before format versions
    if isinstance(made, bool) or not isinstance(made, int) or made < 1:  # not "newer"
        raise DataFileError(
            manifest_path,
            f"format_version {made!r} is not a format's number (1, 2, ...); {rebuild}",
        )
    if made > DATASET_FORMAT:
        raise DataFileError(
            manifest_path,
            f"format_version {made!r}: a dataset of a newer format than this mdframework reads "
            f"({DATASET_FORMAT}); upgrade mdframework to read it",
        )
    if digest is not None and hashlib.sha256(data).hexdigest() != digest:
        raise DataFileError(
            index,
            f"not the file the build wrote (cut short or edited since: it does not match the "
            f"digest in {MANIFEST}); {rebuild}",
        )
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise DataFileError(index, f"not UTF-8 text ({exc.reason}); {rebuild}") from None
    if text and not text.endswith("\n"):  # a build ends every row with one
        raise DataFileError(index, f"cut short (its last row is incomplete); {rebuild}")
    reader = csv.reader(io.StringIO(text, newline=""))
    header = next(reader, [])
    for row in reader:
        if len(row) != len(header):
            raise DataFileError(
                index,
                f"{len(row)} fields where the header has {len(header)} (cut short or edited "
                f"since the build); {rebuild}",
                reader.line_num,
            )
    return text


def record_arrays(
    root: str | Path, ids: Iterable[str], names: Sequence[str] | None = None
) -> Iterator[dict[str, NDArray[Any]]]:
    """The arrays of the records ``ids`` (``Dataset.table["id"]``) of the built dataset at
    ``root``, one record at a time, in order, so that a caller that reduces each record (e.g.
    to its histogram vector) never holds them all: :func:`read_record`'s arrays, or only those
    ``names`` (the others not read; ``histograms`` left out of a record without them). An id
    that is not a plain file name, or a record file missing or damaged, is a
    :class:`DataFileError`."""
    root = Path(root)
    for line, rid in enumerate(ids, start=2):
        if safe_name(str(rid)) != rid:  # a record id names a file inside records/ only
            raise DataFileError(root / INDEX, f"record id {str(rid)!r} is not a plain name", line)
        yield _load_record(root / RECORDS / f"{rid}.npz", names)


def load_dataset(
    path: str | Path, *, spectrograms: bool = True, histograms: bool = False
) -> Dataset:
    """Load a built dataset in one call (arrays plus the index table): a :class:`Dataset`.

    ``features`` (n_records, 7) float64 [m/s], ``labels`` and ``groups`` (n_records,) str and
    ``table`` (every column of ``index.csv``) come from ``index.csv``. ``spectrograms`` (the
    default) also reads every record's ``spectrogram_db`` (n_doppler, n_frames) float32 [dB re
    peak], all held at once (:func:`record_arrays` gives them one at a time), and the first
    record's ``velocity_mps``; ``histograms`` reads each record's per-frame histograms
    (n_frames, n_bins) float32 (``None`` for a spectrogram record). A folder that is not a
    complete build, or that a build is writing, is an :class:`MdfError`; an ``index.csv``
    edited since the build, or a record file missing or damaged, a :class:`DataFileError`."""
    root = Path(path)
    index = root / INDEX
    holder = lock_holder(root)
    # a build (or another command given the folder as --out) is writing it; not this process
    if holder is not None and holder.get("pid") != os.getpid():
        raise MdfError(
            f"{root}: being written by {describe_holder(holder)}; wait for it to finish and "
            "try again"
        )
    if not index.exists():
        raise MdfError(f"{root}: not a built dataset (no {INDEX}); run `mdf dataset build`")
    if _index_half_written(root):
        raise MdfError(
            f"{root}: the build stopped while it wrote {INDEX}, {SKIPPED} and {MANIFEST} (they "
            "may not match); run the same `mdf dataset build` again to finish it"
        )
    rows = list(csv.DictReader(io.StringIO(_verified_index(root), newline="")))
    if not rows:
        raise MdfError(f"{index}: the dataset has no records")
    table: dict[str, NDArray[Any]] = {}
    for key in rows[0]:
        col = [r[key] for r in rows]
        try:
            numbers = None if key in TEXT_COLUMNS else [float(c) if c else np.nan for c in col]
        except ValueError:  # a drawn choice of strings
            numbers = None
        table[key] = np.array(col, dtype=str) if numbers is None else np.array(numbers)
    feats = np.stack([table[n].astype(np.float64) for n in FEATURE_NAMES], axis=1)
    specs: NDArray[np.float32] | list[NDArray[np.float32]] | None = None
    velocity = None
    hists: list[NDArray[np.float32] | None] | None = [] if histograms else None
    if spectrograms or histograms:
        maps = []
        # without spectrograms only the velocity axis and histograms are read (histogram
        # records' dB maps are as large as their histograms)
        names = None if spectrograms else ("velocity_mps", "histograms")
        for arrays in record_arrays(root, table["id"], names):
            if spectrograms:
                maps.append(arrays["spectrogram_db"])
            velocity = arrays["velocity_mps"] if velocity is None else velocity
            if hists is not None:
                hists.append(arrays.get("histograms"))
        if spectrograms:
            same = len({m.shape for m in maps}) == 1
            specs = np.stack(maps) if same else maps
    return Dataset(
        feats,
        table["label"].astype(str),
        table["group"].astype(str),
        table,
        specs,
        velocity,
        hists,
    )
