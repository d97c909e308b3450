"""Cycloid disc and involute stage bindings against independent NumPy references.

Tolerances are stated where used, with the reason.
"""

from __future__ import annotations

import copy
import math
import pickle

import numpy as np
import pytest

import rvdyn
from conftest import E, FACE, K1, RP, RRP, ZC, ZP, pin_centre, rotate


def test_properties_of_the_paper_disc(paper_disc):
    g = paper_disc
    assert (g.pins, g.lobes) == (24, 23)
    assert (g.eccentricity, g.pin_circle_radius, g.pin_radius, g.face_width) == (E, RP, RRP, FACE)
    assert (g.d_rp, g.d_rrp, g.d_delta) == (0.0, 0.0, 0.0)
    # K1 = 4.5 * 24 / 150 = 0.72 and rc' = 4.5 * 23 = 103.5 mm; exact up to round-off.
    assert g.k1 == pytest.approx(0.72, abs=1e-15)
    assert g.pitch_radius == pytest.approx(0.1035, abs=1e-15)
    # docs/validation.md: rho_min(convex) = 20.75 mm (given to 0.01 mm).
    assert g.min_convex_radius == pytest.approx(20.75e-3, abs=0.01e-3)
    assert "pins=24" in repr(g) and "eccentricity=0.0045" in repr(g)


def test_min_convex_radius_against_dense_sampling(paper_disc):
    # The curvature radius of the pin-centre curve is rho_P + rrp. A 200k-point sampling of
    # one lobe resolves its minimum to ~1e-9 relative (quadratic minimum, step 1.4e-6 rad).
    phi = np.linspace(0.0, 2.0 * math.pi / ZC, 200_001)
    rho_c = paper_disc.curvature_radius(phi) + RRP
    convex = rho_c[rho_c > 0]
    assert paper_disc.min_convex_radius == pytest.approx(convex.min(), rel=1e-8)


def test_root_radius_with_and_without_modifications():
    for d_rp, d_rrp in [(0.0, 0.0), (-2e-5, 2e-5), (3e-5, -1e-5)]:
        g = rvdyn.CycloidGeometry(ZP, E, RP, RRP, FACE, d_rp=d_rp, d_rrp=d_rrp)
        root = g.profile(0.0)
        # Root on +x at rp + d_rp - e - rrp - d_rrp; only round-off of 0.1 m values (~1e-17).
        assert root.shape == (2,)
        assert root[0] == pytest.approx(RP + d_rp - E - RRP - d_rrp, abs=1e-15)
        assert abs(root[1]) < 1e-15
        # Lobe tip at zc phi = pi: radius rp + d_rp + e - rrp - d_rrp.
        tip = g.profile(math.pi / ZC)
        assert np.hypot(*tip) == pytest.approx(RP + d_rp + E - RRP - d_rrp, abs=1e-14)


def test_profile_matches_the_closed_form(paper_disc):
    # docs/validation.md: x = (rp - rrp/S) cos phi - (e - K1 rrp/S) cos(zp phi), same for y.
    phi = np.linspace(-3.0, 9.0, 5001)
    s = np.sqrt(1.0 + K1**2 - 2.0 * K1 * np.cos(ZC * phi))
    x = (RP - RRP / s) * np.cos(phi) - (E - K1 * RRP / s) * np.cos(ZP * phi)
    y = (RP - RRP / s) * np.sin(phi) - (E - K1 * RRP / s) * np.sin(ZP * phi)
    p = paper_disc.profile(phi)
    assert p.shape == (5001, 2)
    # Two formulas for the same 0.15 m quantity: agreement to a few ulp (1e-15 m).
    np.testing.assert_allclose(p[:, 0], x, rtol=0, atol=1e-15)
    np.testing.assert_allclose(p[:, 1], y, rtol=0, atol=1e-15)


