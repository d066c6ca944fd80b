"""The ``mdf`` command line.

Errors caused by input (config, data files, the scene) print one line and exit with code 2; add
``--debug`` (anywhere on the command line) for the traceback. ``--disable-plugin NAME`` (also
anywhere, repeatable) switches one plugin off. This module imports nothing heavy: each command
imports what it needs when it runs, so ``mdf --help`` and ``mdf plugins`` start fast.
"""

from __future__ import annotations

import argparse
import errno
import json
import os
import signal
import sys
import textwrap
import threading
import traceback
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any, NoReturn

from .errors import (
    DataFileError,
    MdfError,
    OutputError,
    SettingError,
    caused_by_interrupt,
    interrupt_seen,
    note_interrupt,
)
from .plugins import (
    DISABLE_ENV,
    DISABLE_PLUGINS_ENV,
    INTERFACES,
    SLOW_IMPORTS,
    PluginError,
    add_cli_commands,
    autoload_enabled,
    default_registry,
    disabled_by_user,
    installed_names,
    mdframework_version,
    reset_default_registry,
    suggest,
)
from .progress import Progress, check_progress_setting, printed, retract, safe_stderr, say

EXIT_USAGE = 2
EXIT_INTERRUPTED = 130
#: exit code after SIGTERM (what a batch system such as SLURM sends at a job's time limit)
EXIT_TERMINATED = 143
#: the signal that ended the command (SIGINT or SIGTERM), set by :func:`_catch_interrupts`
_ENDED_BY: list[int] = []
#: options accepted anywhere on the command line (before a lone ``--``)
GLOBAL_FLAGS = ("--debug",)
DISABLE_OPTION = "--disable-plugin"


@contextmanager
def _naming(config_file: str) -> Iterator[None]:
    """Prefix the config file to errors that name only a field (data-file errors name their own
    file)."""
    try:
        yield
    except MdfError as exc:
        if isinstance(exc, (DataFileError, OutputError, SettingError)) or str(exc).startswith(
            config_file
        ):
            raise
        raise type(exc)(f"{config_file}: {exc}") from exc


def _progress(args: argparse.Namespace) -> Progress:
    """The command's progress reporter (``--no-progress``, ``MDF_PROGRESS``, a terminal)."""
    return Progress(not args.no_progress)


def _cmd_run(args: argparse.Namespace) -> int:
    progress = _progress(args)
    with progress.step("reading the config and the installed plugins"):
        from .config import blaming_overrides, load_run_config
        from .output import run_folder, write_run
        from .pipeline import simulate

        config = load_run_config(args.config, overrides=args.overrides)
    if args.no_figures:
        figures = config.figures.model_copy(update={"enabled": False})
        config = config.model_copy(update={"figures": figures})
    with run_folder(args.out, force=args.force, staging_dir=args.staging_dir) as folder:
        with blaming_overrides(args.config, args.overrides), _naming(args.config):
            result = simulate(config, progress=progress)
        resolved = json.loads(config.model_dump_json())
        written = write_run(result, resolved, folder, progress=progress)
    for path in written:
        print(path)
    return 0


def _cmd_show(args: argparse.Namespace) -> int:
    progress = _progress(args)
    with progress.step("reading the config and the installed plugins"):
        from .config import blaming_overrides, load_run_config
        from .output import run_folder, stage_run
        from .pipeline import simulate
        from .preview import check_frame_rate, check_instants, stage_preview

        check_frame_rate(args.format, args.fps)  # before anything is simulated or written
        config = load_run_config(args.config, overrides=args.overrides)
    with run_folder(args.out, force=args.force, staging_dir=args.staging_dir) as folder:
        with blaming_overrides(args.config, args.overrides), _naming(args.config):
            result = simulate(config, progress=progress)
        if args.at is not None:
            check_instants(result.body, args.at)  # before anything is written
        resolved = json.loads(config.model_dump_json())
        stage = folder.stage()
        stage_run(result, resolved, stage, progress)
        stage_preview(
            result,
            resolved,
            stage,
            fmt=args.format,
            fps=args.fps,
            instants=args.at,
            progress=progress,
        )
        written = folder.commit(stage)
    for path in written:
        print(path)
    return 0


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text!r}")
    return value


def _fps(text: str) -> int:
    """Frames per second of ``mdf show``'s animation: 1 .. ``limits.MAX_ANIMATION_FPS``."""
    from .limits import MAX_ANIMATION_FPS

    value = _positive_int(text)
    if value > MAX_ANIMATION_FPS:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_ANIMATION_FPS}, got {text!r}")
    return value


