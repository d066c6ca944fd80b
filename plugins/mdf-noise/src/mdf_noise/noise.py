"""Receiver noise (effect kind ``noise``, stage ``received``).

Circular complex white Gaussian noise ``n(k)`` is added to the pulse-compressed slow-time return
at the range gate (``Received.signal``), one independent sample per pulse, drawn from the run's
seeded generator. ``sigma^2 = E|n(k)|^2`` [W] (the units of ``|signal|^2``: the waveform
normalises its compressed output so that a lone scatterer at the gate gives its range-equation
amplitude, i.e. the matched-filter output divided by the pulse width ``tau``). ``sigma^2`` is
set in one of two ways:

``mode = "snr"``
    ``snr_db`` is the **per-pulse SNR after pulse compression at the range gate**:
    ``SNR = mean_k |y(k)|^2 / sigma^2``, where ``y`` is the compressed return as the radar gave
    it (``SceneContext.echo``: before any received-stage effect, so the clutter effect, listed
    before or after this one, does not count; the paths the scatterer-stage effects add, such
    as multipath's and the room's, do), the mean over the whole record, so it includes the
    body's own fluctuations. It is a property of
    the slow-time samples, not of the spectrogram: an STFT frame with window ``w`` (length L)
    integrates a tone coherently, so a single tone of power ``P`` peaks at ``P (sum w)^2`` while
    the noise floor per bin is ``sigma^2 sum w^2``; the spectrogram's tone-to-floor ratio is
    ``SNR (sum w)^2 / sum w^2`` (``0.667 L`` for a Hann window, 22.3 dB for L = 256).

``mode = "thermal"``
    (refused with a radar whose ``amplitude`` is ``sqrt_rcs``: its signal is not in watts)
    The radar equation's receiver: noise power at the receiver input
    ``N = k_B T F B_n`` (Boltzmann's constant, system temperature ``T`` [K], noise figure ``F``
    (linear), noise bandwidth ``B_n`` [Hz], default the waveform's chirp bandwidth ``B``). The
    matched filter raises the SNR by the time-bandwidth product ``tau B``, so in the normalised
    output ``sigma^2 = k_B T F B_n / (tau B)``, which is ``k_B T F / tau`` when ``B_n = B``.
    Paired with the waveform's range-equation amplitudes this gives the physical SNR of a target
    at any range. A matched filter's output noise is ``k_B T F / tau`` whatever the receiver's
    bandwidth (white noise of density ``k_B T F``), so ``B_n`` other than ``B`` does not model a
    wider IF filter: it scales the noise by ``B_n / B``, a receiver that falls short of the
    matched filter by that factor (a mismatch loss). ``tau`` and ``B`` are read from the
    waveform's config (``pulse_width``, ``bandwidth``) or given here.

When the waveform also returns a range-time map (``Received.range_time``, the raw path), noise of
the same variance is added to every range cell, independently per cell: after pulse compression
neighbouring cells' noise is in fact correlated over ``1/B``, which this does not model.

A radar that adds its own receiver noise (the FMCW radar's ``receiver_noise``, which its
presets turn on) refuses this effect: the noise would be counted twice, and ``snr_db`` would
not be the SNR of the result. A radar that simulates the noise in its raw samples
(``RadarWaveform.takes_receiver_inputs``: the FMCW radar making maps or points) gets it there
(:meth:`ReceiverNoise.receiver_input`): ``k_B T F B_n`` per complex sample, ``B_n`` default its
``sample_rate``; mode ``snr`` is then refused (its level follows from the record's mean echo,
known only after the maps).
"""

from __future__ import annotations

import dataclasses
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, model_validator

from mdframework import (
    Effect,
    PluginConfig,
    RadarWaveform,
    Received,
    ReceiverInput,
    SceneContext,
    SceneError,
)
from mdframework.constants import BOLTZMANN
from mdframework.settings import Bandwidth, Decibels, LossDb

ComplexArray = NDArray[np.complex128]