def test_normals_are_unit_outward_and_orthogonal(paper_disc):
    phi = np.linspace(0.0, 2.0 * math.pi, 997)
    n = paper_disc.normal(phi)
    np.testing.assert_allclose(np.hypot(n[:, 0], n[:, 1]), 1.0, atol=1e-14)
    # Central-difference tangent, h = 1e-6 rad: truncation ~h^2, so the cosine with the
    # normal is below 1e-6 (relative to the tangent length).
    h = 1e-6
    t = paper_disc.profile(phi + h) - paper_disc.profile(phi - h)
    cos = np.abs(np.sum(t * n, axis=1)) / np.hypot(t[:, 0], t[:, 1])
    assert cos.max() < 1e-6
    # Outward: the normal at a root points away from the centre.
    assert paper_disc.normal(0.0)[0] > 0.99


def test_curvature_radius_root_value_and_finite_differences(paper_disc):
    # docs/validation.md: -10.72 mm at the root (concave, nearly conformal with the 10 mm pin).
    # The note gives 2 decimals in mm, so +-0.005 mm.
    assert paper_disc.curvature_radius(0.0) == pytest.approx(-10.72e-3, abs=0.005e-3)
    assert isinstance(paper_disc.curvature_radius(0.0), float)
    # Independent check: signed curvature of the sampled profile from fourth-order central
    # differences. Near the root the pin-centre curve turns on a 0.72 mm radius, so the
    # truncation error is large: measured 1.6e-4 at h = 1e-3 rad and 1.3e-6 at 3e-4 (4th
    # order), round-off 2e-7 at 1e-4. h = 1.5e-4 rad sits between: ~3e-7; tolerance 1e-6.
    phi = np.linspace(0.01, 2.0 * math.pi / ZC - 0.01, 301)
    h = 1.5e-4
    p = {k: paper_disc.profile(phi + k * h) for k in (-2, -1, 0, 1, 2)}
    d1 = (-p[2] + 8 * p[1] - 8 * p[-1] + p[-2]) / (12 * h)
    d2 = (-p[2] + 16 * p[1] - 30 * p[0] + 16 * p[-1] - p[-2]) / (12 * h**2)
    kappa = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.hypot(d1[:, 0], d1[:, 1]) ** 3
    rho = paper_disc.curvature_radius(phi)
    np.testing.assert_allclose(1.0 / kappa, rho, rtol=1e-6)
    # Convex on the lobe tip, concave at the root.
    assert paper_disc.curvature_radius(math.pi / ZC) > 0


def test_array_shapes(paper_disc):
    assert paper_disc.profile(0.3).shape == (2,)
    assert paper_disc.profile([0.1, 0.2, 0.3]).shape == (3, 2)
    assert paper_disc.profile(np.zeros((4, 5))).shape == (4, 5, 2)
    assert paper_disc.normal(np.zeros(0)).shape == (0, 2)
    assert paper_disc.curvature_radius(np.zeros((2, 3))).shape == (2, 3)
    # Integer input is converted; non-contiguous views are read in logical order.
    phi = np.linspace(0, 1, 20)[::3]
    np.testing.assert_array_equal(paper_disc.profile(phi), paper_disc.profile(phi.copy()))
    np.testing.assert_array_equal(paper_disc.profile([0, 1]), paper_disc.profile([0.0, 1.0]))


def test_pin_positions_are_numbered_as_in_the_paper(paper_disc):
    pins = paper_disc.pin_positions()
    assert pins.shape == (24, 2)
    np.testing.assert_allclose(np.hypot(pins[:, 0], pins[:, 1]), RP, rtol=1e-15)
    # Pin 1 on +x, pin 7 (index 6) at 90 deg, counter-clockwise.
    np.testing.assert_allclose(pins[0], [RP, 0.0], atol=1e-16)
    np.testing.assert_allclose(pins[6], [0.0, RP], atol=1e-16)
    for j in range(24):
        np.testing.assert_allclose(pins[j], pin_centre(j), atol=1e-16)


def test_kinematic_pose(paper_disc):
    centre, angle = paper_disc.kinematic_pose(0.7)
    np.testing.assert_allclose(centre, [E * math.cos(0.7), E * math.sin(0.7)], rtol=1e-15)
    assert angle == pytest.approx(-0.7 / ZC, rel=1e-15)