class UsageError(MdfError):
    """The command line itself is wrong (an unknown option, a missing or malformed argument)."""


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (``mdf: error: ...``, exit code 2, like
    every bad input) instead of the usage text and a second line; ``--help`` shows the usage."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(f"{message} (see `{self.prog} --help`)")

    def parse_known_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        """As argparse's, but a command without sub-commands of its own (``mdf run``) refuses
        arguments it does not know itself, so that the error points to its own ``--help``."""
        parsed, extras = super().parse_known_args(args, namespace)
        if extras and self._subparsers is None and " " in self.prog:
            self.error(f"unrecognized arguments: {' '.join(extras)}")
        return parsed, extras


def _output_path(text: str) -> str:
    """An ``--out`` value: not empty (``--out "$DIR"`` with DIR unset would mean the working
    folder)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("must not be empty")
    return text


#: errors of the file system a command writes to (a full disk or quota, a read-only or
#: forbidden folder, a failing disk or a network file system's stale handle): one line naming
#: the file, exit code 2, like bad input (not a bug of mdf's)
_WRITE_ERRNOS = (
    errno.ENOSPC,
    errno.EDQUOT,
    errno.EROFS,
    errno.EACCES,
    errno.EPERM,
    errno.EFBIG,
    errno.EIO,
    errno.ESTALE,
)


#: the errors of a full disk or quota: the command can be run again once there is room
_NO_ROOM = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)


#: import name -> the name pip installs it by, where the two differ
_PIP_NAMES = {
    "sklearn": "scikit-learn",
    "yaml": "pyyaml",
    "PIL": "pillow",
    "imageio_ffmpeg": "imageio-ffmpeg",
    "dask": "mdframework[dask]",
    "distributed": "mdframework[dask]",
}


def _missing_package(exc: BaseException) -> str | None:
    """One line for a Python package that is not installed where a feature imports it (an
    optional dependency such as mujoco, ezc3d or scikit-learn, left out or uninstalled): the
    package, the distribution that imports it (that of the innermost frame of the traceback)
    and the command that installs it; ``None`` for any other error, and for a module missing
    from a package that is installed (a bug, or a broken install: an internal error)."""
    import importlib.metadata
    import importlib.util

    if not isinstance(exc, ModuleNotFoundError) or not exc.name:
        return None
    top = exc.name.partition(".")[0]
    try:
        if importlib.util.find_spec(top) is not None:
            return None
    except (ImportError, ValueError):
        return None
    importer = ""
    tb = exc.__traceback__
    while tb is not None:
        module = str(tb.tb_frame.f_globals.get("__name__", "")).partition(".")[0]
        if module not in ("", "__main__", "importlib", top):
            importer = module
        tb = tb.tb_next
    dists = importlib.metadata.packages_distributions().get(importer, []) if importer else []
    who = f"{dists[0]} needs" if dists else "this command needs"
    return (
        f"{who} the Python package {top!r}, which is not installed: "
        f"pip install {_PIP_NAMES.get(top, top)}"
    )


def _write_failure(exc: OSError, args: argparse.Namespace) -> str:
    """One line for a file-system error (:data:`_WRITE_ERRNOS`): the file being written (the
    note ``while writing PATH`` that mdframework's writers add, else the error's own file name;
    a file in a staging folder by its name in ``--out``; else ``--out`` itself), the cause, and,
    for a full disk or quota, what to do. A dataset build (an experiment's too) keeps the
    records it wrote."""
    from .outdir import STAGING_PREFIX, WRITING_NOTE

    notes = [str(n) for n in getattr(exc, "__notes__", ())]
    writing = next(
        (n.removeprefix(WRITING_NOTE) for n in notes if n.startswith(WRITING_NOTE)), None
    )
    out = getattr(args, "out", None)
    named = exc.filename if isinstance(exc.filename, (str, bytes, os.PathLike)) else None
    path = writing or (os.fsdecode(named) if named is not None else None)
    if path is not None and out is not None and Path(path).parent.name.startswith(STAGING_PREFIX):
        path = str(Path(out) / Path(path).name)  # where the file was to go
    where = path if path is not None else (f"--out {out}" if out is not None else None)
    text = exc.strerror or str(exc)
    line = f"{where}: {text}" if where is not None else text
    func = getattr(args, "func", None)
    building = func is _cmd_dataset_build or (  # an experiment's dataset resumes as well
        func is _cmd_experiment
        and path is not None
        and out is not None
        and Path(out, "dataset") in Path(path).parents
    )
    if exc.errno in _NO_ROOM and building:
        line += (
            "; free some space and run the same command again: it resumes from the records "
            "written so far"
        )
    elif exc.errno in _NO_ROOM:
        line += "; free some space (or choose another --out) and run the command again"
    return line


def _as_given(args: argparse.Namespace) -> str:
    """The config file and its ``--set`` overrides, as a report names what it checked."""
    return str(args.config) + "".join(f" --set {item}" for item in args.overrides)


def _cmd_check(args: argparse.Namespace) -> int:
    with _progress(args).step("reading the config, the installed plugins and the motion"):
        from .check import format_plan, plan_run
        from .config import blaming_overrides, load_run_config

        config = load_run_config(args.config, overrides=args.overrides)
        with blaming_overrides(args.config, args.overrides), _naming(args.config):
            plan = plan_run(config)
    if args.json:
        print(json.dumps(plan.as_dict(), indent=2))
    else:
        print(format_plan(plan, _as_given(args)))
    return 0


def _cmd_dataset_check(args: argparse.Namespace) -> int:
    with _progress(args).step("reading the config, the installed plugins and the motions"):
        from .check import format_dataset_plan, plan_dataset
        from .config import blaming_overrides
        from .dataset import load_dataset_config

        config, base = load_dataset_config(args.config, args.overrides)
        with blaming_overrides(args.config, args.overrides), _naming(args.config):
            plan = plan_dataset(config, base, every=args.all)
    if args.json:
        print(json.dumps(plan.as_dict(), indent=2))
    else:
        print(format_dataset_plan(plan, _as_given(args)))
    return 0


def _cmd_plugins(args: argparse.Namespace) -> int:
    registry = default_registry()
    for interface in INTERFACES:
        print(f"{interface}:")
        infos = registry.plugins[interface]
        if not infos:
            print("  (none installed)")
        for name in registry.names(interface):
            info = infos[name]
            doc = (info.cls.__doc__ or "").strip().splitlines()
            summary = doc[0] if doc else ""
            print(f"  {name:<16} {info.provider:<28} {summary}")
    if registry.disabled:
        print("disabled:")
        for name, why in sorted(registry.disabled.items()):
            print(f"  {name:<16} {why}")
    if SLOW_IMPORTS:
        print(
            "slow to import (every mdf command imports every plugin: import heavy libraries in "
            "the methods that use them, or mdf --disable-plugin NAME):"
        )
        for name, (dist, took) in sorted(SLOW_IMPORTS.items()):
            print(f"  {name:<16} {dist}: {took:.1f} s")
    return 0


def _cmd_schema(args: argparse.Namespace) -> int:
    from pydantic import PydanticUserError

    from .config import run_config_model

    registry = default_registry()
    for interface in ("motion", "scatterers", "radar", "effects"):
        for name in registry.names(interface):
            info = registry.plugins[interface][name]
            try:  # pydantic leaves a member without a schema out of the union, silently
                info.cls.Config.model_json_schema()
            except PydanticUserError as exc:
                why = str(exc).strip().splitlines()[0]
                say(
                    f"mdf: warning: the {interface} kind {name!r} ({info.provider}) is left "
                    f"out of the schema: its Config has no JSON schema ({why}); "
                    "check it with mdframework.testing.check_plugin_class"
                )
    print(json.dumps(run_config_model(registry).model_json_schema(), indent=2))
    return 0


def _check_build_environment(args: argparse.Namespace) -> None:
    """How a build's records are computed (``--scheduler``, ``MDF_DASK_SCHEDULER``,
    ``MDF_START_METHOD``), checked before any folder is made, outside :func:`_naming`: a bad
    setting is not the config's fault."""
    from .cluster import check_scheduler_address, scheduler_address
    from .workers import start_method

    check_scheduler_address(scheduler_address(args.scheduler))
    start_method()


