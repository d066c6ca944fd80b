"""Static scene reflectors (effect kind ``static_scene``, stage ``scatterers``).

A real room returns echoes from the floor, walls and furniture that do not move: a radar sees
them at zero Doppler, and a sensor without static clutter removal reports them as points (in
recordings of a single-chip FMCW sensor they are most of the points near the person). This
effect adds such reflectors as point scatterers that keep their place for the whole record:

- ``reflectors``: explicit ones, each a scene position [m] and an RCS [m^2];
- ``count`` random ones, drawn once from ``seed`` (so every block of a record, and every run
  with the same seed, sees the same room): horizontal distance from the radar uniform in
  ``distance_m``, direction within ``spread_deg`` of ``azimuth_deg`` (scene frame, from +x toward
  +y; 180 = toward -x, where the person stands in the default scene), height uniform in
  ``height_m``, RCS log-uniform in ``rcs_m2``.

Positions ``(n_pulses, n_static, 3)`` are the same at every pulse, so their Doppler is exactly
0; shapes (for effects that use them) are small spheres. Put ``static_scene`` before effects
that act on every scatterer (multipath, antenna, attenuation) so those act on the room as well
(``antenna`` or ``attenuation`` before it is refused).
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, model_validator

from mdframework import ConfigSection, Effect, PluginConfig, Scatterers, SceneContext, limits
from mdframework.settings import AngleDeg, Coordinate, Point3, Seed

FloatArray = NDArray[np.float64]

#: An RCS > 0 [m^2], at most limits.MAX_RCS_M2.
PositiveRcs = Annotated[float, Field(gt=0, le=limits.MAX_RCS_M2)]
#: A horizontal distance from the radar [m], 0 .. limits.MAX_COORDINATE_M.
Reach = Annotated[float, Field(ge=0, le=limits.MAX_COORDINATE_M)]

#: semi-axis [m] of the small sphere that stands for a reflector's shape
SPHERE_M = 0.05


class Reflector(ConfigSection):
    """One static reflector."""

    position: Point3 = Field(description="Scene position (x, y, z) [m].")
    rcs_m2: PositiveRcs = Field(description="RCS [m^2].")


class StaticSceneConfig(PluginConfig):
    """Static reflectors (floor, walls, furniture) at zero Doppler."""

    kind: Literal["static_scene"] = "static_scene"
    reflectors: list[Reflector] = Field(default_factory=list, description="Explicit reflectors.")
    count: int = Field(0, ge=0, le=10_000, description="Number of random reflectors.")
    seed: Seed = Field(0, description="Seed of the random reflectors (the room).")
    distance_m: tuple[Reach, Reach] = Field(
        (0.5, 4.0), description="Horizontal distance from the radar [m], [low, high]."
    )
    azimuth_deg: AngleDeg = Field(180.0, description="Centre direction from the radar [deg].")
    spread_deg: float = Field(60.0, ge=0, le=180, description="Half-width of the directions.")
    height_m: tuple[Coordinate, Coordinate] = Field(
        (0.0, 2.0), description="Height [m], [low, high]."
    )
    rcs_m2: tuple[PositiveRcs, PositiveRcs] = Field(
        (0.01, 1.0), description="RCS [m^2], log-uniform in [low, high]."
    )

    @model_validator(mode="after")
    def _ranges(self) -> StaticSceneConfig:
        for name in ("distance_m", "height_m", "rcs_m2"):
            lo, hi = getattr(self, name)
            if lo > hi:
                raise ValueError(f"{name}: low must not exceed high")
        if self.distance_m[0] < 0 or self.rcs_m2[0] <= 0:
            raise ValueError("distance_m must be >= 0 and rcs_m2 > 0")
        return self


def room(config: StaticSceneConfig, radar_position: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Positions (n_static, 3) [m] and RCS (n_static,) [m^2] of the configured reflectors
    (explicit ones first, then the random ones drawn from ``config.seed``)."""
    pos = [np.asarray(r.position, np.float64) for r in config.reflectors]
    sig = [r.rcs_m2 for r in config.reflectors]
    if config.count:
        rng = np.random.default_rng(config.seed)
        d = rng.uniform(*config.distance_m, config.count)
        az = np.deg2rad(
            config.azimuth_deg + rng.uniform(-config.spread_deg, config.spread_deg, config.count)
        )
        z = rng.uniform(*config.height_m, config.count)
        lo, hi = np.log(config.rcs_m2[0]), np.log(config.rcs_m2[1])
        rcs = np.exp(rng.uniform(lo, hi, config.count))
        r = np.asarray(radar_position, np.float64)
        xyz = np.column_stack([r[0] + d * np.cos(az), r[1] + d * np.sin(az), z])
        pos += list(xyz)
        sig += list(rcs)
    if not pos:
        return np.zeros((0, 3)), np.zeros(0)
    return np.asarray(pos, np.float64), np.asarray(sig, np.float64)


class StaticScene(Effect):
    """Adds static reflectors (zero Doppler) to the scatterers."""

    name = "static_scene"
    Config = StaticSceneConfig
    config: StaticSceneConfig
    stage = "scatterers"

    def apply(self, data: Scatterers, context: SceneContext) -> Scatterers:
        """The scatterers followed by the room's reflectors, fixed over the pulses."""
        pos, sig = room(self.config, context.radar_position)
        n, k = data.positions.shape[0], pos.shape[0]
        if k == 0:
            return data
        positions = np.concatenate([data.positions, np.broadcast_to(pos, (n, k, 3))], axis=1)
        rcs = np.concatenate([data.rcs, np.broadcast_to(sig, (n, k))], axis=1)
        names = data.names + tuple(f"static{i}" for i in range(k))
        semi = axes = None
        if data.semi_axes is not None and data.axes is not None:
            semi = np.concatenate([data.semi_axes, np.full((k, 3), SPHERE_M)])
            up = np.broadcast_to(np.array([0.0, 0.0, 1.0]), (n, k, 3))
            axes = np.concatenate([data.axes, up], axis=1)
        centres = None
        if data.centres is not None:
            centres = np.concatenate([data.centres, positions[:, -k:]], axis=1)
        specular = None
        if data.specular is not None:
            specular = np.concatenate([data.specular, np.zeros(k, dtype=bool)])
        return Scatterers(positions, rcs, names, semi, axes, centres=centres, specular=specular)
