"""Radar cross sections of the body-part shapes.

All RCS values are in m^2, lengths in m. Angles in radians.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def sphere_rcs_optical(radius: ArrayLike) -> FloatArray:
    """Optical-region (ka >> 1) RCS of a sphere: ``pi r^2``."""
    r = np.asarray(radius, dtype=np.float64)
    return np.asarray(np.pi * r * r, dtype=np.float64)


def sphere_rcs_mie(radius: float, wavelength: float) -> float:
    """Exact monostatic RCS of a perfectly conducting sphere (Mie series).

    ``sigma = (lambda^2/pi) |sum_n (-1)^n (n + 1/2)(b_n - a_n)|^2`` with
    ``a_n = j_n(ka)/h_n(ka)`` and
    ``b_n = (ka j_{n-1}(ka) - n j_n(ka)) / (ka h_{n-1}(ka) - n h_n(ka))``, summed to convergence.
    """
    from scipy import special

    r, lam = float(radius), float(wavelength)
    if not (0.0 < r < np.inf and 0.0 < lam < np.inf):  # NaN too
        raise ValueError(
            f"radius and wavelength must be positive and finite, got {radius!r} and {wavelength!r}"
        )
    ka = 2.0 * np.pi * r / lam
    n_max = int(ka + 4.05 * ka ** (1.0 / 3.0) + 10)
    n = np.arange(1, n_max + 1)
    jn = special.spherical_jn(n, ka)
    jn1 = special.spherical_jn(n - 1, ka)
    hn = jn + 1j * special.spherical_yn(n, ka)
    hn1 = jn1 + 1j * special.spherical_yn(n - 1, ka)
    a_n = jn / hn
    b_n = (ka * jn1 - n * jn) / (ka * hn1 - n * hn)
    total = np.sum((-1.0) ** n * (n + 0.5) * (b_n - a_n))
    return float(lam**2 / np.pi * abs(total) ** 2)


def ellipsoid_rcs_local(a: ArrayLike, b: ArrayLike, c: ArrayLike, u: ArrayLike) -> FloatArray:
    """Geometric-optics RCS of an ellipsoid with semi-axes ``a`` (x), ``b`` (y), ``c`` (z) seen
    along the unit vector ``u`` (..., 3), given in the ellipsoid's own frame.

    ``sigma = pi a^2 b^2 c^2 / (a^2 u_x^2 + b^2 u_y^2 + c^2 u_z^2)^2``. The denominator is the
    squared support function, a convex combination of a^2, b^2, c^2, hence never below
    ``min(a, b, c)^2`` for positive semi-axes: no angle makes it singular.
    """
    uu = np.asarray(u, dtype=np.float64)
    a2 = np.asarray(a, dtype=np.float64) ** 2
    b2 = np.asarray(b, dtype=np.float64) ** 2
    c2 = np.asarray(c, dtype=np.float64) ** 2
    h2 = a2 * uu[..., 0] ** 2 + b2 * uu[..., 1] ** 2 + c2 * uu[..., 2] ** 2
    return np.asarray(np.pi * a2 * b2 * c2 / (h2 * h2), dtype=np.float64)


def ellipsoid_rcs_angles(
    a: ArrayLike, b: ArrayLike, c: ArrayLike, theta: ArrayLike, phi: ArrayLike
) -> FloatArray:
    """The textbook (Mahafza) form: ``theta`` from the c-axis, ``phi`` about it from the a-axis."""
    th = np.asarray(theta, dtype=np.float64)
    ph = np.asarray(phi, dtype=np.float64)
    u = np.stack(
        [np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th) * np.ones_like(ph)],
        axis=-1,
    )
    return ellipsoid_rcs_local(a, b, c, u)


def spheroid_rcs(
    a: ArrayLike,
    c: ArrayLike,
    axis: FloatArray,
    line_of_sight: FloatArray,
    axis_norm2: FloatArray | None = None,
    los_norm2: FloatArray | None = None,
) -> FloatArray:
    """RCS of a prolate/oblate spheroid (``a = b``) whose symmetry axis is ``axis`` (..., 3),
    seen along ``line_of_sight`` (..., 3) (part -> radar). Neither vector needs unit length (see
    :func:`spheroid_rcs_from_products`). ``axis_norm2`` and ``los_norm2``: ``|axis|^2`` and
    ``|line_of_sight|^2`` when the caller has them already."""
    return spheroid_rcs_from_products(
        a,
        c,
        _dot(axis, line_of_sight),
        _dot(axis, axis) if axis_norm2 is None else axis_norm2,
        _dot(line_of_sight, line_of_sight) if los_norm2 is None else los_norm2,
    )


def spheroid_rcs_from_products(
    a: ArrayLike,
    c: ArrayLike,
    dot: FloatArray,
    axis_norm2: FloatArray,
    los_norm2: FloatArray,
) -> FloatArray:
    """RCS of a spheroid (``a = b``, semi-axis ``c`` along its symmetry axis ``A``) seen along
    ``B``, from the products ``dot = A.B``, ``axis_norm2 = |A|^2`` and ``los_norm2 = |B|^2``
    (arrays of one shape, in any layout): ``sigma = pi a^4 c^2 / (a^2 sin^2 + c^2 cos^2)^2``
    with ``cos^2 theta = (A.B)^2/(|A|^2 |B|^2)`` and ``sin^2 = 1 - cos^2`` (no arccos, no
    azimuth: it does not matter when ``a = b``). Where either vector is zero the aspect is
    undefined and broadside is used, so the result is always finite; callers that can have
    zero axes should hold the last valid orientation instead. The inputs are not modified."""
    cos2 = np.array(dot, dtype=np.float64)  # a copy: written below
    cos2 *= cos2
    n2 = np.asarray(np.multiply(axis_norm2, los_norm2, dtype=np.float64))
    np.divide(cos2, n2, out=cos2, where=n2 > 0)
    cos2[~(n2 > 0)] = 0.0
    np.clip(cos2, 0.0, 1.0, out=cos2)
    a2 = np.asarray(a, dtype=np.float64) ** 2
    c2 = np.asarray(c, dtype=np.float64) ** 2
    h2 = np.asarray(cos2 * (c2 - a2), dtype=np.float64)  # a^2 sin^2 + c^2 cos^2, less a^2
    h2 += a2
    h2 *= h2
    return np.asarray(np.divide(np.pi * a2 * a2 * c2, h2, out=h2), dtype=np.float64)


def _dot(x: FloatArray, y: FloatArray) -> FloatArray:
    """Dot product over the last axis of length 3 (faster than einsum for small last axes)."""
    return np.asarray(x[..., 0] * y[..., 0] + x[..., 1] * y[..., 1] + x[..., 2] * y[..., 2])


def spheroid_specular_from_products(
    a: ArrayLike,
    c: ArrayLike,
    dot: FloatArray,
    axis_norm2: FloatArray,
    los_norm2: FloatArray,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Geometric-optics specular point of a spheroid (``a = b``, semi-axis ``c`` along its
    symmetry axis ``A``) for a far radar seen along ``B`` (part -> radar), from the same
    products as :func:`spheroid_rcs_from_products` (arrays of one shape, any layout).

    With ``u = B/|B|`` and ``z = A/|A|`` the support function is
    ``h = sqrt(a^2 + (c^2 - a^2)(z.u)^2)`` [m], the distance from the centre to the tangent plane
    facing the radar, and the surface point whose outward normal is ``u`` lies at
    ``centre + (a^2 u + (c^2 - a^2)(z.u) z) / h`` (``R diag(a^2, a^2, c^2) R^T u / h``), a
    distance ``h`` nearer the radar along ``u``: its echo has the phase ``exp(+j 2 k h)``
    relative to the centre's. Returns ``(h, alpha, beta)``, each of the inputs' shape, such that
    the offset from the centre is ``alpha B + beta A`` (no normalised vectors needed). A zero
    axis is taken as broadside, as in :func:`spheroid_rcs_from_products` (offset ``a u``); a
    zero line of sight gives a zero offset."""
    dot = np.asarray(dot, dtype=np.float64)
    axis_norm2 = np.asarray(axis_norm2, dtype=np.float64)
    n2 = np.multiply(axis_norm2, los_norm2, dtype=np.float64)
    good = n2 > 0
    h = np.asarray(dot * dot)  # cos^2, then h, in one buffer
    np.divide(h, n2, out=h, where=good)
    if not np.all(good):
        h[~good] = 0.0
    np.minimum(h, 1.0, out=h)
    a2 = np.asarray(a, dtype=np.float64) ** 2
    d2 = np.asarray(c, dtype=np.float64) ** 2 - a2
    h *= d2
    h += a2
    np.sqrt(h, out=h)
    inv = np.asarray(np.sqrt(los_norm2, dtype=np.float64))  # 1 / (h |B|)
    inv *= h
    ok = inv > 0
    np.divide(1.0, inv, out=inv, where=ok)
    if not np.all(ok):
        inv[~ok] = 0.0
    alpha = a2 * inv
    # (c^2 - a^2)(z.u) z / h = (c^2 - a^2) (A.B) A / (|A|^2 |B| h)
    beta = np.asarray(d2 * dot)
    beta *= inv
    has_axis = axis_norm2 > 0
    np.divide(beta, axis_norm2, out=beta, where=has_axis)
    if not np.all(has_axis):
        beta[~has_axis] = 0.0
    return h, alpha, beta


def spheroid_specular_point(
    a: ArrayLike, c: ArrayLike, axis: FloatArray, line_of_sight: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Specular point of a spheroid (see :func:`spheroid_specular_from_products`) with the
    vectors' coordinates last: ``axis`` and ``line_of_sight`` (..., 3) (part -> radar; neither
    needs unit length). Returns the offset from the centre (..., 3) [m] and the support
    function ``h`` (...) [m]."""
    axis = np.asarray(axis, dtype=np.float64)
    los = np.asarray(line_of_sight, dtype=np.float64)
    h, alpha, beta = spheroid_specular_from_products(
        a, c, _dot(axis, los), _dot(axis, axis), _dot(los, los)
    )
    return alpha[..., None] * los + beta[..., None] * axis, h