def _cmd_dataset_build(args: argparse.Namespace) -> int:
    from .config import blaming_overrides
    from .dataset import build_dataset, load_dataset_config

    config, base = load_dataset_config(args.config, args.overrides)
    _check_build_environment(args)
    with blaming_overrides(args.config, args.overrides), _naming(args.config):
        rows = build_dataset(
            config,
            base,
            Path(args.out),
            workers=args.workers,
            scheduler=args.scheduler,
            progress=not args.no_progress,
            force=args.force,
        )
    manifest = json.loads((Path(args.out) / "dataset.json").read_text(encoding="utf-8"))
    skipped = manifest.get("n_skipped", 0)
    note = f"; {skipped} skipped, see {Path(args.out) / 'skipped.csv'}" if skipped else ""
    print(f"{len(rows)} records in {args.out}{note}")
    return 0


def _cmd_experiment(args: argparse.Namespace) -> int:
    from .config import blaming_overrides
    from .experiment import load_experiment_config, run_experiment
    from .progress import note

    note("reading the experiment config and the installed plugins", not args.no_progress)
    config = load_experiment_config(args.config, args.overrides)
    if args.workers is not None:
        config = config.model_copy(update={"workers": args.workers})
    if config.dataset.config is not None:  # (a built dataset is only read)
        _check_build_environment(args)
    with blaming_overrides(args.config, args.overrides), _naming(args.config):
        run_experiment(
            config,
            Path(args.out),
            source=args.config,
            progress=not args.no_progress,
            allow_import=args.allow_import,
            force=args.force,
            staging_dir=args.staging_dir,
            scheduler=args.scheduler,
        )
    print(Path(args.out) / "report.md")
    return 0


