"""The ``mdf`` command line.

Errors caused by input (config, data files, the scene) print one line and exit with code 2; add
``--debug`` for the traceback.
"""

from __future__ import annotations

import argparse
import json
import sys
import traceback
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from .errors import DataFileError, MdfError
from .plugins import INTERFACES, PluginError, default_registry, make_plugin_manager

EXIT_USAGE = 2


@contextmanager
def _naming(config_file: str) -> Iterator[None]:
    """Prefix the config file to errors that name only a field (data-file errors name their own
    file)."""
    try:
        yield
    except MdfError as exc:
        if isinstance(exc, DataFileError) or str(exc).startswith(config_file):
            raise
        raise type(exc)(f"{config_file}: {exc}") from exc


def _cmd_run(args: argparse.Namespace) -> int:
    from .config import load_run_config
    from .output import write_run
    from .pipeline import simulate

    config = load_run_config(args.config)
    with _naming(args.config):
        result = simulate(config)
    resolved = json.loads(config.model_dump_json())
    written = write_run(result, resolved, Path(args.out))
    for path in written:
        print(path)
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
    return 0


def _cmd_schema(args: argparse.Namespace) -> int:
    from .config import run_config_model

    print(json.dumps(run_config_model().model_json_schema(), indent=2))
    return 0


def _cmd_dataset_build(args: argparse.Namespace) -> int:
    from .dataset import build_dataset, load_dataset_config

    config, base = load_dataset_config(args.config)
    with _naming(args.config):
        rows = build_dataset(
            config,
            base,
            Path(args.out),
            workers=args.workers,
            scheduler=args.scheduler,
            progress=not args.no_progress,
        )
    manifest = json.loads((Path(args.out) / "dataset.json").read_text())
    skipped = manifest.get("n_skipped", 0)
    note = f"; {skipped} skipped, see {Path(args.out) / 'skipped.csv'}" if skipped else ""
    print(f"{len(rows)} records in {args.out}{note}")
    return 0


def _cmd_experiment(args: argparse.Namespace) -> int:
    from .experiment import load_experiment_config, run_experiment

    config = load_experiment_config(args.config)
    with _naming(args.config):
        run_experiment(config, Path(args.out), source=args.config, progress=not args.no_progress)
    print(Path(args.out) / "report.md")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``mdf``."""
    parser = argparse.ArgumentParser(
        prog="mdf", description="Radar micro-Doppler simulation of people in motion."
    )
    parser.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    sub = parser.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="run a config: motion -> radar -> spectrogram")
    run.add_argument("config", help="run config file (.toml, .yaml or .json)")
    run.add_argument("--out", required=True, help="output folder")
    run.set_defaults(func=_cmd_run)

    dataset = sub.add_parser("dataset", help="labelled datasets of simulated records")
    dataset_sub = dataset.add_subparsers(dest="dataset_command", required=True)
    build = dataset_sub.add_parser("build", help="build (or resume building) a dataset")
    build.add_argument("config", help="dataset config file")
    build.add_argument("--out", required=True, help="dataset folder")
    build.add_argument("--workers", type=int, default=None, help="local processes")
    build.add_argument(
        "--scheduler",
        default=None,
        help="Dask scheduler address, or 'local' for a local Dask cluster",
    )
    build.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    build.set_defaults(func=_cmd_dataset_build)

    experiment = sub.add_parser("experiment", help="run a classification experiment")
    experiment.add_argument("config", help="experiment config file")
    experiment.add_argument("--out", required=True, help="report folder")
    experiment.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    experiment.set_defaults(func=_cmd_experiment)

    plugins = sub.add_parser("plugins", help="list installed plugins by interface")
    plugins.set_defaults(func=_cmd_plugins)

    config = sub.add_parser("config", help="config utilities")
    config_sub = config.add_subparsers(dest="config_command", required=True)
    schema = config_sub.add_parser("schema", help="print the JSON schema of run configs")
    schema.set_defaults(func=_cmd_schema)

    make_plugin_manager().hook.mdframework_add_cli_commands(subparsers=sub)
    return parser


def _one_line(message: str) -> str:
    return " ".join(str(message).split())


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit code."""
    debug = "--debug" in (sys.argv[1:] if argv is None else argv)
    try:
        parser = build_parser()
    except PluginError as exc:
        if debug:
            raise
        print(f"mdf: error: {_one_line(str(exc))}", file=sys.stderr)
        return EXIT_USAGE
    args = parser.parse_args(argv)

    def show_warning(message: Any, category: Any, *rest: Any, **kw: Any) -> None:
        print(f"mdf: warning: {_one_line(str(message))}", file=sys.stderr)

    warnings.showwarning = show_warning
    try:
        return int(args.func(args))
    except (MdfError, PluginError) as exc:
        if args.debug:
            traceback.print_exc()
        print(f"mdf: error: {_one_line(str(exc))}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("mdf: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:
        if args.debug:
            raise
        print(
            f"mdf: internal error: {type(exc).__name__}: {_one_line(str(exc))} "
            "(run with --debug for the traceback)",
            file=sys.stderr,
        )
        return 1


if __name__ == "__main__":
    sys.exit(main())
