"""RCS models and body scatterers (physics.md section 2)."""

from __future__ import annotations

import numpy as np
import pytest
import synthetic

from mdframework.physics import body, rcs
from mdframework.skeleton import CANONICAL_JOINTS

LAMBDA_15GHZ = 0.019986163867


def test_sphere_optical() -> None:
    assert float(rcs.sphere_rcs_optical(0.1)) == pytest.approx(0.0314159265, rel=1e-8)


@pytest.mark.parametrize(
    ("ka", "ratio"), [(0.1, 0.000898), (1.0, 3.6376), (10.0, 0.9292), (100.0, 0.99903)]
)
def test_sphere_mie_reference_values(ka: float, ratio: float) -> None:
    radius = 1.0
    lam = 2 * np.pi * radius / ka
    assert rcs.sphere_rcs_mie(radius, lam) / (np.pi * radius**2) == pytest.approx(ratio, rel=2e-3)


def test_sphere_mie_rayleigh_limit_and_head() -> None:
    ka = 0.05
    lam = 2 * np.pi / ka
    assert rcs.sphere_rcs_mie(1.0, lam) / np.pi == pytest.approx(9 * ka**4, rel=0.01)
    assert rcs.sphere_rcs_mie(0.1, LAMBDA_15GHZ) == pytest.approx(0.032015, rel=1e-3)


def test_ellipsoid_equal_axes_is_a_sphere(rng: np.random.Generator) -> None:
    th = rng.uniform(0, np.pi, 100_000)
    ph = rng.uniform(-np.pi, np.pi, 100_000)
    s = rcs.ellipsoid_rcs_angles(0.3, 0.3, 0.3, th, ph)
    assert np.ptp(s) < 1e-15
    assert s[0] == pytest.approx(np.pi * 0.09, rel=1e-14)


def test_ellipsoid_broadside_and_end_on() -> None:
    assert float(rcs.ellipsoid_rcs_angles(0.06, 0.06, 0.2, 0.0, 0.0)) == pytest.approx(
        1.017876e-3, rel=1e-6
    )
    assert float(rcs.ellipsoid_rcs_angles(0.06, 0.06, 0.2, np.pi / 2, 0.0)) == pytest.approx(
        0.1256637, rel=1e-6
    )
    a, b, c = 0.05, 0.08, 0.2
    assert float(rcs.ellipsoid_rcs_angles(a, b, c, np.pi / 2, 0.0)) == pytest.approx(
        np.pi * b**2 * c**2 / a**2, rel=1e-12
    )
    # sigma(theta) = sigma(pi - theta)
    th = np.linspace(0, np.pi, 7)
    assert np.allclose(
        rcs.ellipsoid_rcs_angles(a, b, c, th, 0.3),
        rcs.ellipsoid_rcs_angles(a, b, c, np.pi - th, 0.3),
        rtol=1e-12,
    )


def test_ellipsoid_denominator_never_below_min_axis(rng: np.random.Generator) -> None:
    a, b, c = 0.05, 0.08, 0.2
    u = rng.normal(size=(200_000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    s = rcs.ellipsoid_rcs_local(a, b, c, u)
    denominator = np.sqrt(np.pi * a**2 * b**2 * c**2 / s)
    assert denominator.min() >= min(a, b, c) ** 2 * (1 - 1e-12)
    assert np.all(np.isfinite(s))
    assert s.max() <= np.pi * (b * c / a) ** 2 * (1 + 1e-12)


def test_spheroid_from_vectors_matches_angle_form(rng: np.random.Generator) -> None:
    axis = rng.normal(size=(1000, 3))
    los = rng.normal(size=(1000, 3)) * 5
    cos_t = (
        np.einsum("ij,ij->i", axis, los)
        / np.linalg.norm(axis, axis=1)
        / np.linalg.norm(los, axis=1)
    )
    theta = np.arccos(np.clip(cos_t, -1, 1))
    expected = rcs.ellipsoid_rcs_angles(0.07, 0.07, 0.22, theta, 0.0)
    assert np.allclose(rcs.spheroid_rcs(0.07, 0.22, axis, los), expected, rtol=1e-10)


def test_spheroid_zero_vectors_are_finite() -> None:
    s = rcs.spheroid_rcs(0.07, 0.22, np.zeros((2, 3)), np.array([[1.0, 0, 0], [0, 0, 0]]))
    assert np.all(np.isfinite(s))


def test_spheroid_end_on_from_overhead() -> None:
    """A vertical segment seen from straight above is the legitimate end-on value."""
    s = rcs.spheroid_rcs(0.06, 0.2, np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 5.0]))
    assert float(s) == pytest.approx(1.017876e-3, rel=1e-6)


