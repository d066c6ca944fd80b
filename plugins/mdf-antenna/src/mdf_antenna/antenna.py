"""Antenna gain pattern (effect kind ``antenna``, stage ``scatterers``).

The waveform's ``gain_dbi`` is the boresight gain ``G_0`` in the range equation; this effect
applies the pattern *relative to boresight*, ``g(direction) = G(direction)/G_0 <= 1`` (one-way,
power). The radar is monostatic with one antenna for transmit and receive, so the received power
of a scatterer scales by ``g^2`` (two-way) and its RCS is multiplied by ``g^2``; a scatterer at
the one-way -3 dB edge of the beam (``theta = beamwidth/2`` off boresight) is 6 dB down.

Geometry: the boresight unit vector ``b`` points along azimuth ``az`` (from +x toward +y) and
elevation ``el`` (up from horizontal); ``e_az = (-sin az, cos az, 0)`` and
``e_el = b x ... = (-cos az sin el, -sin az sin el, cos el)`` complete the antenna frame. A unit
direction ``d`` from the radar to a scatterer has components ``(d.b, d.e_az, d.e_el)``.

Patterns (``beamwidth_*_deg`` are full one-way half-power widths):

- ``gaussian``: ``g = exp(-4 ln2 (theta_az^2/BW_az^2 + theta_el^2/BW_el^2))`` with the angles
  ``theta_az = atan2(d.e_az, d.b)`` and ``theta_el = atan2(d.e_el, d.b)``; ``g = 1/2`` exactly at
  ``theta = BW/2`` in either plane. A smooth main-beam model without sidelobes.
- ``uniform``: a uniformly illuminated rectangular aperture,
  ``g = sinc^2(D_az u / lambda) sinc^2(D_el v / lambda)`` in sine space ``u = d.e_az``,
  ``v = d.e_el``, with the aperture widths ``D/lambda = x_h / sin(BW/2)`` chosen so that
  ``sinc^2(x_h) = 1/2`` (x_h = 0.4429): -3 dB at the beam edge, first sidelobes -13.3 dB, nulls.

Directions behind the aperture plane (``d.b <= 0``) get ``g = 0`` (no back lobe).

Ground-bounce multipath (the ``multipath`` effect, listed before this one): a bounced path
leaves and reaches the radar along the direction of the scatterer's mirror image, so the image
scatterer ``name~image`` (placed along that direction) gets ``g(u_b)^2`` like any scatterer, and
the single-bounce scatterer ``name~bounce``, one leg direct and one bounced, gets
``g(u_d) g(u_b)``: the gains of the directions of ``name`` and ``name~image`` (its own
direction, their bisector, would give ``g(bisector)^2``, which for a beam aimed at the body can
be tens of dB too strong). Listed before ``multipath``, the bounced paths would inherit the
direct path's gain: that order is refused, as is ``static_scene`` after this effect (the
room's reflectors would be outside the pattern).

Pointing: ``pointing = "target"`` aims the boresight at the mean position of the gate's
reference point (the hip centre ``base``, or the first joint of a non-human motion) over the
record; ``steering = "track"`` re-aims it at that point on every pulse (a tracking antenna);
``pointing = "angles"`` uses ``azimuth_deg`` and ``elevation_deg``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, model_validator

from mdframework import Effect, PluginConfig, Scatterers, SceneContext, Skeleton
from mdframework.settings import AngleDeg

FloatArray = NDArray[np.float64]

#: ``x_h`` with ``sinc(x_h)^2 = 1/2`` (normalised sinc): the half-power point of a uniform aperture
#: (the root in (0, 1), found with scipy.optimize.brentq to 1e-15 and written out so that
#: importing the plugin does not import scipy.optimize; a test checks it is the root).
SINC2_HALF_POWER: float = 0.44294647068945237


class AntennaConfig(PluginConfig):
    """Antenna gain pattern relative to boresight, applied two-way to every scatterer."""

    kind: Literal["antenna"] = "antenna"
    pattern: Literal["gaussian", "uniform"] = Field(
        "gaussian",
        description="gaussian: Gaussian main beam; uniform: sinc^2 of a uniform rectangular "
        "aperture (with sidelobes and nulls).",
    )
    beamwidth_az_deg: float = Field(
        20.0, gt=0, lt=180, description="Full one-way -3 dB beamwidth in azimuth [deg]."
    )
    beamwidth_el_deg: float | None = Field(
        None,
        gt=0,
        lt=180,
        description="Full one-way -3 dB beamwidth in elevation [deg]; "
        "default: the azimuth beamwidth.",
    )
    pointing: Literal["target", "angles"] = Field(
        "target",
        description="target: aim at the gate's reference point (hip centre); angles: use "
        "azimuth_deg and elevation_deg.",
    )
    steering: Literal["fixed", "track"] = Field(
        "fixed",
        description="pointing 'target': fixed at the record's mean position, or re-aimed on "
        "every pulse.",
    )
    azimuth_deg: AngleDeg = Field(
        180.0, description="pointing 'angles': boresight azimuth, from +x toward +y [deg]."
    )
    elevation_deg: float = Field(
        0.0, ge=-90, le=90, description="pointing 'angles': boresight elevation [deg]."
    )

    @model_validator(mode="after")
    def _check(self) -> AntennaConfig:
        if self.pointing == "angles" and self.steering == "track":
            raise ValueError("steering 'track' needs pointing 'target'")
        return self


def antenna_frame(boresight: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Unit vectors ``(b, e_az, e_el)``, each (..., 3), of boresight directions (..., 3)."""
    b = boresight / np.linalg.norm(boresight, axis=-1, keepdims=True)
    az = np.arctan2(b[..., 1], b[..., 0])
    el = np.arcsin(np.clip(b[..., 2], -1.0, 1.0))
    e_az = np.stack([-np.sin(az), np.cos(az), np.zeros_like(az)], axis=-1)
    e_el = np.stack([-np.cos(az) * np.sin(el), -np.sin(az) * np.sin(el), np.cos(el)], axis=-1)
    return b, e_az, e_el


