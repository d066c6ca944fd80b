"""Plugin discovery and the name -> class registry.

Built-in plugins are separate distributions that register through the ``mdframework`` entry-point
group, exactly as a third party's would. The registry is derived from the hook results, never kept
as a second hand-written table.

One name per interface, used everywhere: the config section (``[radar]``), the registry key, the
base class, the registration hook and the contract check follow :data:`INTERFACES`:

- ``motion``: ``MotionSource``, hook ``mdframework_register_motion_sources``,
  check ``check_motion_source``;
- ``scatterers``: ``ScattererModel``, ``mdframework_register_scatterer_models``,
  ``check_scatterer_model``;
- ``radar``: ``RadarWaveform``, ``mdframework_register_radar_waveforms``,
  ``check_radar_waveform``;
- ``classifier``: ``Classifier``, ``mdframework_register_classifiers``, ``check_classifier``;
- ``effects``: ``Effect``, ``mdframework_register_effects``, ``check_effect``;
- ``recording`` (dataset configs): ``RecordingSource``,
  ``mdframework_register_recording_sources``, ``check_recording_source``.

Old spellings (the registry key ``effect``, the hooks ``mdframework_register_waveforms`` and
``mdframework_register_recordings``, the class name ``RadarRecordingSource``) keep working with
a :class:`DeprecationWarning`.

Switching plugins off (both read by every process, so dataset workers see them too):

- ``MDFRAMEWORK_DISABLE_PLUGINS=name,name``: skip these entry points (by entry-point name, e.g.
  ``mdf_kinect``, or distribution name, e.g. ``mdf-kinect``); ``mdf --disable-plugin NAME`` sets it.
- ``MDFRAMEWORK_DISABLE_PLUGIN_AUTOLOAD=1``: skip every entry point (tests then register plugins by
  hand with :func:`build_registry`).

A plugin that fails to import, whose hook raises, or whose hook returns something that is not a
plugin class, disables only itself with one :class:`PluginWarning`. Every disabled plugin and the
reason are kept in :attr:`Registry.disabled` (``mdf plugins`` lists them).
"""

from __future__ import annotations

import difflib
import importlib.metadata
import os
import sys
import time
import typing
import warnings
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager, redirect_stdout, suppress
from dataclasses import dataclass, field
from functools import cache
from typing import Any, Literal, NamedTuple

import pluggy

from . import hookspecs
from .errors import MdfError, caused_by_interrupt
from .interfaces import (
    Classifier,
    Effect,
    MotionSource,
    Plugin,
    PluginConfig,
    RadarWaveform,
    RecordingSource,
    ScattererModel,
)

#: interface -> kind -> the built-in distribution that registers it: a config naming a kind
#: whose distribution is not installed is told what to install
BUILT_IN_KINDS: dict[str, dict[str, str]] = {
    "motion": {
        **dict.fromkeys(("cmu", "bvh"), "mdf-cmu"),
        **dict.fromkeys(("c3d", "trc"), "mdf-c3d"),
        "deepmimic": "mdf-deepmimic",
        "kinect": "mdf-kinect",
        "boulic": "mdf-mujoco",
        "point_targets": "mdf-point-targets",
        "table": "mdf-table",
    },
    "scatterers": {
        "ellipsoid": "mdf-ellipsoid",
        "mujoco_body": "mdf-mujoco",
        "points": "mdf-point-targets",
    },
    "radar": {"lfm": "mdf-lfm", "fmcw": "mdf-fmcw", "cw": "mdf-cw"},
    "classifier": {"knn": "mdf-knn", "sklearn": "mdf-sklearn"},
    "effects": {
        "antenna": "mdf-antenna",
        "attenuation": "mdf-attenuation",
        "clutter": "mdf-clutter",
        "multipath": "mdf-multipath",
        "noise": "mdf-noise",
        "shadowing": "mdf-mujoco",
        "static_scene": "mdf-static-scene",
    },
    "recording": {"radhar": "mdf-radhar"},
}
#: the distributions of the built-in plugins (``plugins/`` of this repository): a kind one of
#: them registers stays theirs when a third party's plugin claims it too (that plugin is
#: switched off)
BUILT_IN_DISTRIBUTIONS = frozenset(d for kinds in BUILT_IN_KINDS.values() for d in kinds.values())
DISABLE_ENV = "MDFRAMEWORK_DISABLE_PLUGIN_AUTOLOAD"
DISABLE_PLUGINS_ENV = "MDFRAMEWORK_DISABLE_PLUGINS"


