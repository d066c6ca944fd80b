"""Domain randomisation: scene and motion parameters drawn per record from distributions.

A dataset config's ``[randomize]`` section names distributions; every record draws its own
values from a generator seeded by the dataset seed and what the record is (its source's motion,
window, grid point and draw; see :func:`mdframework.dataset.plan_records`), so a dataset is the
same whatever the number of workers, and every drawn value is written to the dataset table
(``index.csv`` columns ``draw.<name>``).

Distributions (one key each)::

    radar_height = { uniform = [0.8, 1.6] }        # low, high
    aspect_deg   = { normal = [0.0, 30.0] }        # mean, standard deviation
    snr          = { choice = [10, 20, 30] }       # one of the values, equally likely
    speed        = { loguniform = [0.7, 1.4] }     # log-uniform between low and high

Named scene parameters: ``aspect_deg``, ``radar_range``, ``radar_height`` (as the grid
variations), ``height`` (the person's height, for sources that have one). Any other run-config
field is drawn through ``params`` with its dotted path, list items by position::

    [randomize.params]
    "effects.0.snr_db" = { uniform = [5.0, 25.0] }
    "radar.beamwidth_elevation_deg" = { uniform = [20.0, 60.0] }

Motion augmentation (:mod:`mdframework.augment`), per record: ``speed`` (speed factor,
0.1 .. 10), ``body_scale`` (height factor, 0.5 .. 2), ``mirror`` (probability of the mirror
image) and ``time_warp`` (strength ``s`` < 1: three warp coefficients drawn uniformly from
``[-s/3, s/3]``). The factors' distributions must lie within their ranges (a normal one to 4
standard deviations; a rarer draw beyond is clipped).
"""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np
from pydantic import Field, field_validator, model_validator

from . import limits
from .settings import StrictModel

#: A number drawn into a config field; the field's own range applies to what is drawn (each
#: record's config is validated), this only keeps the distribution finite.
Number = Annotated[float, Field(ge=-limits.MAX_DRAWN_NUMBER, le=limits.MAX_DRAWN_NUMBER)]
Whole = Annotated[int, Field(ge=-int(limits.MAX_DRAWN_NUMBER), le=int(limits.MAX_DRAWN_NUMBER))]
Scalar = Number | Whole | str | bool


class Distribution(StrictModel):
    """One distribution: give exactly one of the fields."""

    uniform: tuple[Number, Number] | None = Field(None, description="[low, high].")
    loguniform: tuple[Number, Number] | None = Field(
        None, description="[low, high], both > 0: uniform in log."
    )
    normal: tuple[Number, Number] | None = Field(None, description="[mean, std].")
    choice: list[Scalar] | None = Field(None, min_length=1, description="Equally likely values.")

    @model_validator(mode="after")
    def _one(self) -> Distribution:
        given = [k for k in ("uniform", "loguniform", "normal", "choice") if getattr(self, k)]
        if len(given) != 1:
            raise ValueError("give exactly one of uniform, loguniform, normal, choice")
        lo_hi = self.uniform or self.loguniform
        if lo_hi is not None and not lo_hi[0] <= lo_hi[1]:
            raise ValueError("low must not exceed high")
        if self.loguniform is not None and self.loguniform[0] <= 0:
            raise ValueError("loguniform bounds must be positive")
        if self.normal is not None and self.normal[1] < 0:
            raise ValueError("the standard deviation must be >= 0")
        return self

    def support(self) -> tuple[float, float] | None:
        """The smallest and largest value drawn (a normal distribution: 4 standard deviations
        about its mean); None for a choice that is not all numbers."""
        if self.uniform is not None:
            return self.uniform
        if self.loguniform is not None:
            return self.loguniform
        if self.normal is not None:
            mean, std = self.normal
            return mean - 4.0 * std, mean + 4.0 * std
        assert self.choice is not None
        numbers = [v for v in self.choice if isinstance(v, int | float) and not isinstance(v, bool)]
        if len(numbers) != len(self.choice):
            return None
        return float(min(numbers)), float(max(numbers))

    def draw(self, rng: np.random.Generator) -> Scalar:
        """One value."""
        if self.uniform is not None:
            return float(rng.uniform(*self.uniform))
        if self.loguniform is not None:
            lo, hi = np.log(self.loguniform[0]), np.log(self.loguniform[1])
            return float(np.exp(rng.uniform(lo, hi)))
        if self.normal is not None:
            return float(rng.normal(*self.normal))
        assert self.choice is not None
        value = self.choice[int(rng.integers(len(self.choice)))]
        return value