@pytest.mark.parametrize("psi", [-7.0, -1.3, 0.0, 0.05, 0.4, 2.0, 3.14159, 11.0, 100.0])
def test_every_pin_touches_the_unmodified_disc_at_kinematic_poses(paper_disc, psi):
    # The unmodified disc is conjugate to the pins: every gap is zero. The exact Newton stops at
    # 1e-13 m tangential; the gap of 0.15 m coordinates is accurate to ~1e-15 m; 1e-12 m allows
    # for the round-off of large psi.
    centre, angle = paper_disc.kinematic_pose(psi)
    gaps = [paper_disc.gap(p, centre, angle).gap for p in paper_disc.pin_positions()]
    assert max(abs(g) for g in gaps) < 1e-12


def brute_force_gap(g, pin, centre, angle):
    """Signed gap from a dense sampling of the profile, refined twice locally (NumPy only)."""
    def dist(phi):
        pts = rotate(g.profile(phi), angle) + centre
        return np.hypot(pts[:, 0] - pin[0], pts[:, 1] - pin[1])

    phi = np.linspace(0.0, 2.0 * math.pi, 2**18, endpoint=False)
    i = int(np.argmin(dist(phi)))
    best, h = phi[i], phi[1] - phi[0]
    for _ in range(3):  # each level shrinks the step 1000x: 2.4e-5 -> 2.4e-14 rad
        local = np.linspace(best - 2 * h, best + 2 * h, 4001)
        best = local[int(np.argmin(dist(local)))]
        h = local[1] - local[0]
    d = dist(np.array([best]))[0]
    q = rotate(g.profile(best), angle) + centre
    n = rotate(g.normal(best), angle)
    side = np.sign(np.dot(pin - q, n))
    return side * d - g.pin_radius, best


def test_gap_against_numpy_brute_force_on_perturbed_poses():
    g = rvdyn.CycloidGeometry(ZP, E, RP, RRP, FACE, d_rp=-2e-5, d_rrp=2e-5, d_delta=1e-4)
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(12):
        psi = rng.uniform(-10, 10)
        centre, angle = g.kinematic_pose(psi)
        centre = centre + rng.uniform(-1e-4, 1e-4, 2)
        angle += rng.uniform(-1e-3, 1e-3)
        pin = pin_centre(int(rng.integers(0, ZP)))
        exact = g.gap(pin, centre, angle)
        brute, _ = brute_force_gap(g, pin, centre, angle)
        worst = max(worst, abs(exact.gap - brute))
        # The pin centre lies on the normal through the contact point at gap + rrp.
        back = exact.point + (exact.gap + RRP) * exact.normal
        np.testing.assert_allclose(back, pin, rtol=0, atol=1e-12)
        assert exact.point.shape == (2,) and exact.normal.shape == (2,)
        assert 0.0 <= exact.phi < 2 * math.pi
        assert exact.curvature_radius == pytest.approx(g.curvature_radius(exact.phi), rel=1e-12)
    # The sampled minimum is accurate to ~1e-13 m; distances of 0.15 m carry ~3e-17 m
    # round-off each. 1e-11 m leaves a margin of 100x.
    assert worst < 1e-11, worst


def test_gap_with_another_pin_radius(paper_disc):
    centre, angle = paper_disc.kinematic_pose(0.3)
    pin = pin_centre(3)
    base = paper_disc.gap(pin, centre, angle)
    smaller = paper_disc.gap(pin, centre, angle, pin_radius=RRP - 5e-6)
    # The same foot point; the gap grows by exactly the radius difference (round-off 1e-17 m).
    assert smaller.gap - base.gap == pytest.approx(5e-6, abs=1e-15)
    np.testing.assert_array_equal(smaller.point, base.point)
    assert isinstance(base, rvdyn.GapResult)
    gap, point, normal, phi, rho = base  # a named tuple unpacks
    assert gap == base.gap and rho == base.curvature_radius


