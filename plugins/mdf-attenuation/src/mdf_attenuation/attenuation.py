"""Atmospheric and rain attenuation versus range (effect kind ``attenuation``, stage
``scatterers``).

The one-way specific attenuation ``gamma`` [dB/km] is the sum of a gaseous part
``gas_db_per_km`` and a rain part ``gamma_R = k R_r^alpha`` (the power law of ITU-R P.838, with
rain rate ``R_r`` [mm/h] and the coefficients ``k``, ``alpha`` for the radar's frequency and
polarisation, which the user supplies: they are not tabulated here). The wave crosses the
medium twice, so a scatterer at range ``R`` [m] loses

    ``L(R) = 2 gamma R / 1000``  [dB] (two-way),

applied as a power factor on its RCS: ``sigma' = sigma 10^(-L(R)/10)`` for every pulse, with
``R`` the scatterer's own range at that pulse (so the loss follows each scatterer; over a body
it differs by a negligible ``2 gamma dR``). The medium is taken as uniform along the path and
present over all of it (``path_fraction`` < 1 limits it to that fraction of the range, e.g. a
rain cell). The waveform's constant ``atmospheric_loss_db`` is a separate, range-independent
loss; use one or the other.

Effects that add scatterers (``multipath``'s ground-bounce paths, ``static_scene``'s room) must
be listed before this one, so that each of their paths loses what its own length loses (the image
over its round trip ``2 R_b``, a reflector over its range): listed after it, a bounced path
would keep the direct path's loss and a reflector none, so that order is refused.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import Field, model_validator

from mdframework import Effect, PluginConfig, Scatterers, SceneContext

FloatArray = NDArray[np.float64]


class AttenuationConfig(PluginConfig):
    """Uniform atmospheric (gaseous) and rain attenuation along the radar path."""

    kind: Literal["attenuation"] = "attenuation"
    gas_db_per_km: float = Field(
        0.0, ge=0, le=1000, description="One-way gaseous specific attenuation [dB/km]."
    )
    rain_rate_mm_per_h: float = Field(0.0, ge=0, le=1000, description="Rain rate R_r [mm/h].")
    rain_k: float | None = Field(
        None,
        gt=0,
        le=100,
        description="ITU-R P.838 coefficient k for the frequency and polarisation.",
    )
    rain_alpha: float | None = Field(
        None,
        gt=0,
        le=10,
        description="ITU-R P.838 exponent alpha for the frequency and polarisation.",
    )
    path_fraction: float = Field(
        1.0, gt=0, le=1, description="Fraction of the range over which the medium is present."
    )

    @model_validator(mode="after")
    def _check(self) -> AttenuationConfig:
        if self.rain_rate_mm_per_h > 0 and (self.rain_k is None or self.rain_alpha is None):
            raise ValueError("rain needs rain_k and rain_alpha (ITU-R P.838 coefficients)")
        return self


def specific_attenuation(
    gas_db_per_km: float,
    rain_rate_mm_per_h: float = 0.0,
    rain_k: float | None = None,
    rain_alpha: float | None = None,
) -> float:
    """One-way specific attenuation ``gamma = gas + k R_r^alpha`` [dB/km]."""
    gamma = float(gas_db_per_km)
    if rain_rate_mm_per_h > 0:
        if rain_k is None or rain_alpha is None:
            raise ValueError("rain needs k and alpha")
        gamma += rain_k * rain_rate_mm_per_h**rain_alpha
    return gamma


def two_way_loss(
    ranges: ArrayLike, gamma_db_per_km: float, path_fraction: float = 1.0
) -> FloatArray:
    """Two-way power loss factor ``10^(-2 gamma f R / 10^4)`` (<= 1) for ranges [m], any shape."""
    r = np.asarray(ranges, dtype=np.float64)
    loss_db = 2.0 * gamma_db_per_km * path_fraction * r / 1000.0
    return np.asarray(10.0 ** (-loss_db / 10.0), dtype=np.float64)


#: effects that add scatterers, and what listing them after this one would do
ADDS_SCATTERERS = {
    "multipath": "the ground-bounce paths would lose the direct path's attenuation, not their own",
    "static_scene": "the room's reflectors would not be attenuated",
}


class Attenuation(Effect):
    """Scales each scatterer's RCS by the two-way attenuation of its own range."""

    name = "attenuation"
    Config = AttenuationConfig
    config: AttenuationConfig
    stage = "scatterers"

    def gamma(self) -> float:
        """One-way specific attenuation [dB/km]."""
        c = self.config
        return specific_attenuation(c.gas_db_per_km, c.rain_rate_mm_per_h, c.rain_k, c.rain_alpha)

    def check_effects(self, effects: Sequence[Effect]) -> None:
        """Refuse an effect listed after this one that adds scatterers (:data:`ADDS_SCATTERERS`):
        they would not lose what their own path loses."""
        self.refuse_listed_after(effects, ADDS_SCATTERERS)

    def apply(self, data: Scatterers, context: SceneContext) -> Scatterers:
        """Scatterers with RCS reduced by the two-way path loss."""
        factor = two_way_loss(
            data.ranges(context.radar_position), self.gamma(), self.config.path_fraction
        )
        return data.replace(rcs=data.rcs * factor)

    def describe(self) -> dict[str, Any]:
        """The config plus the one-way specific attenuation [dB/km]."""
        return {**self.config.model_dump(), "specific_attenuation_db_per_km": self.gamma()}