class NoiseConfig(PluginConfig):
    """Receiver noise, from an SNR or from the receiver's noise figure and temperature."""

    kind: Literal["noise"] = "noise"
    mode: Literal["snr", "thermal"] = Field(
        "snr",
        description="snr: noise set by snr_db relative to the signal; thermal: k T F B from "
        "the receiver (physical SNR through the range equation).",
    )
    snr_db: Decibels = Field(
        20.0,
        description="mode snr: mean power of the noise-free compressed return at the gate over "
        "the noise power per pulse [dB] (per pulse, after pulse compression).",
    )
    noise_figure_db: LossDb = Field(3.0, description="mode thermal: receiver noise figure F [dB].")
    temperature: float = Field(
        290.0, gt=0, le=1e5, description="mode thermal: system noise temperature T [K]."
    )
    noise_bandwidth: Bandwidth | None = Field(
        None,
        description="mode thermal: noise bandwidth B_n [Hz]; default: chirp bandwidth. The "
        "noise is k T F B_n / (tau B): B_n other than B acts as a mismatch loss B_n / B.",
    )
    pulse_width: float | None = Field(
        None,
        gt=0,
        le=0.1,
        description="mode thermal: pulse width tau [s]; default: the waveform's.",
    )
    bandwidth: Bandwidth | None = Field(
        None, description="mode thermal: chirp bandwidth B [Hz]; default: the waveform's."
    )

    @model_validator(mode="after")
    def _check(self) -> NoiseConfig:
        if self.mode == "snr" and not np.isfinite(self.snr_db):
            raise ValueError("snr_db must be finite")
        return self


def noise_power(
    mode: str,
    *,
    signal: ComplexArray | None = None,
    snr_db: float = 20.0,
    noise_figure_db: float = 3.0,
    temperature: float = 290.0,
    noise_bandwidth: float | None = None,
    pulse_width: float = 1e-6,
    bandwidth: float = 150e6,
) -> float:
    """Noise power per compressed slow-time sample ``sigma^2`` [W] (see the module docstring).

    ``signal`` (n_pulses,) complex: the noise-free compressed return (mode ``snr``).
    """
    if mode == "snr":
        if signal is None:
            raise ValueError("mode 'snr' needs the signal")
        p_signal = float(np.mean(np.abs(signal) ** 2)) if signal.size else 0.0
        return p_signal * 10.0 ** (-snr_db / 10.0)
    if mode == "thermal":
        b_n = bandwidth if noise_bandwidth is None else noise_bandwidth
        f = 10.0 ** (noise_figure_db / 10.0)
        return BOLTZMANN * temperature * f * b_n / (pulse_width * bandwidth)
    raise ValueError(f"unknown noise mode {mode!r}")


def complex_noise(rng: np.random.Generator, shape: tuple[int, ...], power: float) -> ComplexArray:
    """Circular complex Gaussian samples with ``E|n|^2 = power`` [W], complex128."""
    scale = np.sqrt(power / 2.0)
    out = np.empty(shape, dtype=np.complex128)
    out.real = rng.standard_normal(shape) * scale
    out.imag = rng.standard_normal(shape) * scale
    return out