@pytest.mark.parametrize("d_rp", [-5e-4, -8e-4, -1e-3, -2e-3])
def test_gap_of_pins_beyond_the_root_centre_of_curvature(d_rp):
    # A shift modification of -0.8 mm leaves the pins at the roots 0.8 mm outside the pin-centre
    # curve, beyond its 0.72 mm concave radius of curvature: the distance has two local minima
    # on either side of the root. The gap is the smaller (against the NumPy brute force, 1e-11 m
    # as above), and a run starts (both raised an error before).
    g = rvdyn.CycloidGeometry(ZP, E, RP, RRP, FACE, d_rp=d_rp)
    for psi, j in [(0.0, 0), (0.3, 0), (1.0, 5)]:
        centre, angle = g.kinematic_pose(psi)
        exact = g.gap(pin_centre(j), centre, angle)
        brute, _ = brute_force_gap(g, pin_centre(j), centre, angle)
        assert abs(exact.gap - brute) < 1e-11, (exact.gap, brute)
        assert exact.gap > 0.0
    r = rvdyn.simulate(rvdyn.Scene.paper("idle", **{"cycloid.d_rp": d_rp}), 2e-3)
    assert np.all(np.isfinite(r.pin_force))


def test_modifications_open_the_first_order_clearance():
    # docs/validation.md: g0(phi) = d_rrp - d_rp (1 - K1 cos phi)/S at the kinematic pose,
    # phi the pin angle from the eccentricity direction. The exact gap differs at second order:
    # ~3e-5 mm for 0.02 mm modifications, so 1e-7 m is a tolerance with a 3x margin, and the
    # difference must be visible (> 1e-10 m), or the test would not see the second order.
    d_rp, d_rrp = -2e-5, 2e-5
    g = rvdyn.CycloidGeometry(ZP, E, RP, RRP, FACE, d_rp=d_rp, d_rrp=d_rrp)
    for psi in (0.0, 0.4, 2.5):
        centre, angle = g.kinematic_pose(psi)
        diffs = []
        for j in range(ZP):
            th = 2 * math.pi * j / ZP
            phi = th - psi
            s = math.sqrt(1 + K1**2 - 2 * K1 * math.cos(phi))
            first_order = d_rrp - d_rp * (1 - K1 * math.cos(phi)) / s
            gap = g.gap(pin_centre(j), centre, angle).gap
            assert gap > 0
            diffs.append(abs(gap - first_order))
        assert max(diffs) < 1e-7
        assert max(diffs) > 1e-10


def test_rotation_modification_turns_the_profile():
    g0 = rvdyn.CycloidGeometry.paper()
    g = rvdyn.CycloidGeometry(ZP, E, RP, RRP, FACE, d_delta=1e-3)
    phi = np.linspace(0, 1, 11)
    np.testing.assert_allclose(g.profile(phi), rotate(g0.profile(phi), 1e-3), atol=1e-16)


def test_mass_properties_against_a_polygon(paper_disc):
    # Shoelace area and polar moment of a 460,000-gon of the exact profile (inscribed polygon:
    # error O(h^2), measured 2.4e-9 relative; 2.4e-7 with 46,000 sides) minus the holes of DiscHoles::paper(): bore r 40 mm, 3 crank holes r 25 mm,
    # 3 pillar holes r 20 mm on a 90 mm circle. Steel 7850 kg/m^3, face 40 mm.
    phi = np.linspace(0.0, 2 * math.pi, 460_001)
    p = paper_disc.profile(phi)
    x0, y0, x1, y1 = p[:-1, 0], p[:-1, 1], p[1:, 0], p[1:, 1]
    cross = x0 * y1 - x1 * y0
    area = 0.5 * cross.sum()
    polar = (cross * (x0**2 + x0 * x1 + x1**2 + y0**2 + y0 * y1 + y1**2)).sum() / 12.0

    def hole(r, d):
        return math.pi * r**2, math.pi * r**4 / 2 + math.pi * r**2 * d**2

    for r, d, n in [(0.040, 0.0, 1), (0.025, 0.090, 3), (0.020, 0.090, 3)]:
        a, j = hole(r, d)
        area -= n * a
        polar -= n * j
    mass, inertia = paper_disc.mass_properties()
    assert mass == pytest.approx(area * FACE * 7850.0, rel=1e-8)
    assert inertia == pytest.approx(polar * FACE * 7850.0, rel=1e-8)
    # Plausibility: a solid disc of radius rp - rrp less the same holes gives 14.72 kg and
    # 0.1628 kg m^2 (a hand estimate, given to 3 digits): within 2 %.
    assert mass == pytest.approx(14.7, rel=0.02)
    assert inertia == pytest.approx(0.163, rel=0.02)
    # The default density is steel, 7850 kg/m^3, as the signature says.
    assert paper_disc.mass_properties(7850.0) == (mass, inertia)
    m2, j2 = paper_disc.mass_properties(density=2 * 7850.0)
    assert (m2, j2) == pytest.approx((2 * mass, 2 * inertia), rel=1e-14)