def _install_hint(interface: str, name: str) -> str:
    """``"; it comes with mdf-x: pip install mdf-x"`` where ``name`` is a built-in kind whose
    distribution is not installed, else ``""``."""
    import importlib.metadata

    dist = BUILT_IN_KINDS.get(interface, {}).get(name)
    if dist is None:
        return ""
    try:
        importlib.metadata.distribution(dist)
    except importlib.metadata.PackageNotFoundError:
        return f"; it comes with {dist}, which is not installed: pip install {dist}"
    return ""  # installed, so disabled or broken: the disabled note says which


class Interface(NamedTuple):
    """One plugin interface: its registration hook and base class."""

    hook: str
    base: type[Plugin]


#: interface (= config section) -> (hook name, base class)
INTERFACES: dict[str, Interface] = {
    "motion": Interface("mdframework_register_motion_sources", MotionSource),
    "scatterers": Interface("mdframework_register_scatterer_models", ScattererModel),
    "radar": Interface("mdframework_register_radar_waveforms", RadarWaveform),
    "classifier": Interface("mdframework_register_classifiers", Classifier),
    "effects": Interface("mdframework_register_effects", Effect),
    "recording": Interface("mdframework_register_recording_sources", RecordingSource),
}

#: interface -> the contract check of its plugins (:mod:`mdframework.testing`)
CONTRACT_CHECKS = {
    "motion": "check_motion_source",
    "scatterers": "check_scatterer_model",
    "radar": "check_radar_waveform",
    "classifier": "check_classifier",
    "effects": "check_effect",
    "recording": "check_recording_source",
}


@contextmanager
def blame(plugin: Plugin | type[Plugin], method: str) -> Iterator[None]:
    """Run a call of ``plugin``'s ``method`` (of the class itself for ``__init__``): an
    exception it raises, other than an :class:`~mdframework.errors.MdfError` (bad input, the
    user's), is the plugin's bug, and gets a note naming the plugin, its class and its contract
    check, which the CLI's internal error shows (``in receive() of the radar plugin 'acme'
    (acme.Radar); check it with mdframework.testing.check_radar_waveform``)."""
    try:
        yield
    except MdfError:
        raise
    except Exception as exc:
        cls = plugin if isinstance(plugin, type) else type(plugin)
        interface = next((i for i, s in INTERFACES.items() if issubclass(cls, s.base)), "")
        name_plugin_bug(
            exc,
            f"in {method}() of the {interface} plugin {getattr(plugin, 'name', '?')!r} "
            f"({cls.__module__}.{cls.__qualname__}); check it with "
            f"mdframework.testing.{CONTRACT_CHECKS.get(interface, 'check_plugin')}",
        )
        raise


def name_plugin_bug(exc: Exception, note: str) -> None:
    """Mark ``exc``, raised by a plugin's method, as that plugin's bug, with ``note`` naming
    the plugin (the CLI's internal error shows it); :func:`is_plugin_bug` then tells it from
    the user's bad input, also where a ``ValueError`` would be taken for that (a dataset
    build's record)."""
    exc.add_note(note)
    with suppress(AttributeError, TypeError):  # an exception class without attributes
        setattr(exc, _PLUGIN_BUG, True)


def is_plugin_bug(exc: BaseException) -> bool:
    """Whether ``exc`` came out of a plugin's method as its bug (:func:`name_plugin_bug`)."""
    return getattr(exc, _PLUGIN_BUG, False) is True