FORCE_HELP = (
    "write into an existing folder that holds other files (only this command's files are "
    "replaced; nothing else is deleted)"
)
#: --force of the commands that build a dataset
FORCE_DATASET_HELP = FORCE_HELP + ", or rebuild a dataset from a different config"
PROGRESS_HELP = (
    "hide the progress of steps that take more than a second (shown on stderr when it is a "
    "terminal, or with MDF_PROGRESS=1)"
)
STAGING_HELP = (
    "folder for the files being written (default: inside --out); must be on the same file "
    "system as --out"
)


#: the exit codes, as ``mdf --help`` lists them
EXIT_CODES_HELP = (
    "exit codes: 0 done; 1 internal error (a bug, in mdf or a plugin: --debug shows the "
    "traceback); 2 bad input (a config, a data file, a scene that cannot be simulated, the "
    "command line, --out, a Python package a feature needs that is not installed); 130 "
    "interrupted (Ctrl-C); 143 terminated (SIGTERM)."
)


def _examples(*lines: str) -> str:
    return "examples:\n" + "\n".join(f"  {line}" for line in lines)


def add_command(
    sub: argparse._SubParsersAction[Any],
    name: str,
    summary: str,
    description: str,
    examples: Sequence[str],
) -> argparse.ArgumentParser:
    """A sub-command with a one-line summary (``mdf --help``), a description and examples
    (``mdf NAME --help``). Plugins adding commands may use it too."""
    return sub.add_parser(  # type: ignore[no-any-return]
        name,
        help=summary,
        description=textwrap.fill(description, 79),
        epilog=_examples(*examples),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


def _version() -> str:
    return f"mdf (mdframework) {mdframework_version()}, Python {sys.version.split()[0]}"


SET_HELP = (
    "change one config field for this run, as if the file said so: KEY is a dotted path "
    "(radar.prf, effects.0.snr_db), VALUE a TOML value (4000, 7.7e10, true, '\"hann\"'; other "
    "text is a string); repeatable, applied in order; the output keeps the config that ran"
)


def _set_argument(parser: argparse.ArgumentParser) -> None:
    """``--set KEY=VALUE`` of the commands that read a run config."""
    parser.add_argument(
        "--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE", help=SET_HELP
    )


def _run_arguments(parser: argparse.ArgumentParser) -> None:
    """The arguments `mdf run` and `mdf show` share: the config, the output folder and how it
    is written, and progress."""
    parser.add_argument("config", help="run config file (.toml, .yaml or .json)")
    parser.add_argument("--out", required=True, type=_output_path, help="output folder")
    parser.add_argument("--force", action="store_true", help=FORCE_HELP)
    parser.add_argument("--staging-dir", default=None, help=STAGING_HELP)
    parser.add_argument("--no-progress", action="store_true", help=PROGRESS_HELP)
    _set_argument(parser)


def _build_arguments(parser: argparse.ArgumentParser, workers_help: str) -> None:
    """The options of the commands that build a dataset: ``--workers``, ``--scheduler``."""
    parser.add_argument("--workers", type=_positive_int, default=None, help=workers_help)
    parser.add_argument(
        "--scheduler",
        default=None,
        help="Dask scheduler address, or 'local' for a local Dask cluster (default: the "
        "MDF_DASK_SCHEDULER environment variable, else local processes; connection timeout "
        "MDF_DASK_TIMEOUT seconds, default 10)",
    )


def _check_arguments(parser: argparse.ArgumentParser, config_help: str) -> None:
    """The arguments of ``mdf check`` and ``mdf dataset check``."""
    parser.add_argument("config", help=config_help)
    parser.add_argument("--json", action="store_true", help="print the report as JSON")
    parser.add_argument("--no-progress", action="store_true", help=PROGRESS_HELP)
    _set_argument(parser)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``mdf`` (with the commands installed plugins add)."""
    parser = _Parser(
        prog="mdf",
        description=textwrap.fill(
            "Radar micro-Doppler signatures of people in motion, simulated from motion capture: "
            "runs, labelled datasets and classification experiments from config files.",
            79,
        ),
        epilog=_examples(
            "mdf check examples/cmu_walk.toml            # what a run would do",
            "mdf run examples/cmu_walk.toml --out out/walk",
            "mdf dataset check examples/datasets/cmu.toml # what a build would do",
            "mdf dataset build examples/datasets/cmu.toml --out out/ds",
            "mdf experiment examples/experiment_cmu.toml --out out/exp",
            "mdf plugins                                  # installed and disabled plugins",
            "mdf COMMAND --help                           # options and examples of a command",
        )
        + "\n\n--debug and --disable-plugin may be given anywhere on the command line.\n\n"
        + textwrap.fill(EXIT_CODES_HELP, 79),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=_version())
    parser.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    parser.add_argument(
        DISABLE_OPTION,
        metavar="NAME",
        action="append",
        default=[],
        help=f"do not load the plugin NAME (entry point or distribution name, e.g. mdf_kinect "
        f"or mdf-kinect); repeatable; adds to ${DISABLE_PLUGINS_ENV}",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    run = add_command(
        sub,
        "run",
        "run a config: motion -> radar -> spectrogram",
        "Simulate one record from a run config (TOML, YAML or JSON) and write result.npz, "
        "features.json, config.resolved.json, metadata.json and spectrogram.png into the "
        "output folder (all or nothing), with range_time.png on the raw path and points.csv, "
        "range_doppler.png and point_cloud.png for a radar's point products. See "
        "docs/config-reference.md for every field.",
        [
            "mdf run examples/point_target.toml --out out/pt",
            "mdf run examples/cmu_walk.toml --out out/walk --debug",
            "mdf run examples/point_target.toml --out out/pt-arrays --no-figures",
            "mdf run examples/cmu_walk.toml --out out/walk-4k --set radar.prf=4000",
        ],
    )
    _run_arguments(run)
    run.add_argument(
        "--no-figures",
        action="store_true",
        help="write no figures, only the arrays and JSON/CSV files (as [figures] enabled = "
        "false; the run does not import matplotlib)",
    )
    run.set_defaults(func=_cmd_run)

    show = add_command(
        sub,
        "show",
        "run a config and preview the motion beside its spectrogram",
        "Run a config (writing what `mdf run` writes) and add motion.gif (or .mp4): the scene "
        "from above, the body in 3-D and the spectrogram with a time cursor; and skeleton.png: "
        "the body at chosen instants above the spectrogram. See docs/figures.md.",
        ["mdf show examples/cmu_walk.toml --out out/walk --at 0.5 1.4 2.3 --fps 6"],
    )
    _run_arguments(show)
    show.add_argument("--format", choices=("gif", "mp4"), default="gif", help="animation format")
    show.add_argument(
        "--fps", type=_fps, default=12, help="animation frames per second (1 .. 100; a GIF 1 .. 50)"
    )
    show.add_argument(
        "--at", type=float, nargs="+", default=None, metavar="T",
        help="instants of skeleton.png [s from the record's start]; default: five spread over it",
    )  # fmt: skip
    show.set_defaults(func=_cmd_show)

    check = add_command(
        sub,
        "check",
        "validate a run config and report what a run would do, without running it",
        "Validate a run config, load its motion and report the plugins chosen, the record "
        "(length, pulses), the spectrogram geometry, the Doppler and velocity resolution, the "
        "unambiguous velocity, the aliasing risk (with the PRF that avoids it) and the memory "
        "the run needs. Simulates nothing and writes nothing.",
        [
            "mdf check examples/cmu_walk.toml",
            "mdf check examples/point_target.toml --json",
            "mdf check examples/cmu_walk.toml --set radar.prf=1000",
        ],
    )
    _check_arguments(check, "run config file (.toml, .yaml or .json)")
    check.set_defaults(func=_cmd_check)

    dataset = add_command(
        sub,
        "dataset",
        "labelled datasets of simulated records",
        "Build labelled datasets of simulated records, or check a dataset config before "
        "building it (see docs/datasets.md).",
        [
            "mdf dataset check examples/datasets/cmu.toml",
            "mdf dataset build examples/datasets/cmu.toml --out out/ds",
        ],
    )
    dataset_sub = dataset.add_subparsers(
        dest="dataset_command", required=True, metavar="SUBCOMMAND"
    )
    build = add_command(
        dataset_sub,
        "build",
        "build (or resume building) a dataset",
        "Simulate every record a dataset config describes, in parallel, into a dataset folder "
        "(features, spectrograms, labels). An interrupted build resumes where it stopped.",
        [
            "mdf dataset build examples/datasets/cmu.toml --out out/ds",
            "mdf dataset build examples/datasets/cmu.toml --out out/ds --workers 2",
        ],
    )
    build.add_argument("config", help="dataset config file")
    build.add_argument("--out", required=True, type=_output_path, help="dataset folder")
    _build_arguments(build, "local processes")
    build.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    build.add_argument("--force", action="store_true", help=FORCE_DATASET_HELP)
    _set_argument(build)
    build.set_defaults(func=_cmd_dataset_build)

    dcheck = add_command(
        dataset_sub,
        "check",
        "validate a dataset config and report what a build would do, without building",
        "Plan a dataset config as a build does before its first record (every record's config "
        "validated, with its random draws) and report the records per label and, for each "
        "label's first simulated record, what `mdf check` reports of a run: its pulses, "
        "scatterers, spectrogram, aliasing risk and memory. Simulates nothing and writes "
        "nothing.",
        [
            "mdf dataset check examples/datasets/cmu.toml",
            "mdf dataset check examples/datasets/cmu.toml --json",
            "mdf dataset check examples/datasets/cmu.toml --all   # every record",
        ],
    )
    _check_arguments(dcheck, "dataset config file")
    dcheck.add_argument(
        "--all",
        action="store_true",
        help="plan every record, not only each label's first: what a run refuses, aliasing "
        "and the largest memory over all of them (each record's motion is loaded)",
    )
    dcheck.set_defaults(func=_cmd_dataset_check)

    experiment = add_command(
        sub,
        "experiment",
        "run a classification experiment",
        "Build (or load) a dataset, select features, train and test a classifier over repeated "
        "splits, and write report.md with confusion matrices, the selected features and "
        "feature statistics (see docs/experiments.md).",
        ["mdf experiment examples/experiment_cmu.toml --out out/exp"],
    )
    experiment.add_argument("config", help="experiment config file")
    experiment.add_argument("--out", required=True, type=_output_path, help="report folder")
    experiment.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    experiment.add_argument(
        "--allow-import",
        action="store_true",
        help="let the config's classifier name any import path (importing runs that module's "
        "code: use only with configs you trust); default: scikit-learn's classifiers only",
    )
    experiment.add_argument("--force", action="store_true", help=FORCE_DATASET_HELP)
    _set_argument(experiment)
    experiment.add_argument("--staging-dir", default=None, help=STAGING_HELP)
    _build_arguments(
        experiment, "local processes building the dataset (default: the config's workers)"
    )
    experiment.set_defaults(func=_cmd_experiment)

    plugins = add_command(
        sub,
        "plugins",
        "list installed plugins by interface, and the disabled ones with the reason",
        "List the installed plugins of every interface (the kind a config uses, the "
        "distribution that provides it, a summary), then the plugins that are disabled and "
        f"why. Disable one with --disable-plugin NAME or ${DISABLE_PLUGINS_ENV}=NAME,...",
        ["mdf plugins", "mdf plugins --disable-plugin mdf_kinect"],
    )
    plugins.set_defaults(func=_cmd_plugins)

    config = add_command(
        sub,
        "config",
        "config utilities",
        "Config utilities: the JSON schema of run configs for the installed plugins.",
        ["mdf config schema > run-config.schema.json"],
    )
    config_sub = config.add_subparsers(dest="config_command", required=True, metavar="SUBCOMMAND")
    schema = add_command(
        config_sub,
        "schema",
        "print the JSON schema of run configs",
        "Print the JSON schema of run configs for the installed plugins (for editors and "
        "validators).",
        ["mdf config schema > run-config.schema.json"],
    )
    schema.set_defaults(func=_cmd_schema)

    add_cli_commands(sub)
    return parser


def _one_line(message: str) -> str:
    return " ".join(str(message).split())


def split_global_options(argv: Sequence[str]) -> tuple[list[str], bool, list[str]]:
    """``argv`` without the options accepted anywhere (``--debug``, ``--disable-plugin NAME``),
    whether ``--debug`` was given, and the plugins to disable. A lone ``--`` ends the scan."""
    rest: list[str] = []
    debug = False
    disabled: list[str] = []
    items = list(argv)
    i = 0
    while i < len(items):
        arg = items[i]
        if arg == "--":
            rest += items[i:]
            break
        if arg in GLOBAL_FLAGS:
            debug = True
        elif arg == DISABLE_OPTION and i + 1 < len(items):
            disabled.append(items[i + 1])
            i += 1
        elif arg.startswith(DISABLE_OPTION + "="):
            disabled.append(arg.split("=", 1)[1])
        else:
            rest.append(arg)
        i += 1
    return rest, debug, disabled


def _show_warning(message: Any, category: Any, *rest: Any, **kw: Any) -> None:
    printed()
    say(f"mdf: warning: {_one_line(str(message))}")


def _plugins_off_note() -> str:
    if not autoload_enabled():
        return f" (plugin loading is off: {DISABLE_ENV} is set)"
    off = disabled_by_user()
    return f" (disabled plugins: {', '.join(sorted(off))})" if off else ""


def _quiet_broken_pipe() -> int:
    """The reader of our output went away (``mdf plugins | head -1``): stop quietly."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # pragma: no cover - stdout without a file descriptor
        pass
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit code. Ctrl-C at any moment (plugin loading included) prints
    one line and returns 130."""
    try:
        _ENDED_BY.clear()
        note_interrupt(False)  # a Ctrl-C of an earlier command in this process is not ours
        previous = _catch_interrupts()
        hook = sys.unraisablehook
        sys.unraisablehook = _quiet_unraisable_interrupt(hook)
        try:
            with safe_stderr():  # printing a line never fails a command
                code = _main_with_options(argv)
        finally:
            sys.unraisablehook = hook
            for sig, handler in previous.items():
                signal.signal(sig, handler)
        # a Ctrl-C that Python could not raise (it arrived in a finaliser or a callback and
        # was reported as unraisable) still ends the command as interrupted
        return _interrupted() if interrupt_seen() else code
    except KeyboardInterrupt:
        return _interrupted()


def _quiet_unraisable_interrupt(hook: Any) -> Any:
    """A ``sys.unraisablehook``: a KeyboardInterrupt that could not be raised is recorded (the
    command ends as interrupted) instead of printed; anything else goes to ``hook``."""

    def handle(unraisable: Any) -> None:
        if isinstance(unraisable.exc_value, KeyboardInterrupt):
            note_interrupt()
            return
        hook(unraisable)

    return handle


def _forget_handled_interrupt() -> None:
    """CPython marks a KeyboardInterrupt that ends an ``exec`` of source text as unhandled even
    when a caller handles it (dataclasses and named tuples build their methods that way, so a
    Ctrl-C or SIGTERM can land in one during a lazy import); under ``python -m`` the process then
    dies by SIGINT at exit instead of returning our exit code. Running source text once more
    clears that mark."""
    exec("None", {})


def _interrupted() -> int:
    _forget_handled_interrupt()
    retract()
    if _ENDED_BY and _ENDED_BY[0] == signal.SIGTERM:
        say("mdf: terminated")
        return EXIT_TERMINATED
    say("mdf: interrupted")
    return EXIT_INTERRUPTED


def _catch_interrupts() -> dict[int, Any]:
    """The first Ctrl-C or SIGTERM raises KeyboardInterrupt (the command cleans up: staging
    folders, the lock, worker processes) and prints one line (``mdf: interrupted``, exit 130;
    ``mdf: terminated``, exit 143); a second one during that clean-up ends the process at once
    with the same line (the next command on the folder removes what is left). Returns the
    handlers to restore (none where signals cannot be handled: not the main thread)."""
    if threading.current_thread() is not threading.main_thread():
        return {}

    def again(signum: int, frame: Any) -> None:
        term = _ENDED_BY[:1] == [signal.SIGTERM]
        try:
            os.write(2, b"mdf: terminated\n" if term else b"mdf: interrupted\n")
        except OSError:  # stderr closed or full
            pass
        os._exit(EXIT_TERMINATED if term else EXIT_INTERRUPTED)

    def first(signum: int, frame: Any) -> None:
        signal.signal(signal.SIGINT, again)
        signal.signal(signal.SIGTERM, again)
        _ENDED_BY.append(signum)
        note_interrupt()
        raise KeyboardInterrupt

    return {sig: signal.signal(sig, first) for sig in (signal.SIGINT, signal.SIGTERM)}


def _main_with_options(argv: Sequence[str] | None) -> int:
    raw = sys.argv[1:] if argv is None else argv
    args_list, debug, disable = split_global_options(raw)
    unknown = sorted(set(disable) - installed_names()) if disable else []
    if unknown:  # a misspelt name would otherwise leave the plugin on without a word
        known = sorted(installed_names())
        say(
            f"mdf: error: {DISABLE_OPTION} {unknown[0]}: no installed plugin has this name"
            f"{suggest(unknown[0], known)}; `mdf plugins` lists them"
        )
        return EXIT_USAGE
    old_env = os.environ.get(DISABLE_PLUGINS_ENV)
    if disable:  # in the environment, so that worker processes see it too
        off = sorted(disabled_by_user() | set(disable))
        os.environ[DISABLE_PLUGINS_ENV] = ",".join(off)
        reset_default_registry()
    old_showwarning = warnings.showwarning
    warnings.showwarning = _show_warning
    try:
        with warnings.catch_warnings():
            # a numerical warning (overflow, invalid value) in our own code means a result
            # would not be trustworthy: stop there instead of writing it (valid inputs never
            # cause one; see benchmarks/fuzz_scenes.py)
            warnings.filterwarnings(
                "error", category=RuntimeWarning, module=r"(mdframework|mdf_\w+)\b"
            )
            return _main(args_list, debug)
    except BrokenPipeError:
        return _quiet_broken_pipe()
    finally:
        warnings.showwarning = old_showwarning
        if disable:  # main() may be called again in this process (tests, embedding)
            if old_env is None:
                os.environ.pop(DISABLE_PLUGINS_ENV, None)
            else:
                os.environ[DISABLE_PLUGINS_ENV] = old_env
            reset_default_registry()


def _main(argv: list[str], debug: bool) -> int:
    try:
        parser = build_parser()
    except PluginError as exc:
        if debug:
            raise
        say(f"mdf: error: {_one_line(str(exc))}")
        return EXIT_USAGE
    try:
        args = parser.parse_args(argv)
    except UsageError as exc:
        if debug:
            traceback.print_exc()
        say(f"mdf: error: {_one_line(str(exc))}")
        return EXIT_USAGE
    args.debug = debug or args.debug
    try:
        if hasattr(args, "no_progress"):  # a command that reports progress: a bad setting
            check_progress_setting()  # stops it before it starts
        return int(args.func(args))
    except BrokenPipeError:
        raise
    except (MdfError, PluginError) as exc:
        if args.debug:
            traceback.print_exc()
        message = _one_line(str(exc))
        if "disabled" not in message:
            message += _plugins_off_note()
        retract()
        say(f"mdf: error: {message}")
        return EXIT_USAGE
    except Exception as exc:
        if caused_by_interrupt(exc):
            raise KeyboardInterrupt from exc
        if args.debug:
            raise
        retract()
        if isinstance(exc, OSError) and exc.errno in _WRITE_ERRNOS:
            say(f"mdf: error: {_write_failure(exc, args)}")
            return EXIT_USAGE
        missing = _missing_package(exc)
        if missing is not None:
            say(f"mdf: error: {missing}")
            return EXIT_USAGE
        notes = "".join(f"{_one_line(note)}; " for note in getattr(exc, "__notes__", ()))
        say(
            f"mdf: internal error: {type(exc).__name__}: {_one_line(str(exc))} "
            f"({notes}run with --debug for the traceback)"
        )
        return 1


if __name__ == "__main__":
    sys.exit(main())