def test_pickle_and_copy(paper_disc):
    g = rvdyn.CycloidGeometry(ZP, E, RP, RRP, FACE, d_rp=-1e-5, d_rrp=1e-5, d_delta=1e-4)
    for h in (pickle.loads(pickle.dumps(g)), copy.deepcopy(g)):
        assert repr(h) == repr(g)
        np.testing.assert_array_equal(h.profile([0.1, 0.2]), g.profile([0.1, 0.2]))


@pytest.mark.parametrize(
    "kwargs, rule",
    [
        (dict(pins=2), "at least 3 pins"),
        (dict(eccentricity=7e-3), "curtate ratio K1"),  # K1 = 1.12
        (dict(pin_radius=0.0196), "pins overlap"),  # rp sin(pi/24) = 19.58 mm
        (dict(pin_radius=0.019, d_rrp=0.002), "undercut"),  # 21 mm > rho_min 20.75 mm
    ],
)
def test_invalid_geometry_names_the_rule(kwargs, rule):
    args = dict(pins=ZP, eccentricity=E, pin_circle_radius=RP, pin_radius=RRP, face_width=FACE)
    args.update(kwargs)
    with pytest.raises(rvdyn.GeometryError, match=rule) as info:
        rvdyn.CycloidGeometry(**args)
    assert isinstance(info.value, ValueError)


# ---- involute stage -------------------------------------------------------------------------


def test_involute_stage_paper_values():
    s = rvdyn.InvoluteStage.paper()
    assert (s.z_sun, s.z_planet, s.planets) == (18, 42, 3)
    assert s.module == 3e-3 and s.face_width == 0.030 and s.backlash == 0.0
    assert s.pressure_angle == pytest.approx(math.radians(20), rel=1e-15)
    # r1 = 27 mm, r2 = 63 mm, a = 90 mm (= crank circle radius), addendum = module.
    assert s.sun_pitch_radius == pytest.approx(0.027, rel=1e-15)
    assert s.planet_pitch_radius == pytest.approx(0.063, rel=1e-15)
    assert s.centre_distance == pytest.approx(0.090, rel=1e-15)
    assert s.addendum == pytest.approx(3e-3, rel=1e-15)
    assert s.sun_tip_radius == pytest.approx(0.030, rel=1e-15)
    assert s.planet_tip_radius == pytest.approx(0.066, rel=1e-15)
    cos_a = math.cos(math.radians(20))
    assert s.sun_base_radius == pytest.approx(0.027 * cos_a, rel=1e-15)
    assert s.planet_base_radius == pytest.approx(0.063 * cos_a, rel=1e-15)
    # Textbook contact ratio (no interference for 18/42 at 20 deg, so the caps are inactive):
    # [sqrt(ra1^2 - rb1^2) + sqrt(ra2^2 - rb2^2) - a sin(alpha)] / (pi m cos(alpha)) = 1.63.
    path = (
        math.sqrt(0.030**2 - (0.027 * cos_a) ** 2)
        + math.sqrt(0.066**2 - (0.063 * cos_a) ** 2)
        - 0.090 * math.sin(math.radians(20))
    )
    assert s.line_of_action_length == pytest.approx(path, rel=1e-12)
    assert s.contact_ratio == pytest.approx(path / (math.pi * 3e-3 * cos_a), rel=1e-12)
    assert s.contact_ratio == pytest.approx(1.63, abs=0.005)
    assert s.stage_ratio == pytest.approx(-42 / 18, rel=1e-15)
    np.testing.assert_allclose(s.planet_angles, [0, 2 * math.pi / 3, 4 * math.pi / 3], rtol=1e-15)
    assert "z_sun=18" in repr(s)
    assert repr(pickle.loads(pickle.dumps(s))) == repr(s)