_PLUGIN_BUG = "_mdf_plugin_bug"


#: old interface spelling -> current one
OLD_INTERFACE_NAMES = {"effect": "effects"}
#: old hook name -> the interface it registers for
OLD_HOOKS = {
    "mdframework_register_waveforms": "radar",
    "mdframework_register_recordings": "recording",
}


class PluginError(RuntimeError):
    """A plugin could not be registered (two plugins with one name, unknown interface, ...)."""


class PluginWarning(UserWarning):
    """A plugin was disabled because it failed to load or to register."""


def interface_name(name: str) -> str:
    """The current spelling of an interface name (old spellings warn); ``PluginError`` if
    unknown."""
    if name in INTERFACES:
        return name
    if name in OLD_INTERFACE_NAMES:
        new = OLD_INTERFACE_NAMES[name]
        warnings.warn(
            f"the plugin interface {name!r} is now called {new!r}", DeprecationWarning, stacklevel=3
        )
        return new
    raise PluginError(f"unknown plugin interface {name!r} (known: {', '.join(INTERFACES)})")


@dataclass(frozen=True)
class PluginInfo:
    """A registered plugin class and the distribution that provides it."""

    cls: type[Plugin]
    interface: str
    provider: str


class _ByInterface(dict[str, dict[str, PluginInfo]]):
    """Plugins by interface; old interface spellings still work (with a DeprecationWarning)."""

    def __missing__(self, key: str) -> dict[str, PluginInfo]:
        if key in OLD_INTERFACE_NAMES:
            return self[interface_name(key)]
        raise KeyError(key)


