"""Ground-bounce multipath through image scatterers (effect kind ``multipath``, stage
``scatterers``).

A flat specular ground plane ``z = ground_height`` with a complex reflection coefficient
``Gamma = |Gamma| exp(j phi)`` (default ``-1 x 0.6``: smooth ground near grazing incidence).
For a scatterer at ``p`` (above the plane) and a radar at ``r``, let ``p'`` be the mirror image of
``p`` in the plane, ``R_d = |p - r|`` (direct) and ``R_b = |p' - r|`` (the length of the path
radar -> ground -> p). A monostatic radar then receives, besides the direct echo (round trip
``2 R_d``):

- two **single-bounce** echoes (radar -> p -> ground -> radar and the reverse), each of round trip
  ``R_d + R_b`` and amplitude ``Gamma``; they add coherently to ``2 Gamma``. They are one virtual
  scatterer ``name~bounce`` at range ``R_m = (R_d + R_b)/2`` (delay ``(R_d + R_b)/c``; Doppler
  the mean of the direct and image Dopplers), placed along the bisector of the directions to
  ``p`` and ``p'``;
- one **double-bounce** echo (radar -> ground -> p -> ground -> radar), round trip ``2 R_b``,
  amplitude ``Gamma^2``: the image scatterer ``name~image`` at ``p'`` (delay ``2 R_b / c``,
  Doppler from ``dR_b/dt``).

The Scatterers interface carries positions and RCS only, so each path's complex factor is encoded
exactly: its magnitude in the RCS and its phase ``psi`` (``phi`` or ``2 phi``, wrapped to
``(-pi, pi]``) as a sub-wavelength range offset ``delta = -psi lambda / (4 pi)`` (``|delta| <=
lambda/4``, 5 mm at 15 GHz), since the return goes as ``exp(-j 4 pi f_c R/c)``. The RCS carries the
range-equation correction as well, so the waveform's ``1/R^2`` amplitude at the virtual range
``R_v = R + delta`` reproduces the path's true spreading:

- bounce: ``sigma_m = 4 |Gamma|^2 sigma_db R_v^4 / (R_d^2 R_b^2)``;
- image:  ``sigma_i = |Gamma|^4 sigma_b R_v^4 / R_b^4``.

``sigma_b`` is the scatterer's RCS seen from the image radar ``r'`` (the direction along which the
bounced wave meets it), ``sigma_db = sqrt(sigma sigma_b)`` the geometric mean used for the
bistatic single-bounce paths. When the scatterers carry spheroid shapes (``semi_axes``, ``axes``:
the ``ellipsoid`` and ``mujoco_body`` models) ``sigma_b = sigma x sigma_GO(r' - p)/sigma_GO(r - p)``
(spheroid RCS ratio of the two aspects); otherwise ``sigma_b = sigma``. Scatterers below the
plane get no images. ``paths = "image"`` keeps only the double-bounce image.

Scatterers that sit at their shapes' specular points (``Scatterers.specular``: the ``ellipsoid``
model's ``scattering_phase = "specular"``) keep their direct echo; the bounced paths are built
from their ``centres`` ``p``, each with its own specular point: the image at the range
``R_b - h(u_b)`` (``u_b`` toward the image radar, ``h`` the spheroid's support function), the
bistatic single bounce at ``(R_d + R_b)/2 - |u_d + u_b|/2 h((u_d + u_b)/|u_d + u_b|)`` (the
stationary point of the path length over the surface), and the spreading corrections take these
path lengths. The virtual scatterers' ``centres`` are where they would sit without the shift.

Put ``multipath`` after ``shadowing`` (the other order is refused): the bounced paths are then
made from the shadowed RCS, so each takes the visibility of its scatterer's direct path (an
approximation: a path arriving from below, through the ground, can be hidden where the direct
one is not, and the other way round). Put it before ``antenna`` and ``attenuation`` (which
refuse the other order): the antenna then weighs the image by ``g(u_b)^2`` and the single
bounce by ``g(u_d) g(u_b)``, and the attenuation takes each path over its own length
(``2 R_b``, ``R_d + R_b``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from mdframework import Effect, PluginConfig, Scatterers, SceneContext, SceneError, Skeleton
from mdframework.physics import radar, rcs
from mdframework.settings import AngleDeg, Coordinate

FloatArray = NDArray[np.float64]


class MultipathConfig(PluginConfig):
    """Specular ground-bounce multipath from a flat ground plane."""

    kind: Literal["multipath"] = "multipath"
    ground_height: Coordinate = Field(0.0, description="Height z of the ground plane [m].")
    reflection_magnitude: float = Field(
        0.6, ge=0, le=1, description="|Gamma|, the ground's amplitude reflection coefficient."
    )
    reflection_phase_deg: AngleDeg = Field(
        180.0, description="Phase of Gamma [deg]; 180 = sign inversion (grazing incidence)."
    )
    paths: Literal["all", "image"] = Field(
        "all",
        description="all: single-bounce (2 Gamma) and double-bounce (Gamma^2) paths; "
        "image: the double-bounce image scatterer only.",
    )
    image_aspect: bool = Field(
        True,
        description="Spheroid scatterers: take the RCS of the bounced paths at the image "
        "radar's aspect (else the direct RCS).",
    )


def mirror(points: FloatArray, ground_height: float) -> FloatArray:
    """Mirror images of points (..., 3) [m] in the plane ``z = ground_height``."""
    out = np.array(points, dtype=np.float64, copy=True)
    out[..., 2] = 2.0 * ground_height - out[..., 2]
    return out


def _unit(v: FloatArray) -> FloatArray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.asarray(v / np.where(n > 0, n, 1.0), dtype=np.float64)


def _phase_offset(psi: float, wavelength: float) -> float:
    """Range offset [m] that multiplies a return by ``exp(j psi)``."""
    wrapped = float(np.angle(np.exp(1j * psi)))
    return -wrapped * wavelength / (4.0 * np.pi)


#: what ``shadowing`` listed after this effect would do
SHADOWED_AFTER = {
    "shadowing": "it would cast rays to the bounced paths' virtual places, which are not their "
    "paths, and take those copies' ellipsoids for parts of the body that hide the others",
}


class GroundMultipath(Effect):
    """Adds the ground-bounce virtual scatterers of every scatterer."""

    name = "multipath"
    Config = MultipathConfig
    config: MultipathConfig
    stage = "scatterers"

    def __init__(self, config: PluginConfig | None = None) -> None:
        super().__init__(config)
        self._stats: dict[str, Any] = {}
        self._extra = [0, 0]  # the record's sum of R_b - R_d [2**-20 m] and its count

    def start_record(self, body: Skeleton, radar_position: FloatArray) -> None:
        """Start the record's sums of the extra path lengths (:meth:`describe`)."""
        self._extra = [0, 0]

    def check_effects(self, effects: Sequence[Effect]) -> None:
        """Refuse ``shadowing`` listed after this one (:data:`SHADOWED_AFTER`)."""
        self.refuse_listed_after(effects, SHADOWED_AFTER)

    def _aspect_ratio(
        self, data: Scatterers, p: FloatArray, r: FloatArray, r_img: FloatArray
    ) -> FloatArray:
        """``sigma_GO(seen from r') / sigma_GO(seen from r)`` per (pulse, scatterer) of shapes
        centred at ``p`` (n_pulses, n_scatterers, 3) [m]."""
        if not self.config.image_aspect or data.semi_axes is None or data.axes is None:
            return np.ones(data.rcs.shape)
        a = data.semi_axes[:, 0]
        c = data.semi_axes[:, 2]
        direct = rcs.spheroid_rcs(a, c, data.axes, r - p)
        bounced = rcs.spheroid_rcs(a, c, data.axes, r_img - p)
        return np.asarray(bounced / direct, dtype=np.float64)

    def apply(self, data: Scatterers, context: SceneContext) -> Scatterers:
        """The scatterers followed by their bounce and image scatterers."""
        c = self.config
        h = c.ground_height
        r = np.asarray(context.radar_position, dtype=np.float64)
        if r[2] <= h:
            raise SceneError(
                f"effects.multipath: the radar (z = {r[2]:g} m) is not above the ground plane "
                f"(z = {h:g} m)"
            )
        lam = radar.wavelength(context.carrier_frequency)
        gamma = c.reflection_magnitude
        phi = np.deg2rad(c.reflection_phase_deg)
        mask = data.specular if data.specular is not None else np.zeros(0, dtype=bool)
        p = data.positions
        if np.any(mask) and data.centres is not None:  # those at specular points: their centres
            p = np.where(mask[:, None], data.centres, data.positions)
        above = p[..., 2] > h
        p_img = mirror(p, h)
        r_img = mirror(r, h)
        r_d = np.linalg.norm(p - r, axis=-1)
        r_b = np.linalg.norm(p_img - r, axis=-1)
        sigma_b = data.rcs * self._aspect_ratio(data, p, r, r_img)
        # scatterers at their specular points (centres given): each path's echo comes from
        # the specular point for its own directions, at the path length less the support
        # function: h(u_b) seen from the image radar, |u_d + u_b|/2 h(bisector) bistatic
        spec_b = spec_m = np.zeros(0)
        if np.any(mask) and data.semi_axes is not None and data.axes is not None:
            a, semi_c = data.semi_axes[:, 0], data.semi_axes[:, 2]
            _, h_b = rcs.spheroid_specular_point(a, semi_c, data.axes, r_img - p)
            bisector = _unit(r - p) + _unit(r_img - p)
            _, h_m = rcs.spheroid_specular_point(a, semi_c, data.axes, bisector)
            spec_b = np.where(mask, h_b, 0.0)
            spec_m = np.where(mask, 0.5 * np.linalg.norm(bisector, axis=-1) * h_m, 0.0)

        # double bounce: image scatterer at p', range R_b + delta_2
        delta2 = _phase_offset(2.0 * phi, lam)
        u_img = _unit(p_img - r)
        r_v2 = r_b + delta2
        r_b_go = r_b  # the path's own length, for its spreading
        if spec_b.size:
            r_v2 = r_v2 - spec_b
            r_b_go = r_b - spec_b
        pos_img = r + u_img * r_v2[..., None]
        rcs_img = gamma**4 * sigma_b * (r_v2 / r_b_go) ** 4
        parts_pos = [data.positions, pos_img]
        parts_rcs = [data.rcs, np.where(above, rcs_img, 0.0)]
        names = [*data.names, *(f"{n}~image" for n in data.names)]
        # the copies' unshifted places, the centres of their ellipsoids (only if the scatterers
        # carry centres: the default path builds nothing it does not return)
        keep_centres = data.centres is not None
        virtual = [r + u_img * (r_b + delta2)[..., None]] if keep_centres else []
        n_copies = 2
        if c.paths == "all":
            delta1 = _phase_offset(phi, lam)
            r_v1 = 0.5 * (r_d + r_b) + delta1
            r_d_go = r_d
            if spec_m.size:
                r_v1 = r_v1 - spec_m
                r_d_go = np.linalg.norm(data.positions - r, axis=-1)
            u_mid = _unit(_unit(p - r) + u_img)
            pos_mid = r + u_mid * r_v1[..., None]
            sigma_db = np.sqrt(data.rcs * sigma_b)
            rcs_mid = 4.0 * gamma**2 * sigma_db * r_v1**4 / (r_d_go**2 * r_b_go**2)
            parts_pos.append(pos_mid)
            parts_rcs.append(np.where(above, rcs_mid, 0.0))
            names += [f"{n}~bounce" for n in data.names]
            if keep_centres:
                virtual.append(r + u_mid * (0.5 * (r_d + r_b) + delta1)[..., None])
            n_copies = 3
        semi_axes = axes = None
        if data.semi_axes is not None and data.axes is not None:
            semi_axes = np.concatenate([data.semi_axes] * n_copies, axis=0)
            ax_img = data.axes.copy()
            ax_img[..., 2] *= -1.0
            axes = np.concatenate([data.axes, ax_img, data.axes][:n_copies], axis=1)
        # summed exactly, in whole steps of 2**-20 m (about 1 um), so that the record's mean
        # has the same bits whatever its cut into blocks (a float sum's rounding would not)
        steps = np.rint((r_b - r_d) * 2.0**20).astype(np.int64)
        self._extra[0] += int(steps.sum())
        self._extra[1] += int(steps.size)
        bounce = self._extra[0] / max(self._extra[1], 1) / 2.0**20
        self._stats = {
            "extra_path_m": {"image_mean": 2.0 * bounce, "bounce_mean": bounce},
            "n_virtual_scatterers": int(len(names) - len(data.names)),
        }
        return Scatterers(
            np.concatenate(parts_pos, axis=1),
            np.concatenate(parts_rcs, axis=1),
            tuple(names),
            semi_axes,
            axes,
            centres=None
            if data.centres is None
            else np.concatenate([data.centres, *virtual], axis=1),
            specular=None
            if data.specular is None
            else np.concatenate([data.specular, np.zeros(len(names) - len(data.names), bool)]),
        )

    def describe(self) -> dict[str, Any]:
        """The config plus the mean extra round-trip path lengths [m] over the record's pulses
        and scatterers (to about 1 um)."""
        return {**self.config.model_dump(), **self._stats}