def test_segment_table_for_1_8_m() -> None:
    h = 1.8
    assert body.SEGMENT_FRACTIONS["torso"] * h == pytest.approx(0.5184)
    assert body.SEGMENT_FRACTIONS["foot"] * h == pytest.approx(0.2574)
    assert body.LEG_FRACTION * h == pytest.approx(0.8838)


@pytest.mark.parametrize("placement", ["chen16", "joints17"])
def test_placements_count_and_rcs_table(placement: str) -> None:
    parts = body.body_parts(placement, "sphere")  # type: ignore[arg-type]
    assert len(parts) == (16 if placement == "chen16" else 17)
    a, c = body.part_semi_axes(parts, 1.8)
    names = [p.name for p in parts]
    # physics.md 2.3 RCS table at H = 1.8: thigh broadside pi c^2 = 0.1528, end-on 0.00155
    thigh = names.index("l_upper_leg" if placement == "chen16" else "l_knee")
    assert np.pi * c[thigh] ** 2 == pytest.approx(0.1528, abs=1e-4)
    assert np.pi * a[thigh] ** 4 / c[thigh] ** 2 == pytest.approx(0.00155, abs=1e-5)
    torso = names.index("torso" if placement == "chen16" else "neck")
    assert np.pi * c[torso] ** 2 == pytest.approx(0.2111, abs=1e-4)


def _standing_body(height: float = 1.8) -> np.ndarray:
    return synthetic.standing(height)[None]


def test_height_estimate_of_a_standing_body() -> None:
    assert body.estimate_height(_standing_body(1.7)) == pytest.approx(1.7, rel=1e-12)


def test_chen16_positions_follow_the_table() -> None:
    joints = _standing_body()
    parts = body.body_parts("chen16")
    pos, axes = body.part_geometry(parts, joints)
    names = [p.name for p in parts]
    j = {n: joints[0, i] for i, n in enumerate(CANONICAL_JOINTS)}
    assert np.allclose(pos[0, names.index("torso")], (j["neck"] + j["base"]) / 2)
    assert np.allclose(pos[0, names.index("r_lower_arm")], j["r_hand"])
    assert np.allclose(pos[0, names.index("l_foot")], j["l_toe"])
    assert np.allclose(axes[0, names.index("l_upper_leg")], j["l_knee"] - j["l_hip"])


@pytest.mark.parametrize("placement", ["chen16", "joints17"])
def test_part_geometry_in_coordinate_planes(placement: str) -> None:
    """Coordinates first ((3, n, 17), joints along the last axis) gives the same positions
    and axes as the (n, 17, 3) layout, transposed, for weighted and identity placements."""
    rng = np.random.default_rng(3)
    joints = _standing_body() + rng.normal(0.0, 0.05, (40, 17, 3))
    parts = body.body_parts(placement)  # type: ignore[arg-type]
    pos, axes = body.part_geometry(parts, joints)
    planes = np.ascontiguousarray(np.moveaxis(joints, -1, 0))
    pos_t, axes_t = body.part_geometry(parts, planes, joint_axis=-1)
    assert pos_t.shape == axes_t.shape == (3, 40, len(parts))
    assert np.allclose(np.moveaxis(pos_t, 0, -1), pos, rtol=0, atol=1e-15)
    assert np.array_equal(np.moveaxis(axes_t, 0, -1), axes)
    # a joint that is not finite (e.g. untracked) reaches only the parts whose axis uses it
    planes[:, 7, CANONICAL_JOINTS.index("l_knee")] = np.nan
    _, axes_nan = body.part_geometry(parts, planes, joint_axis=-1)
    bad = ~np.isfinite(axes_nan)
    uses = [i for i, p in enumerate(parts) if "l_knee" in p.axis]
    assert bad[:, 7, uses].all() and not np.delete(bad, uses, axis=2).any()
    # joints that are not the 17 canonical ones along the given axis: refused, not clipped
    with pytest.raises(ValueError, match="15 along axis 1, not the 17 canonical joints"):
        body.part_geometry(parts, joints[:, :15])
    with pytest.raises(ValueError, match="3 along axis -1"):
        body.part_geometry(parts, joints, joint_axis=-1)