def test_involute_stage_backlash_and_errors():
    s = rvdyn.InvoluteStage(18, 42, 3, 3e-3, math.radians(20), 0.03, backlash=1e-4)
    assert s.backlash == 1e-4
    with pytest.raises(rvdyn.GeometryError, match="at least 5"):
        rvdyn.InvoluteStage(4, 42, 3, 3e-3, math.radians(20), 0.03)
    with pytest.raises(rvdyn.GeometryError, match="planets collide"):
        rvdyn.InvoluteStage(18, 42, 6, 3e-3, math.radians(20), 0.03)
    with pytest.raises(rvdyn.ParameterError, match="pressure angle"):
        rvdyn.InvoluteStage(18, 42, 3, 3e-3, math.radians(50), 0.03)
    with pytest.raises(rvdyn.ParameterError, match="backlash"):
        rvdyn.InvoluteStage(18, 42, 3, 3e-3, math.radians(20), 0.03, backlash=-1e-5)


def test_plot_geometry_draws_discs_and_numbered_pins(paper_disc):
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, Polygon

    from rvdyn.plotting import new_figure, plot_geometry

    fig = plot_geometry(paper_disc, psi=0.3)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    assert sum(isinstance(p, Circle) for p in ax.patches) == 24
    polygons = [p for p in ax.patches if isinstance(p, Polygon)]
    assert len(polygons) == 2
    # The drawn outline of the front disc is the profile placed at the kinematic pose [mm].
    centre, angle = paper_disc.kinematic_pose(0.3)
    xy = polygons[0].get_xy() / 1e3
    np.testing.assert_allclose(xy[0], rotate(paper_disc.profile(0.0), angle) + centre, atol=1e-12)
    assert [t.get_text() for t in ax.texts] == [str(j) for j in range(1, 25)]
    # Drawing into a given Axes returns its figure; one disc only.
    fig2, ax2 = new_figure()
    assert plot_geometry(paper_disc, disc="rear", ax=ax2, number_pins=False) is fig2
    assert sum(isinstance(p, Polygon) for p in ax2.patches) == 1 and not ax2.texts


def test_the_interference_remedy_works_for_the_pair() -> None:
    # The suggested tooth count cleared only the named gear's tip: (5, 5) at 20 deg suggested
    # 11 sun teeth, and (11, 5) then interfered the other way (an outside fuzz run). Now each
    # suggested count makes a valid pair, with the other gear as it is.
    import re

    for deg in (10, 20, 25):
        for z1 in range(5, 40, 3):
            for z2 in range(5, 60, 4):
                try:
                    rvdyn.InvoluteStage(z1, z2, 1, 3e-3, math.radians(deg), 0.03)
                except rvdyn.GeometryError as err:
                    m = re.search(r"at least (\d+) (sun|planet) teeth", str(err))
                    if "interference" not in str(err) or m is None:
                        continue
                    z = int(m.group(1))
                    zs, zp = (z, z2) if m.group(2) == "sun" else (z1, z)
                    rvdyn.InvoluteStage(zs, zp, 1, 3e-3, math.radians(deg), 0.03)
    with pytest.raises(rvdyn.GeometryError, match="use more teeth or a larger pressure angle"):
        rvdyn.InvoluteStage(5, 5, 1, 3e-3, math.radians(20), 0.03)
