"""Plugin discovery and the name -> class registry.

Built-in plugins are separate distributions that register through the ``mdframework`` entry-point
group, exactly as a third party's would. The registry is derived from the hook results, never kept
as a second hand-written table.

Set the environment variable ``MDFRAMEWORK_DISABLE_PLUGIN_AUTOLOAD=1`` to skip entry points (tests
then register plugins by hand with :func:`build_registry`).
"""

from __future__ import annotations

import importlib.metadata
import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import cache
from typing import Any

import pluggy

from . import hookspecs
from .interfaces import (
    Classifier,
    Effect,
    MotionSource,
    Plugin,
    RadarRecordingSource,
    RadarWaveform,
    ScattererModel,
)

DISABLE_ENV = "MDFRAMEWORK_DISABLE_PLUGIN_AUTOLOAD"

#: interface name -> (hook name, base class)
INTERFACES: dict[str, tuple[str, type[Plugin]]] = {
    "motion": ("mdframework_register_motion_sources", MotionSource),
    "scatterers": ("mdframework_register_scatterer_models", ScattererModel),
    "radar": ("mdframework_register_waveforms", RadarWaveform),
    "classifier": ("mdframework_register_classifiers", Classifier),
    "effect": ("mdframework_register_effects", Effect),
    "recording": ("mdframework_register_recordings", RadarRecordingSource),
}


class PluginError(RuntimeError):
    """A plugin could not be loaded or registered (duplicate name, wrong type, ...)."""


@dataclass(frozen=True)
class PluginInfo:
    """A registered plugin class and the distribution that provides it."""

    cls: type[Plugin]
    interface: str
    provider: str


@dataclass
class Registry:
    """Registered plugins, by interface and name."""

    plugins: dict[str, dict[str, PluginInfo]] = field(
        default_factory=lambda: {k: {} for k in INTERFACES}
    )

    def get(self, interface: str, name: str) -> type[Plugin]:
        """The plugin class ``name`` of ``interface``; ``KeyError`` lists the known names."""
        known = self.plugins[interface]
        if name not in known:
            names = ", ".join(sorted(known)) or "none installed"
            raise KeyError(f"no {interface} plugin named {name!r} (known: {names})")
        return known[name].cls

    def names(self, interface: str) -> list[str]:
        """Sorted plugin names of one interface."""
        return sorted(self.plugins[interface])


def _provider_name(pm: pluggy.PluginManager, plugin: object) -> str:
    name = pm.get_name(plugin) or repr(plugin)
    return _DISTRIBUTIONS.get(name, name)


#: plugin name in the manager -> "distribution version", for entry-point plugins
_DISTRIBUTIONS: dict[str, str] = {}


def _load_entry_points(pm: pluggy.PluginManager) -> None:
    for ep in importlib.metadata.entry_points(group=hookspecs.PROJECT):
        if pm.get_plugin(ep.name) is not None or pm.is_blocked(ep.name):
            continue
        dist = f"{ep.dist.name} {ep.dist.version}" if ep.dist else ep.name
        try:
            plugin = ep.load()
        except Exception as exc:
            raise PluginError(
                f"plugin {ep.name!r} from {dist} failed to load: {type(exc).__name__}: {exc}"
            ) from exc
        pm.register(plugin, name=ep.name)
        _DISTRIBUTIONS[ep.name] = dist


def _collect(pm: pluggy.PluginManager) -> Registry:
    registry = Registry()
    for interface, (hook_name, base) in INTERFACES.items():
        hook = getattr(pm.hook, hook_name)
        for impl in hook.get_hookimpls():
            provider = _provider_name(pm, impl.plugin)
            classes = impl.function() or []
            for cls in classes:
                if not (isinstance(cls, type) and issubclass(cls, base)):
                    raise PluginError(
                        f"plugin {provider}: {hook_name} returned {cls!r}, "
                        f"which is not a {base.__name__} subclass"
                    )
                name = getattr(cls, "name", None)
                if not isinstance(name, str) or not name:
                    raise PluginError(f"plugin {provider}: {cls.__name__} has no 'name'")
                known = registry.plugins[interface]
                if name in known:
                    raise PluginError(
                        f"two {interface} plugins are named {name!r}: "
                        f"{known[name].provider} and {provider}"
                    )
                known[name] = PluginInfo(cls, interface, provider)
    return registry


def make_plugin_manager(
    modules: Iterable[Any] = (), *, autoload: bool | None = None
) -> pluggy.PluginManager:
    """A plugin manager with the hookspecs, the given plugin modules and (unless disabled) every
    ``mdframework`` entry point. An import error in a plugin propagates to the caller."""
    pm = pluggy.PluginManager(hookspecs.PROJECT)
    pm.add_hookspecs(hookspecs)
    for module in modules:
        pm.register(module)
    if autoload is None:
        autoload = os.environ.get(DISABLE_ENV, "") in ("", "0")
    if autoload:
        _load_entry_points(pm)
    pm.check_pending()
    return pm


def build_registry(modules: Iterable[Any] = (), *, autoload: bool | None = None) -> Registry:
    """Load plugins and build the registry (see :func:`make_plugin_manager`)."""
    return _collect(make_plugin_manager(modules, autoload=autoload))


@cache
def default_registry() -> Registry:
    """The registry of installed plugins, built once per process."""
    return build_registry()