def suggest(name: str, known: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for the closest of ``known`` to ``name`` (first one that differs
    only in case or surrounding blanks: ``'CW'`` for ``'cw'``), or ``""``."""
    known = list(known)
    same = [k for k in known if k.casefold() == str(name).strip().casefold()]
    close = same or difflib.get_close_matches(str(name), known, n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


@dataclass
class Registry:
    """Registered plugins, by interface and name, and the disabled ones with the reason."""

    plugins: dict[str, dict[str, PluginInfo]] = field(
        default_factory=lambda: _ByInterface({k: {} for k in INTERFACES})
    )
    #: entry-point name (or "<all entry points>") -> why it is not loaded
    disabled: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.plugins, _ByInterface):
            self.plugins = _ByInterface(self.plugins)

    def get(self, interface: str, name: str) -> type[Plugin]:
        """The plugin class ``name`` of ``interface``; ``KeyError`` with a one-line message that
        lists the installed names, suggests the nearest and says which plugins are disabled."""
        interface = interface_name(interface)
        known = self.plugins[interface]
        if name not in known:
            raise KeyError(self.unknown_kind_message(interface, name))
        return known[name].cls

    def unknown_kind_message(self, interface: str, name: str) -> str:
        """Why ``name`` is not a plugin of ``interface``, and what to do."""
        interface = interface_name(interface)
        known = sorted(self.plugins[interface])
        installed = ", ".join(known) or "none"
        hint = _install_hint(interface, name)  # a built-in kind: no nearest name to suggest
        near = "" if hint else suggest(name, known)
        shown = repr(name) if len(name) <= 60 else repr(name[:57] + "...")
        msg = f"no {interface} plugin named {shown}{near}; installed: {installed}{hint}"
        return msg + self.disabled_note()

    def disabled_note(self) -> str:
        """``"; disabled plugins: ..."`` naming each disabled plugin and why, or ``""``."""
        if not self.disabled:
            return ""
        by_reason: dict[str, list[str]] = {}
        for name, why in sorted(self.disabled.items()):
            by_reason.setdefault(why, []).append(name)
        items = [
            f"{names[0]} ({why})" if len(names) == 1 else f"{len(names)} plugins ({why})"
            for why, names in by_reason.items()
        ]
        return "; disabled: " + ", ".join(items)

    def names(self, interface: str) -> list[str]:
        """Sorted plugin names of one interface."""
        return sorted(self.plugins[interface_name(interface)])

    def provided_by(self, distributions: Iterable[str]) -> Registry:
        """The plugins of the named distributions only (e.g. the project's own, to document
        them whatever else is installed)."""
        keep = set(distributions)
        plugins = {
            interface: {n: i for n, i in infos.items() if i.provider.split()[0] in keep}
            for interface, infos in self.plugins.items()
        }
        return Registry(plugins, dict(self.disabled))


def versions(
    registry: Registry | None = None, used: Iterable[tuple[str, str]] | None = None
) -> dict[str, Any]:
    """The software a result was made with, for its provenance (``metadata.json``,
    ``dataset.json``, ``summary.json``, each dataset record): the versions of mdframework,
    Python, NumPy, SciPy and scikit-learn (``None`` when not installed), and ``plugins``, every
    plugin distribution of ``registry`` (default: the installed plugins) as ``"name version"``,
    sorted; with ``used`` (interface, kind) pairs, only the distributions providing those."""
    reg = default_registry() if registry is None else registry
    wanted = None if used is None else set(used)
    return {
        "mdframework": mdframework_version(),
        "python": "{}.{}.{}".format(*sys.version_info[:3]),
        "numpy": _distribution_version("numpy"),
        "scipy": _distribution_version("scipy"),
        "scikit-learn": _distribution_version("scikit-learn"),
        "plugins": sorted(
            {
                info.provider
                for interface, infos in reg.plugins.items()
                for kind, info in infos.items()
                if wanted is None or (interface, kind) in wanted
            }
        ),
    }


def mdframework_version() -> str:
    """mdframework's version: its installed distribution's, else the source tree's
    ``__version__``."""
    from . import __version__

    return _distribution_version("mdframework") or __version__


@cache
def _distribution_version(distribution: str) -> str | None:
    """An installed distribution's version (once per process: each record names them)."""
    try:
        return importlib.metadata.version(distribution)
    except importlib.metadata.PackageNotFoundError:
        return None


def _provider_name(pm: pluggy.PluginManager, plugin: object) -> str:
    name = pm.get_name(plugin) or repr(plugin)
    return _DISTRIBUTIONS.get(name, name)


#: plugin name in the manager -> "distribution version", for entry-point plugins
_DISTRIBUTIONS: dict[str, str] = {}
#: a third party's plugin whose import takes longer [s] is listed by ``mdf plugins``
SLOW_IMPORT_SECONDS = 1.0
#: entry-point name -> ("distribution version", seconds its import took), for a third party's
#: plugin that took over :data:`SLOW_IMPORT_SECONDS` (every command imports every plugin)
SLOW_IMPORTS: dict[str, tuple[str, float]] = {}


def _warn_disabled(
    pm: pluggy.PluginManager, name: str, reason: str, what: str | None = None
) -> None:
    """Record a plugin (or ``what`` else, e.g. a kind two plugins claim) as disabled and warn
    once (per plugin manager, i.e. once per process for the installed plugins)."""
    disabled = _disabled(pm)
    if name not in disabled:
        shown = what or f"plugin {name!r}"
        warnings.warn(f"{shown} is disabled: {reason}", PluginWarning, stacklevel=2)
    disabled[name] = reason


def _disabled(pm: pluggy.PluginManager) -> dict[str, str]:
    found: dict[str, str] | None = getattr(pm, "_mdf_disabled", None)
    if found is None:
        found = {}
        pm._mdf_disabled = found  # type: ignore[attr-defined]
    return found


def disabled_by_user() -> set[str]:
    """Plugin names listed in ``MDFRAMEWORK_DISABLE_PLUGINS`` (comma or space separated)."""
    raw = os.environ.get(DISABLE_PLUGINS_ENV, "")
    return {n.strip() for n in raw.replace(",", " ").split() if n.strip()}


def autoload_enabled() -> bool:
    """Whether entry points are loaded (``MDFRAMEWORK_DISABLE_PLUGIN_AUTOLOAD`` unset or 0)."""
    return os.environ.get(DISABLE_ENV, "") in ("", "0")


def _entry_points() -> list[importlib.metadata.EntryPoint]:
    return sorted(importlib.metadata.entry_points(group=hookspecs.PROJECT), key=lambda e: e.name)


def installed_names() -> set[str]:
    """Every name ``--disable-plugin`` accepts: the entry-point names of the installed plugins
    and their distributions' names (reads package metadata only; imports no plugin)."""
    names = set()
    for ep in _entry_points():
        names.add(ep.name)
        if ep.dist is not None:
            names.add(_name_and_version(ep.dist)[0])
    return names


def _name_and_version(dist: importlib.metadata.Distribution) -> tuple[str, str]:
    """A distribution's name and version from one reading of its metadata (``dist.name`` and
    ``dist.version`` each read and parse the whole file again)."""
    meta = dist.metadata
    return meta["Name"], meta["Version"]


def _unknown_hooks(plugin: object) -> list[str]:
    """Names of hook implementations on ``plugin`` that match no hook specification."""
    specs = {n for n in dir(hookspecs) if n.startswith("mdframework_")}
    bad = []
    for attr in dir(plugin):
        if not attr.startswith("mdframework_") or attr in specs:
            continue
        if hasattr(getattr(plugin, attr, None), f"{hookspecs.PROJECT}_impl"):
            bad.append(attr + suggest(attr, specs))
    return bad


def _load_entry_points(
    pm: pluggy.PluginManager, select: Callable[[importlib.metadata.EntryPoint], bool] | None
) -> None:
    off = disabled_by_user()
    for ep in _entry_points():
        if pm.get_plugin(ep.name) is not None or pm.is_blocked(ep.name):
            continue
        if select is not None and not select(ep):
            continue
        dist_name, dist = ep.name, ep.name
        if ep.dist is not None:
            dist_name, version = _name_and_version(ep.dist)
            dist = f"{dist_name} {version}"
        if {ep.name, dist_name} & off:
            why = f"disabled by --disable-plugin or {DISABLE_PLUGINS_ENV}"  # the CLI sets it
            _disabled(pm)[ep.name] = f"{dist}, {why}"
            continue
        clock = time.perf_counter()
        try:
            # what a plugin prints when imported goes to stderr, not into a command's output
            # (`mdf config schema > schema.json`)
            with redirect_stdout(sys.stderr):
                plugin = ep.load()
        except (Exception, SystemExit) as exc:  # sys.exit() at import: the plugin's, not ours
            _reraise_interrupt(exc)
            _warn_disabled(pm, ep.name, f"{dist} failed to load: {type(exc).__name__}: {exc}")
            continue
        bad = _unknown_hooks(plugin)
        if bad:
            _warn_disabled(pm, ep.name, f"{dist} implements unknown hooks: {', '.join(bad)}")
            continue
        with warnings.catch_warnings():
            # the old hook names warn through pluggy; a plugin author sees it in their tests
            warnings.simplefilter("ignore", DeprecationWarning)
            pm.register(plugin, name=ep.name)
        _DISTRIBUTIONS[ep.name] = dist
        took = time.perf_counter() - clock
        if took > SLOW_IMPORT_SECONDS and dist_name not in BUILT_IN_DISTRIBUTIONS:
            SLOW_IMPORTS[ep.name] = (dist, took)


def _reraise_interrupt(exc: BaseException) -> None:
    """Ctrl-C while a plugin loads ends the command; it does not disable the plugin."""
    if caused_by_interrupt(exc):
        raise KeyboardInterrupt from exc


def _hook_classes(
    pm: pluggy.PluginManager, hook_name: str
) -> Iterable[tuple[object, str, list[Any] | None]]:
    hook = getattr(pm.hook, hook_name)
    for impl in hook.get_hookimpls():
        provider = _provider_name(pm, impl.plugin)
        name = pm.get_name(impl.plugin) or provider
        try:
            with redirect_stdout(sys.stderr):  # what it prints stays out of a command's output
                classes = impl.function()
                # a list, or any other collection of classes (a set, a generator), but not one
                # class or text, whose items are no classes
                if isinstance(classes, str | bytes | type) or not isinstance(
                    classes, Iterable | None
                ):
                    problem = f"{hook_name} returned {classes!r}, not a list of classes"
                else:
                    found, problem = list(classes or []), ""
        except (Exception, SystemExit) as exc:  # in the hook, or a generator it returned
            _reraise_interrupt(exc)
            problem = f"{hook_name} raised {type(exc).__name__}: {exc}"
        if problem:
            _warn_disabled(pm, name, f"{provider}: {problem}")
            yield impl.plugin, provider, None
        else:
            yield impl.plugin, provider, found


def _class_problem(cls: Any, base: type[Plugin], hook_name: str) -> str:
    """What makes ``cls`` unusable as a plugin of the interface ``base``, or ``""``: it must be
    a subclass with a ``name`` and a ``Config`` (a :class:`PluginConfig`) whose ``kind`` is
    ``Literal[name]``, which the run config's discriminated union is built from."""
    if not (isinstance(cls, type) and issubclass(cls, base)):
        return f"{hook_name} returned {cls!r}, which is not a {base.__name__}"
    if not isinstance(getattr(cls, "name", None), str) or not cls.name:
        return f"{cls.__name__} has no 'name'"
    config = getattr(cls, "Config", None)
    if not (isinstance(config, type) and issubclass(config, PluginConfig)):
        return f"{cls.__name__}.Config is not a subclass of mdframework.PluginConfig"
    kind = config.model_fields.get("kind")
    annotation = None if kind is None else kind.annotation
    if typing.get_origin(annotation) is not Literal or typing.get_args(annotation) != (cls.name,):
        return f"{cls.__name__}.Config needs kind: Literal[{cls.name!r}] = {cls.name!r}"
    return ""


def _collect(pm: pluggy.PluginManager) -> Registry:
    registry = Registry(disabled=_disabled(pm))
    hooks = [(i, spec.hook) for i, spec in INTERFACES.items()]
    hooks += [(i, old) for old, i in OLD_HOOKS.items()]
    entries: list[tuple[str, str, object, str, type[Plugin]]] = []
    broken: set[object] = set()
    for interface, hook_name in hooks:
        base = INTERFACES[interface].base
        for plugin, provider, classes in _hook_classes(pm, hook_name):
            if classes is None:
                broken.add(plugin)
                continue
            for cls in classes:
                problem = _class_problem(cls, base, hook_name)
                if problem:
                    broken.add(plugin)
                    _warn_disabled(pm, pm.get_name(plugin) or provider, f"{provider}: {problem}")
                    continue
                entries.append((interface, cls.name, plugin, provider, cls))
    # a kind of ours stays ours: a third party's plugin that claims one is switched off whole
    built_in = {
        (interface, name): (cls, provider)
        for interface, name, plugin, provider, cls in entries
        if plugin not in broken and provider.split()[0] in BUILT_IN_DISTRIBUTIONS
    }
    for interface, name, plugin, provider, cls in entries:
        ours = built_in.get((interface, name))
        if plugin in broken or ours is None or ours[0] is cls:
            continue
        if provider.split()[0] in BUILT_IN_DISTRIBUTIONS:
            continue  # two of ours: a kind claimed twice (below)
        broken.add(plugin)
        _warn_disabled(
            pm,
            pm.get_name(plugin) or provider,
            f"{provider}: its {interface} kind {name!r} is built in ({ours[1]}); give its class "
            "another name",
        )
    for plugin in broken:
        if pm.is_registered(plugin):
            pm.unregister(plugin)  # its other hooks (e.g. CLI commands) go with it
    # one class returned by two hooks of one plugin (the current and the old spelling) is one
    # claim on its name
    claims: dict[tuple[str, str], dict[type[Plugin], str]] = {}
    for interface, name, plugin, provider, cls in entries:
        if plugin not in broken:
            claims.setdefault((interface, name), {}).setdefault(cls, provider)
    for (interface, name), claimants in claims.items():
        providers = sorted(set(claimants.values()))
        if len(claimants) == 1:
            ((cls, provider),) = claimants.items()
            registry.plugins[interface][name] = PluginInfo(cls, interface, provider)
        else:  # neither is chosen for the user: the kind is withheld, everything else works
            _warn_disabled(
                pm,
                f"{interface} kind {name!r}",
                f"claimed by {' and '.join(providers)}; switch one off with "
                "mdf --disable-plugin NAME",
                f"the {interface} kind {name!r}",
            )
    return registry


def make_plugin_manager(
    modules: Iterable[Any] = (),
    *,
    autoload: bool | None = None,
    select: Callable[[importlib.metadata.EntryPoint], bool] | None = None,
) -> pluggy.PluginManager:
    """A plugin manager with the hookspecs, the given plugin modules and (unless disabled) every
    ``mdframework`` entry point, or those for which ``select`` is true. The given modules must be
    valid (an unknown hook raises); an entry point that fails to load is disabled with one
    :class:`PluginWarning`."""
    pm = pluggy.PluginManager(hookspecs.PROJECT)
    pm.add_hookspecs(hookspecs)
    for module in modules:
        pm.register(module)
    if autoload is None:
        autoload = autoload_enabled()
    if autoload:
        _load_entry_points(pm, select)
    else:
        for ep in _entry_points():
            _disabled(pm)[ep.name] = f"plugin autoloading is off: {DISABLE_ENV}=1"
    pm.check_pending()
    return pm


def build_registry(
    modules: Iterable[Any] = (),
    *,
    autoload: bool | None = None,
    select: Callable[[importlib.metadata.EntryPoint], bool] | None = None,
) -> Registry:
    """Load plugins and build the registry (see :func:`make_plugin_manager`)."""
    return _collect(make_plugin_manager(modules, autoload=autoload, select=select))


@cache
def default_plugin_manager() -> pluggy.PluginManager:
    """The plugin manager of the installed plugins, built once per process."""
    return make_plugin_manager()


@cache
def default_registry() -> Registry:
    """The registry of installed plugins, built once per process."""
    return _collect(default_plugin_manager())


def add_cli_commands(subparsers: Any) -> None:
    """Let the installed plugins add their ``mdf`` sub-commands; a plugin whose hook raises is
    disabled with one :class:`PluginWarning` (the others still add theirs)."""
    pm = default_plugin_manager()
    default_registry()  # unregisters the plugins that fail to register their classes
    for impl in pm.hook.mdframework_add_cli_commands.get_hookimpls():
        before = set(getattr(subparsers, "choices", {}))
        try:
            impl.function(subparsers=subparsers)
        except Exception as exc:
            _reraise_interrupt(exc)
            _remove_commands(subparsers, set(getattr(subparsers, "choices", {})) - before)
            provider = _provider_name(pm, impl.plugin)
            name = pm.get_name(impl.plugin) or provider
            _warn_disabled(
                pm,
                name,
                f"{provider}: mdframework_add_cli_commands raised {type(exc).__name__}: {exc}",
            )
            # disabled means disabled: its plugin classes go too (the registry is rebuilt)
            pm.unregister(impl.plugin)
            default_registry.cache_clear()


def _remove_commands(subparsers: Any, names: set[str]) -> None:
    """Take the sub-commands ``names`` off an argparse sub-parsers action again (the ones a
    failing hook added before it raised)."""
    for name in names:
        subparsers.choices.pop(name, None)
    listed = getattr(subparsers, "_choices_actions", None)
    if isinstance(listed, list):
        listed[:] = [a for a in listed if getattr(a, "dest", None) not in names]


def reset_default_registry() -> None:
    """Forget the cached plugin manager and registry (after changing the environment)."""
    default_registry.cache_clear()
    default_plugin_manager.cache_clear()
    SLOW_IMPORTS.clear()