def one_way_gain(
    directions: FloatArray,
    boresight: FloatArray,
    *,
    pattern: str,
    beamwidth_az: float,
    beamwidth_el: float,
) -> FloatArray:
    """One-way power gain relative to boresight (<= 1) of directions (..., 3) (any length, not
    zero) for boresights broadcastable to them; beamwidths are full -3 dB widths [rad]."""
    d = np.asarray(directions, dtype=np.float64)
    norm = np.linalg.norm(d, axis=-1, keepdims=True)
    d = d / np.where(norm > 0, norm, 1.0)
    b, e_az, e_el = antenna_frame(np.asarray(boresight, dtype=np.float64))
    xb = np.sum(d * b, axis=-1)
    xa = np.sum(d * e_az, axis=-1)
    xe = np.sum(d * e_el, axis=-1)
    if pattern == "gaussian":
        ta = np.arctan2(xa, xb)
        te = np.arctan2(xe, xb)
        g = np.exp(-4.0 * np.log(2.0) * ((ta / beamwidth_az) ** 2 + (te / beamwidth_el) ** 2))
    elif pattern == "uniform":
        da = SINC2_HALF_POWER / np.sin(beamwidth_az / 2.0)
        de = SINC2_HALF_POWER / np.sin(beamwidth_el / 2.0)
        g = np.sinc(da * xa) ** 2 * np.sinc(de * xe) ** 2
    else:
        raise ValueError(f"unknown pattern {pattern!r}")
    return np.asarray(np.where(xb > 0, g, 0.0), dtype=np.float64)


def reference_track(context: SceneContext) -> FloatArray:
    """The gate's reference point over the pulses, (n_pulses, 3) [m]: ``base`` or joint 0."""
    skel = context.skeleton
    ref = skel.index("base") if "base" in skel.joint_names else 0
    return np.asarray(skel.positions[:, ref, :], dtype=np.float64)


#: effects that add scatterers the pattern must weigh, and what listing them after it would do
ADDS_SCATTERERS = {
    "multipath": "the ground-bounce paths would get the direct path's antenna gain",
    "static_scene": "the room's reflectors would get no antenna gain",
}

#: suffixes of the ``multipath`` effect's single-bounce and image scatterers' names
BOUNCE, IMAGE = "~bounce", "~image"


