"""A receiver gain: multiplies the compressed return by ``10^(gain_db / 20)``."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field

from mdframework import Effect, PluginConfig, Received, SceneContext


class GainConfig(PluginConfig):
    """Receiver gain."""

    kind: Literal["gain"] = "gain"
    gain_db: float = Field(20.0, ge=-100, le=100, description="Power gain [dB].")


class Gain(Effect):
    """Multiplies the received signal (and range-time data) by ``10^(gain_db / 20)``: the
    power, and so the spectrogram before its normalisation, rises by ``gain_db``."""

    name = "gain"
    Config = GainConfig
    config: GainConfig
    stage = "received"

    def apply(self, data: Received, context: SceneContext) -> Received:
        """A new Received (never modify ``data`` in place; always return it)."""
        factor = 10.0 ** (self.config.gain_db / 20.0)
        range_time = None if data.range_time is None else data.range_time * factor
        return Received(data.signal * factor, range_time, data.range_axis)

    def describe(self) -> dict[str, Any]:
        """Recorded in the run's metadata."""
        return {
            "gain_db": self.config.gain_db,
            "amplitude_factor": 10.0 ** (self.config.gain_db / 20),
        }