class ReceiverNoise(Effect):
    """Adds seeded complex white Gaussian receiver noise to the compressed return."""

    name = "noise"
    Config = NoiseConfig
    config: NoiseConfig
    stage = "received"

    def __init__(self, config: PluginConfig | None = None) -> None:
        super().__init__(config)
        self._power: float | None = None
        self._in_receiver = False

    def check_radar(self, waveform: RadarWaveform) -> None:
        """Refuse a radar that adds receiver noise itself (``RadarWaveform.adds_receiver_noise``:
        the FMCW radar's ``receiver_noise``), mode ``thermal`` with a radar whose amplitudes
        are ``sqrt(rcs)`` (``amplitude = "sqrt_rcs"``), not received powers, and mode
        ``thermal`` without the values it needs that neither the effect nor the radar's config
        gives (``pulse_width`` and ``bandwidth``; ``noise_bandwidth`` or the radar's
        ``sample_rate`` in raw samples), so that ``mdf check`` refuses them too."""
        if waveform.adds_receiver_noise:
            raise SceneError(
                f"effects.noise: the {waveform.name!r} radar adds receiver noise itself "
                "(for fmcw: radar.receiver_noise = true, as its presets set it), in its maps, "
                "points and spectrogram: remove the noise effect (or set "
                "radar.receiver_noise = false to have the effect's noise instead)"
            )
        if waveform.takes_receiver_inputs and self.config.mode == "snr":
            raise SceneError(
                f"effects.noise.mode: 'snr' sets the noise from the record's mean echo, known "
                f"only after the {waveform.name!r} radar has made its maps and points from IF "
                "samples that must carry the noise: use mode 'thermal' (k T F B_n per IF "
                "sample, in the maps, points and spectrogram), or radar.points = false and "
                "radar.save_range_doppler = false for a spectrogram alone"
            )
        amplitude = getattr(getattr(waveform, "config", None), "amplitude", None)
        if self.config.mode == "thermal" and amplitude == "sqrt_rcs":
            raise SceneError(
                "effects.noise: mode 'thermal' adds the receiver's noise in watts, but with "
                "radar.amplitude = 'sqrt_rcs' the signal is sqrt(rcs), not a received power: "
                "use mode 'snr', or radar.amplitude = 'range_equation'"
            )
        if self.config.mode != "thermal":
            return
        if waveform.takes_receiver_inputs:
            self._noise_bandwidth(waveform)
        else:
            self._waveform_param(waveform, "pulse_width")
            self._waveform_param(waveform, "bandwidth")

    def _waveform_param(self, waveform: RadarWaveform, field: str) -> float:
        """The effect's ``field``, else the radar config's; a :class:`SceneError` naming the
        effect's field when neither gives it."""
        given = getattr(self.config, field)
        if given is not None:
            return float(given)
        value = getattr(getattr(waveform, "config", None), field, None)
        if value is None:
            raise SceneError(
                f"effects.noise.{field}: mode 'thermal' needs {field}; the {waveform.name!r} "
                "waveform does not give it, so set it in the effect"
            )
        return float(value)

    def _noise_bandwidth(self, waveform: RadarWaveform) -> float:
        """``noise_bandwidth`` [Hz] in the raw samples: the effect's, else the radar config's
        ``sample_rate``; a :class:`SceneError` naming the field when neither gives it."""
        if self.config.noise_bandwidth is not None:
            return float(self.config.noise_bandwidth)
        rate = getattr(getattr(waveform, "config", None), "sample_rate", None)
        if rate is None:
            raise SceneError(
                "effects.noise.noise_bandwidth: mode 'thermal' in the raw samples of the "
                f"{waveform.name!r} radar needs noise_bandwidth (it has no sample_rate): set "
                "it in the effect"
            )
        return float(rate)

    def receiver_input(self, context: SceneContext) -> ReceiverInput | None:
        """For a radar that simulates the noise in its raw samples (the FMCW radar making maps
        or points; ``mode = "thermal"``, the only mode :meth:`check_radar` lets through):
        ``k_B T F B_n`` per complex sample, ``B_n`` default the radar's ``sample_rate`` (the
        complex ADC's noise bandwidth), drawn per frame from a key of this effect's stream."""
        c = self.config
        b_n = self._noise_bandwidth(context.waveform)
        power = BOLTZMANN * c.temperature * 10.0 ** (c.noise_figure_db / 10.0) * b_n
        self._power = power
        self._in_receiver = True
        key = int(context.rng.integers(2**63))
        return ReceiverInput(self.name, noise_power=power, noise_key=key)

    def apply(self, data: Received, context: SceneContext) -> Received:
        """The received data plus noise of power :func:`noise_power`."""
        c = self.config
        if c.mode == "snr":  # relative to the echo, whatever the order of the effects
            echo = context.echo if context.echo is not None else data.signal
            power = noise_power("snr", signal=echo, snr_db=c.snr_db)
        else:
            power = noise_power(
                "thermal",
                noise_figure_db=c.noise_figure_db,
                temperature=c.temperature,
                noise_bandwidth=c.noise_bandwidth,
                pulse_width=self._waveform_param(context.waveform, "pulse_width"),
                bandwidth=self._waveform_param(context.waveform, "bandwidth"),
            )
        self._power = power
        signal = data.signal + complex_noise(context.rng, data.signal.shape, power)
        range_time = data.range_time
        if range_time is not None:
            range_time = range_time + complex_noise(context.rng, range_time.shape, power)
        return dataclasses.replace(data, signal=signal, range_time=range_time)

    def describe(self) -> dict[str, Any]:
        """The config plus the noise power per compressed sample [W] (per raw sample for a
        radar that simulates it in its raw samples, then marked ``in_receiver``)."""
        out = {**self.config.model_dump(), "noise_power_w": self._power}
        return {**out, "in_receiver": True} if self._in_receiver else out