#: physics.md 2.3, Chen's 16 parts: (part, a = b [m], segment length / H, position as
#: (joint, weight) pairs, axis as (tail, tip)); the lower leg with its own length (Q5 fixed).
CHEN16_TABLE = [
    ("head", 0.10, 0.130, {"head": 1.0}, ("neck", "head")),
    ("torso", 0.15, 0.288, {"neck": 0.5, "base": 0.5}, ("base", "neck")),
    ("shoulder", 0.06, 0.1295, {"{s}_shoulder": 1.0}, ("neck", "{s}_shoulder")),
    (
        "upper_arm",
        0.06,
        0.188,
        {"{s}_shoulder": 0.5, "{s}_elbow": 0.5},
        ("{s}_elbow", "{s}_shoulder"),
    ),
    ("lower_arm", 0.05, 0.152, {"{s}_hand": 1.0}, ("{s}_hand", "{s}_elbow")),
    ("hip", 0.07, 0.0955, {"{s}_hip": 1.0}, ("base", "{s}_hip")),
    ("upper_leg", 0.07, 0.245, {"{s}_hip": 0.5, "{s}_knee": 0.5}, ("{s}_hip", "{s}_knee")),
    ("lower_leg", 0.06, 0.246, {"{s}_knee": 0.5, "{s}_ankle": 0.5}, ("{s}_knee", "{s}_ankle")),
    ("foot", 0.05, 0.143, {"{s}_toe": 1.0}, ("{s}_ankle", "{s}_toe")),
]


def test_chen16_every_part_follows_the_table() -> None:
    """Every one of the 16 parts (head as Chen's spheroid) against physics.md 2.3 written out
    here: position (joint or segment midpoint) and axis on random joints, so that no two
    joints coincide, to 1e-15 m (the axis up to its sign, which the RCS and the specular
    point do not see), a = b and c = half the segment length at H = 1.7 m to 1e-15 m."""
    rng = np.random.default_rng(5)
    joints = rng.uniform(-1.0, 1.0, (3, 17, 3))
    parts = body.body_parts("chen16", "spheroid")
    pos, axes = body.part_geometry(parts, joints)
    a, c = body.part_semi_axes(parts, 1.7)
    j = {n: joints[:, i] for i, n in enumerate(CANONICAL_JOINTS)}
    rows = [(name, row) for name, *row in CHEN16_TABLE if name in ("head", "torso")]
    for side in ("l", "r"):
        rows += [(f"{side}_{name}", row) for name, *row in CHEN16_TABLE[2:]]
    assert sorted(p.name for p in parts) == sorted(name for name, _ in rows)
    names = [p.name for p in parts]
    for name, (radius, fraction, where, (tail, tip)) in rows:
        side = name[0]
        i = names.index(name)
        want = sum(w * j[k.format(s=side)] for k, w in where.items())
        np.testing.assert_allclose(pos[:, i], want, rtol=0, atol=1e-15, err_msg=name)
        seg = j[tip.format(s=side)] - j[tail.format(s=side)]
        sign = np.sign(np.sum(axes[:, i] * seg, axis=-1))[:, None]
        np.testing.assert_allclose(sign * axes[:, i], seg, rtol=0, atol=1e-15, err_msg=name)
        assert (a[i], c[i]) == pytest.approx((radius, fraction * 1.7 / 2), abs=1e-15), name


@pytest.mark.parametrize(("kind", "sigma"), [("mie", 0.032015), ("optical", 0.0314159265)])
def test_ellipsoid_model_head_sphere_rcs_at_the_radar_wavelength(kind: str, sigma: float) -> None:
    """The ellipsoid model's spherical head (r = 0.1 m) at the radar's 15 GHz wavelength:
    Mie 0.032015 m^2 (+1.9 % over pi r^2, physics.md 2.1), optical pi r^2, at every pulse and
    whatever the aspect (at twice the wavelength, ka = 15.7, Mie gives 4.5 % more)."""
    from mdf_ellipsoid.model import EllipsoidBody, EllipsoidConfig

    from mdframework.skeleton import Skeleton

    joints = np.repeat(_standing_body(), 3, axis=0)
    skel = Skeleton(np.arange(3) / 2400.0, joints, CANONICAL_JOINTS)
    model = EllipsoidBody(EllipsoidConfig(sphere_rcs=kind, head="sphere", height=1.8))  # type: ignore[arg-type]
    model.start_record(skel)
    scat = model.scatterers(None, skel, np.array([10.0, 3.0, 1.0]), LAMBDA_15GHZ)  # type: ignore[arg-type]
    np.testing.assert_allclose(scat.rcs[:, scat.names.index("head")], sigma, rtol=2e-4)