def bounce_legs(names: Sequence[str]) -> tuple[NDArray[np.intp], ...]:
    """Indices ``(bounce, direct, image)`` of every single-bounce scatterer ``name~bounce`` whose
    ``name`` and ``name~image`` are among ``names``, each (n_bounce,)."""
    index = {n: i for i, n in enumerate(names)}
    rows = []
    for i, n in enumerate(names):
        direct = n.removesuffix(BOUNCE)
        if direct != n and direct in index and direct + IMAGE in index:
            rows.append((i, index[direct], index[direct + IMAGE]))
    table = np.asarray(rows, dtype=np.intp).reshape(-1, 3)
    return table[:, 0], table[:, 1], table[:, 2]


class AntennaPattern(Effect):
    """Multiplies each scatterer's RCS by the two-way pattern gain ``g^2`` of its direction.

    A single-bounce multipath scatterer gets ``g(u_d) g(u_b)`` (the module docstring)."""

    name = "antenna"
    Config = AntennaConfig
    config: AntennaConfig
    stage = "scatterers"

    def __init__(self, config: PluginConfig | None = None) -> None:
        super().__init__(config)
        self._stats: dict[str, Any] = {}
        self._mean: FloatArray | None = None
        self._min_gain = 1.0

    def start_record(self, body: Skeleton, radar_position: FloatArray) -> None:
        """The fixed boresight's aim: the record's mean reference point (``base`` or joint 0)."""
        ref = body.index("base") if "base" in body.joint_names else 0
        track = body.positions[:, ref, :][body.valid[:, ref]]
        self._mean = np.asarray(np.mean(track, axis=0), dtype=np.float64) if track.size else None
        self._min_gain = 1.0

    def check_effects(self, effects: Sequence[Effect]) -> None:
        """Refuse an effect listed after this one that adds scatterers the pattern must weigh:
        ``multipath`` (its bounced paths would keep the direct path's gain, not the gain
        toward the ground) and ``static_scene`` (the room would be outside the pattern)."""
        self.refuse_listed_after(effects, ADDS_SCATTERERS)

    def boresight(self, context: SceneContext) -> FloatArray:
        """Boresight vector(s): (3,) or (n_pulses, 1, 3) when tracking."""
        c = self.config
        radar = np.asarray(context.radar_position, dtype=np.float64)
        if c.pointing == "angles":
            az, el = np.deg2rad(c.azimuth_deg), np.deg2rad(c.elevation_deg)
            return np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        if c.steering == "track":
            return (reference_track(context) - radar)[:, None, :]
        mean = self._mean if self._mean is not None else np.mean(reference_track(context), axis=0)
        return np.asarray(mean - radar, dtype=np.float64)

    def apply(self, data: Scatterers, context: SceneContext) -> Scatterers:
        """Scatterers with RCS times the two-way gain."""
        c = self.config
        bw_az = np.deg2rad(c.beamwidth_az_deg)
        bw_el = bw_az if c.beamwidth_el_deg is None else np.deg2rad(c.beamwidth_el_deg)
        boresight = self.boresight(context)
        d = data.positions - np.asarray(context.radar_position, dtype=np.float64)
        g = one_way_gain(d, boresight, pattern=c.pattern, beamwidth_az=bw_az, beamwidth_el=bw_el)
        b = np.asarray(boresight).reshape(-1, 3)[0]
        if context.block_start == 0 or not self._stats:
            self._min_gain = 1.0
            self._stats = {
                "boresight_azimuth_deg": float(np.degrees(np.arctan2(b[1], b[0]))),
                "boresight_elevation_deg": float(np.degrees(np.arcsin(b[2] / np.linalg.norm(b)))),
            }
        self._min_gain = min(self._min_gain, float(np.min(g)) if g.size else 1.0)
        self._stats["min_two_way_gain_db"] = float(10 * np.log10(max(self._min_gain**2, 1e-300)))
        two_way = g * g
        bounce, direct, image = bounce_legs(data.names)
        if bounce.size:  # one leg along the direct path, one toward the ground
            two_way[:, bounce] = g[:, direct] * g[:, image]
        return data.replace(rcs=data.rcs * two_way)

    def describe(self) -> dict[str, Any]:
        """The config plus the boresight (first pulse when tracking) and the smallest gain."""
        return {**self.config.model_dump(), **self._stats}
