"""CW Doppler radar (kind ``cw``): the I/Q baseband of a continuous-wave radar at any carrier.

A CW radar transmits one frequency and mixes the echo down with it; the complex (I/Q) baseband
is sampled at ``sample_rate``:

    ``y(t) = sum_i a_i(t) exp(-j 4 pi f_c R_i(t) / c)``

(the project's phase convention: an approaching target has positive Doppler ``2 v / lambda``).
There is no range resolution: every scatterer in the beam contributes, whatever its range, so the
range gate is ignored. Amplitudes follow the radar range equation (``amplitude =
"range_equation"``) or are ``sqrt(sigma)`` (``"sqrt_rcs"``, no range dependence). The carrier
phase is reduced to a fraction of a cycle in float64 before any complex number is formed.

Typical carriers: 5.8 GHz and 24 GHz (ISM bands), the latter the K-band of low-cost Doppler
modules. The slow-time rate is the I/Q sample rate, so the unambiguous velocity is
``lambda fs / 4`` (at 24 GHz and 2 kHz: 6.25 m/s).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

import numpy as np
from pydantic import Field

from mdframework import RadarWaveform, Received, limits
from mdframework.physics import radar
from mdframework.settings import RadarPowerConfig

if TYPE_CHECKING:
    from mdframework.interfaces import PulseBlock


class CwConfig(RadarPowerConfig):
    """CW Doppler radar. Defaults: a 24 GHz K-band module sampled at 2 kHz."""

    kind: Literal["cw"] = "cw"
    carrier_frequency: float = Field(
        24.125e9,
        ge=limits.MIN_CARRIER_HZ,
        le=limits.MAX_CARRIER_HZ,
        description="Carrier frequency [Hz], 1 MHz .. 1 THz.",
    )
    sample_rate: float = Field(
        2000.0,
        ge=limits.MIN_PRF_HZ,
        le=limits.MAX_PRF_HZ,
        description="I/Q sample rate (slow time) [Hz].",
    )

    def pulse_rate(self) -> float:
        """I/Q samples per second [Hz]: the rate of the pulse budget."""
        return self.sample_rate


class CwDoppler(RadarWaveform):
    """Monostatic CW Doppler radar: complex baseband of every scatterer, no range gating."""

    name = "cw"
    Config = CwConfig
    config: CwConfig

    @property
    def carrier_frequency(self) -> float:
        """Carrier frequency [Hz]."""
        return self.config.carrier_frequency

    @property
    def prf(self) -> float:
        """I/Q sample rate [Hz] (the slow-time rate)."""
        return self.config.sample_rate

    def faster_sampling(self, rate: float) -> str:
        """The slow-time rate is the I/Q ``sample_rate``."""
        return f"raise radar.sample_rate to at least {np.ceil(rate):.0f} Hz"

    def receive(self, block: PulseBlock) -> Received:
        """I/Q baseband of the block's pulses: the sum of every scatterer's phasor."""
        ranges = block.ranges
        amp = self.config.amplitudes(
            block.scatterers.rcs, ranges, radar.wavelength(self.carrier_frequency)
        )
        signal = radar.compressed_return_at_gate(
            ranges,
            amp,
            block.gate_range,
            carrier_frequency=self.carrier_frequency,
            pulse_width=1.0,
            bandwidth=1.0,
            response="phase_only",
        )
        return Received(np.asarray(signal, dtype=np.complex128))