#: Range of a motion augmentation's factors: ``speed`` plays a motion ten times slower to ten
#: times faster; ``body_scale`` makes a body of half to twice the size.
FACTOR_RANGES = {"speed": (0.1, 10.0), "body_scale": (0.5, 2.0)}


class Randomization(StrictModel):
    """Per-record draws (see the module docstring); every field is optional."""

    draws: int = Field(1, ge=1, le=10_000, description="Records drawn per window and grid point.")
    aspect_deg: Distribution | None = Field(None, description="Facing [deg].")
    radar_range: Distribution | None = Field(None, description="Horizontal distance [m].")
    radar_height: Distribution | None = Field(None, description="Radar height [m].")
    height: Distribution | None = Field(None, description="Person's height [m].")
    params: dict[str, Distribution] = Field(
        default_factory=dict, description="Dotted run-config path -> distribution."
    )
    speed: Distribution | None = Field(None, description="Motion speed factor.")
    body_scale: Distribution | None = Field(None, description="Body size factor.")
    mirror: float = Field(0.0, ge=0, le=1, description="Probability of the mirror image.")
    time_warp: float = Field(
        0.0,
        ge=0,
        lt=1,
        description="Time-warp strength s, dimensionless (0: none; three warp coefficients drawn "
        "uniformly between -s/3 and s/3).",
    )

    @field_validator("params")
    @classmethod
    def _field_paths(cls, params: dict[str, Distribution]) -> dict[str, Distribution]:
        for path in params:
            if path.split(".")[0] == "seed":
                raise ValueError(
                    f"\"{path}\": each record's seed derives from the dataset's top-level seed "
                    "and what the record is; it is not drawn"
                )
            if "." not in path:
                raise ValueError(
                    f'"{path}": not a field of a run-config section; give a dotted path such as '
                    '"radar.prf" (the named draws, e.g. speed, go beside params)'
                )
        return params

    @model_validator(mode="after")
    def _factors(self) -> Randomization:
        for name, (lo, hi) in FACTOR_RANGES.items():
            dist = getattr(self, name)
            span = None if dist is None else dist.support()
            if dist is not None and span is None:
                raise ValueError(f"{name}: the choices must be numbers")
            if span is not None and not lo <= span[0] <= span[1] <= hi:
                raise ValueError(
                    f"{name}: draws {span[0]:g} .. {span[1]:g} (a normal distribution counted to "
                    f"4 standard deviations), outside the factor's range {lo:g} .. {hi:g}"
                )
        return self

    def active(self) -> bool:
        """Whether anything is drawn."""
        return bool(
            self.aspect_deg
            or self.radar_range
            or self.radar_height
            or self.height
            or self.params
            or self.speed
            or self.body_scale
            or self.mirror
            or self.time_warp
        )

    def sample(self, rng: np.random.Generator) -> dict[str, Any]:
        """One record's draws, ``{name: value}`` in a fixed order (``params`` by path,
        ``time_warp`` as a list of three coefficients)."""
        out: dict[str, Any] = {}
        for name in ("aspect_deg", "radar_range", "radar_height", "height"):
            dist = getattr(self, name)
            if dist is not None:
                out[name] = dist.draw(rng)
        for path in sorted(self.params):
            out[path] = self.params[path].draw(rng)
        for name, (lo, hi) in FACTOR_RANGES.items():
            dist = getattr(self, name)
            if dist is not None:  # a normal draw beyond 4 standard deviations is clipped
                out[name] = float(np.clip(float(dist.draw(rng)), lo, hi))
        if self.mirror:
            out["mirror"] = bool(rng.uniform() < self.mirror)
        if self.time_warp:
            s = self.time_warp / 3.0
            out["time_warp"] = [float(c) for c in rng.uniform(-s, s, 3)]
        return out


def set_path(config: dict[str, Any], path: str, value: Any) -> None:
    """Set ``config[a][b][0][c] = value`` for ``path = "a.b.0.c"`` in place. Missing tables
    are created; a list index must exist. ``KeyError`` names the part that does not fit."""
    parts = path.split(".")
    node: Any = config
    for i, part in enumerate(parts[:-1]):
        where = ".".join(parts[: i + 1])
        if isinstance(node, list):
            if not part.isdigit() or int(part) >= len(node):
                raise KeyError(f"{where}: no item {part} in a list of {len(node)}")
            node = node[int(part)]
        elif isinstance(node, dict):
            node = node.setdefault(part, {})
        else:
            raise KeyError(f"{where}: not a table or list")
    last = parts[-1]
    if isinstance(node, list):
        if not last.isdigit() or int(last) >= len(node):
            raise KeyError(f"{path}: no item {last} in a list of {len(node)}")
        node[int(last)] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise KeyError(f"{path}: not a table or list")
