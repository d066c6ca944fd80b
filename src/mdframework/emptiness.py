"""Empty results: pure checks that a record holds the target it was meant to show.

A run can be valid and still simulate nothing: a target outside a fixed range gate gives an
all-zero signal, attenuation over tens of kilometres underflows every echo, and shadowing or
gating can remove most of a body. :func:`empty_result` names the cause and what to change; the
pipeline warns with it, or stops when ``processing.empty = "error"``.

The checks, in order:

1. **all zeros**: every sample of the target's echo (the received signal before the
   received-stage effects such as noise) is exactly zero;
2. **no power**: the echo's mean power is below :data:`MIN_POWER_W` (float64's smallest normal
   number: the echoes underflowed);
3. **lost scatterers**: more than ``max_lost_fraction`` of the scatterer returns (one per
   scatterer of the scatterer model and pulse, counted on every :data:`SAMPLE_EVERY`-th pulse;
   the static reflectors and multipath images that effects add are not counted) are lost, i.e.
   weighted by :data:`LOST_GAIN` or less (-20 dB) by the range gate, or cut to that by the
   scatterer-stage effects (shadowing, attenuation, antenna pattern).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

#: a scatterer return weighted by this power gain or less (-20 dB) counts as lost
LOST_GAIN = 0.01
#: the pipeline counts lost returns on every this many-th pulse (the share, not every pulse)
SAMPLE_EVERY = 8
#: an echo whose mean power [W] is below this has underflowed (float64's smallest normal)
MIN_POWER_W = float(np.finfo(np.float64).tiny)


@dataclass(frozen=True)
class Losses:
    """Scatterer returns of a record, counted (they add up across blocks of pulses).

    ``total``: scatterer x pulse pairs; ``gated``: of them, weighted by at most
    :data:`LOST_GAIN` by the range gate; ``cut``: RCS cut to at most :data:`LOST_GAIN` of the
    scatterer model's by the scatterer-stage effects (and not gated); ``range_m``: the smallest
    and largest scatterer range [m]; ``gate_m``: the smallest and largest gate range [m].
    """

    total: int = 0
    gated: int = 0
    cut: int = 0
    range_m: tuple[float, float] = (np.inf, -np.inf)
    gate_m: tuple[float, float] = (np.inf, -np.inf)

    def __add__(self, other: Losses) -> Losses:
        return Losses(
            self.total + other.total,
            self.gated + other.gated,
            self.cut + other.cut,
            (min(self.range_m[0], other.range_m[0]), max(self.range_m[1], other.range_m[1])),
            (min(self.gate_m[0], other.gate_m[0]), max(self.gate_m[1], other.gate_m[1])),
        )


def count_losses(
    ranges: FloatArray,
    gate_range: FloatArray,
    rcs_model: FloatArray | None,
    rcs: FloatArray,
    gate_gain: FloatArray | None,
) -> Losses:
    """Count the lost scatterer returns of a block of pulses.

    ``ranges`` (n, K) [m]; ``gate_range`` (n,) [m]; ``rcs_model`` (n, K) [m^2]: the scatterer
    model's RCS (None when the effects changed the scatterers, e.g. multipath images: nothing
    is counted as cut then); ``rcs`` (n, K) [m^2]: after the scatterer-stage effects;
    ``gate_gain`` (n, K): each scatterer's power gain in the range gate (1 at the gate), or None
    for a radar without a single gate (nothing is lost to gating then).
    """
    gated = np.zeros(ranges.shape, dtype=bool) if gate_gain is None else gate_gain <= LOST_GAIN
    if rcs_model is None or rcs_model.shape != rcs.shape:
        cut = np.zeros(ranges.shape, dtype=bool)
    else:
        cut = (rcs <= LOST_GAIN * rcs_model) & (rcs_model > 0) & ~gated
    if ranges.size == 0:
        return Losses()
    return Losses(
        int(ranges.size),
        int(np.count_nonzero(gated)),
        int(np.count_nonzero(cut)),
        (float(np.min(ranges)), float(np.max(ranges))),
        (float(np.min(gate_range)), float(np.max(gate_range))),
    )


def _gate_advice(losses: Losses, fixed_gate: bool, max_range: float | None) -> str:
    lo, hi = losses.range_m
    if fixed_gate:
        return (
            f"the fixed range gate at {losses.gate_m[0]:.4g} m misses the scatterers (at "
            f"{lo:.4g}-{hi:.4g} m): set scene.gate = 'track', or a gate within their ranges"
        )
    if max_range is not None and hi >= max_range:
        return (
            f"the body (at {lo:.4g}-{hi:.4g} m) reaches beyond the radar's maximum range "
            f"{max_range:.4g} m, where its range bins fold back and the tracking gate cannot "
            "follow it: bring the body within the maximum range"
        )
    return (
        f"the range gate (tracking the body) is narrower than the body's spread in range "
        f"({lo:.4g}-{hi:.4g} m): lengthen the radar's pulse, or choose a wider gate response "
        "or gate (an FMCW radar's radar.gate_width)"
    )


_CUT_ADVICE = (
    "the scene effects (shadowing, attenuation, antenna pattern) cut the scatterers' RCS by 20 dB "
    "or more: check the effects' settings, the radar's range and where its antenna points"
)


def empty_result(
    echo: NDArray[np.complexfloating],
    losses: Losses,
    *,
    max_lost_fraction: float,
    fixed_gate: bool,
    max_range: float | None = None,
) -> str | None:
    """Why a record is empty, with what to change; None when it is not.

    ``echo`` (n_pulses,) complex [sqrt(W)]: the target's received signal before received-stage
    effects (noise); ``losses``: :func:`count_losses` over the whole record;
    ``max_lost_fraction``: the largest acceptable share of lost scatterer returns;
    ``fixed_gate``: whether the range gate is fixed (else it tracks the body);
    ``max_range``: the range [m] at which the radar's range gate folds ranges back (an FMCW
    radar's maximum range; None: it does not, as the LFM radar's simulated gate does not),
    named when the body reaches it.
    """
    all_gated = losses.total > 0 and losses.gated == losses.total
    all_cut = losses.total > 0 and losses.gated + losses.cut == losses.total
    if all_gated:
        cause = _gate_advice(losses, fixed_gate, max_range)
    elif all_cut:
        cause = _CUT_ADVICE
    else:
        cause = (
            "the echoes underflow (the range equation or the attenuation over "
            f"{losses.range_m[1]:.4g} m leaves no power): bring the radar closer or reduce the "
            "attenuation"
        )
    if not np.any(echo):
        return f"empty result: the received signal is all zeros: {cause}"
    power = float(np.mean(np.abs(echo.astype(np.complex128)) ** 2))
    if not power >= MIN_POWER_W:
        return f"empty result: no power in the record (mean {power:.3g} W): {cause}"
    if losses.total == 0:
        return None
    gated = losses.gated / losses.total
    cut = losses.cut / losses.total
    if gated + cut > max_lost_fraction:
        if gated >= cut:
            why = f"{100 * gated:.0f} % are outside the range gate: "
            why += _gate_advice(losses, fixed_gate, max_range)
        else:
            why = f"{100 * cut:.0f} % are lost: {_CUT_ADVICE}"
        return (
            f"nearly empty result: {100 * (gated + cut):.0f} % of the scatterer returns are lost "
            f"(more than processing.max_lost_fraction = {max_lost_fraction:g}); {why}"
        )
    return None
