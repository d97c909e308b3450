"""Contact bindings: the paper's stiffness (eqs. 5-11, errata corrected), Hertz line contact,
the IMPACT law; hand values, independent NumPy references, vectorisation and broadcasting."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rvdyn

E_STEEL, NU = 2.17e11, 0.3
PER_MM15 = 1000.0**1.5  # N/mm^1.5 -> N/m^1.5


def stiffness_reference(width, r1, r2, condition, exponent=1.5, x=1e-5):
    """Eqs. 5-11 with the errata corrected, in the paper's N-mm units (independent NumPy code).

    1/E* = 2 (1 - nu^2)/E; R = R1 R2/(R1 + R2) or R1 R2/(R2 - R1); k' = 4/3 E* sqrt(R);
    F = k' x^e; b = 1.60 sqrt(F/L 2R/E*); w = 2F/(pi L) C [2/3 + ln(4R1/b) + ln(4R2/b)];
    k = k' sqrt(w), read as N/mm^e and converted to N/m^e.
    """
    c = (1 - NU**2) / (E_STEEL * 1e-6)  # mm^2/N
    e_star = 1.0 / (2 * c)
    r1, r2, length = r1 * 1e3, r2 * 1e3, np.asarray(width) * 1e3
    r = r1 * r2 / (r1 + r2) if condition == "convex-convex" else r1 * r2 / (r2 - r1)
    kp = 4.0 / 3.0 * e_star * math.sqrt(r)
    force = kp * (x * 1e3) ** exponent
    b = 1.60 * np.sqrt(force / length * 2 * r / e_star)
    w = 2 * force / (math.pi * length) * c * (2.0 / 3.0 + np.log(4 * r1 / b) + np.log(4 * r2 / b))
    return kp * np.sqrt(w) * 1000.0**exponent


def test_stiffness_hand_value_at_5_mm():
    # Hand computation (N, mm): C = 0.91/2.17e5 = 4.193548e-6 mm^2/N, E* = 119230.77 N/mm^2,
    # R = 10 * 103.5 / 113.5 = 9.118943 mm, k' = 4/3 E* sqrt(R) = 480064.2 N/mm^1.5,
    # F = k' 0.01^1.5 = 480.0642 N, b = 1.60 sqrt(96.01284 * 18.237885 * 8.387097e-6)
    # = 0.1939000 mm, w = 2 F/(5 pi) C (2/3 + ln(40/b) + ln(414/b)) = 3.501974e-3 mm,
    # k = k' sqrt(w) = 28408.99 N/mm^1.5. Seven digits carried: rel 1e-6.
    k = rvdyn.contact_stiffness(0.005, 0.010, 0.1035, "convex-convex")
    assert isinstance(k, float)
    assert k == pytest.approx(28408.99 * PER_MM15, rel=1e-6)


@pytest.mark.parametrize("condition", ["convex-convex", "convex-concave"])
def test_stiffness_matches_the_numpy_reference(condition):
    widths = np.geomspace(1e-4, 0.05, 50)
    k = rvdyn.contact_stiffness(widths, 0.010, 0.1035, condition)
    # Same formulas, different code and operation order: round-off only (1e-12).
    np.testing.assert_allclose(k, stiffness_reference(widths, 0.010, 0.1035, condition),
                               rtol=1e-12)
    # Errata corrected, the stiffness decreases with width (no maximum near 5 mm).
    assert np.all(np.diff(k) < 0)


def test_stiffness_parameters_are_passed_through():
    k = rvdyn.contact_stiffness(0.005, 0.01, 0.1035, exponent=1.0, penetration=2e-5,
                                youngs_modulus=E_STEEL, poisson_ratio=NU)
    ref = stiffness_reference(0.005, 0.01, 0.1035, "convex-convex", exponent=1.0, x=2e-5)
    assert k == pytest.approx(float(ref), rel=1e-12)
    k_soft = rvdyn.contact_stiffness(0.005, 0.01, 0.1035, youngs_modulus=1e11)
    assert k_soft < rvdyn.contact_stiffness(0.005, 0.01, 0.1035)
    # Condition names: case and "_" accepted.
    assert rvdyn.contact_stiffness(0.005, 0.01, 0.1035, "Convex_Concave") == \
        rvdyn.contact_stiffness(0.005, 0.01, 0.1035, "convex-concave")


def test_stiffness_maximum():
    # No interior maximum over physical widths: a clear ParameterError.
    with pytest.raises(rvdyn.ParameterError, match="no interior maximum"):
        rvdyn.stiffness_maximum(0.010, 0.1035, "convex-convex")
    # The formal maximum is in closed form (equal materials): L* = e^(1/3) 2.56 F K_D C_E /
    # (16 R1 R2) and k_max = k' sqrt(2 F C / (pi L*)) in mm units. Golden section to 1e-10
    # in ln(width): width rel 1e-6 (flat maximum), value rel 1e-9.
    for cond in ("convex-convex", "convex-concave"):
        c = 0.91 / 2.17e5
        r = 10 * 103.5 / (113.5 if cond == "convex-convex" else 93.5)
        kp = 4 / 3 / (2 * c) * math.sqrt(r)
        f = kp * 0.01**1.5
        l_star = math.exp(1 / 3) * 2.56 * f * 2 * r * 2 * c / (16 * 10 * 103.5)
        k_max = kp * math.sqrt(2 * f * c / (math.pi * l_star)) * PER_MM15
        w, k = rvdyn.stiffness_maximum(0.010, 0.1035, cond, lo=1e-8, hi=1e-6)
        assert w == pytest.approx(l_star * 1e-3, rel=1e-6)
        assert k == pytest.approx(k_max, rel=1e-9)


def test_stiffness_broadcasting_and_shapes():
    w = np.array([1e-3, 5e-3, 2e-2])
    r2 = np.array([[0.05], [0.1035]])
    k = rvdyn.contact_stiffness(w, 0.01, r2)
    assert k.shape == (2, 3) and k.dtype == np.float64
    for i in range(2):
        for j in range(3):
            assert k[i, j] == rvdyn.contact_stiffness(w[j], 0.01, r2[i, 0])
    assert rvdyn.contact_stiffness([5e-3], 0.01, 0.1035).shape == (1,)
    assert rvdyn.contact_stiffness(np.zeros((0,)) + 5e-3, 0.01, 0.1035).shape == (0,)


# ---- Hertz line contact ----------------------------------------------------------------------


def test_hertz_hand_values():
    # docs/model.md#contact-laws: F = 35 kN over 40 mm, R_pin 10 mm, R_disc 94 mm:
    # R = 9.0385 mm, E* = 1.19231e11 Pa, a = sqrt(4 P R/(pi E*)) = 0.29061 mm,
    # p0 = 2P/(pi a) = 1.9168 GPa, approach (Johnson) 2.5905e-5 m. Five digits: rel 1e-4.
    c = rvdyn.hertz_line_contact(35e3, 0.040, 0.010, 0.094)
    assert isinstance(c, rvdyn.LineContact)
    assert c.half_width == pytest.approx(2.9061e-4, rel=1e-4)
    assert c.peak_pressure == pytest.approx(1.9168e9, rel=1e-4)
    assert c.mean_pressure == pytest.approx(math.pi / 4 * c.peak_pressure, rel=1e-15)
    assert c.approach == pytest.approx(2.5905e-5, rel=1e-4)


@pytest.mark.parametrize("force, width, r1, r2", [
    (35e3, 0.04, 0.010, 0.094),
    (1e3, 0.01, 0.020, -0.050),   # pin in a concave seat (negative radius)
    (5e4, 0.03, 0.010, -0.0107224),  # nearly conformal root of the paper disc
])
def test_hertz_against_roark(force, width, r1, r2):
    # Roark: full width b = 1.60 sqrt(p K_D C_E), sigma_max = 0.798 sqrt(p/(K_D C_E)) with
    # K_D = 2R (diameters) and C_E = 2(1 - nu^2)/E. The printed 1.60 and 0.798 are the exact
    # sqrt(32/pi)/2 = 1.5958 and sqrt(2/pi) = 0.79788 rounded: 0.3 % and 0.02 %.
    c = rvdyn.hertz_line_contact(force, width, r1, r2)
    p = force / width
    k_d = 2 / (1 / r1 + 1 / r2)
    c_e = 2 * (1 - NU**2) / E_STEEL
    assert 2 * c.half_width == pytest.approx(1.60 * math.sqrt(p * k_d * c_e), rel=3e-3)
    assert c.peak_pressure == pytest.approx(0.798 * math.sqrt(p / (k_d * c_e)), rel=3e-4)
    # With the exact constants the agreement is round-off.
    assert 2 * c.half_width == pytest.approx(math.sqrt(32 / math.pi) / 2 * math.sqrt(p * k_d * c_e),
                                             rel=1e-13)


def test_hertz_vectorised_and_zero_force():
    f = np.array([0.0, 1e3, 4e3])
    c = rvdyn.hertz_line_contact(f, 0.04, 0.01, 0.1)
    assert all(isinstance(v, np.ndarray) and v.shape == (3,) for v in c)
    assert c.half_width[0] == 0.0 and c.approach[0] == 0.0
    # a ~ sqrt(F): four times the force, twice the width and the peak pressure.
    assert c.half_width[2] == pytest.approx(2 * c.half_width[1], rel=1e-14)
    assert c.peak_pressure[2] == pytest.approx(2 * c.peak_pressure[1], rel=1e-14)
    grid = rvdyn.hertz_line_contact(f[:, None], np.array([0.02, 0.04]), 0.01, 0.1)
    assert grid.peak_pressure.shape == (3, 2)


# ---- IMPACT law ------------------------------------------------------------------------------

K = rvdyn.PAPER_IMPACT_STIFFNESS


def test_paper_impact_constants():
    # 3.988e5 N/mm^1.5 -> x 1000^1.5; 100 N s/mm -> 1e5 N s/m; 0.01 mm -> 1e-5 m.
    assert K == pytest.approx(3.988e5 * PER_MM15, rel=1e-15)
    assert rvdyn.PAPER_IMPACT_EXPONENT == 1.5
    assert rvdyn.PAPER_IMPACT_MAX_DAMPING == 1e5
    assert rvdyn.PAPER_IMPACT_DEPTH == 1e-5


def test_impact_hand_value():
    # x = 5e-6 m (half the depth, s = 0.5, c = 0.5 cmax = 5e4 N s/m), v = 0.02 m/s:
    # 1.2611143e10 * (5e-6)^1.5 + 5e4 * 0.02 = 140.9971 + 1000 = 1140.997 N.
    f = rvdyn.impact_force(5e-6, 0.02, K)
    assert f == pytest.approx(1140.997, rel=1e-6)
    # Same force in both unit systems at 0.01 mm and rest: 3.988e5 * 0.01^1.5 = 398.8 N.
    assert rvdyn.impact_force(1e-5, 0.0, K) == pytest.approx(398.8, rel=1e-12)


def test_impact_is_continuous_and_ramps_the_damping():
    # Continuous at first touch: the damping term starts at 0 (STEP ramp), not at cmax.
    assert rvdyn.impact_force(0.0, 5.0, K) == 0.0
    small = rvdyn.impact_force(1e-12, 5.0, K)
    assert 0.0 < small < 1e-6
    # Damping coefficient (F(x, v) - F(x, 0)) / v = cmax s^2 (3 - 2 s), s = x / d clamped.
    x = np.linspace(1e-7, 2e-5, 40)
    v = 0.01
    c = (rvdyn.impact_force(x, v, K) - rvdyn.impact_force(x, 0.0, K)) / v
    s = np.clip(x / 1e-5, 0, 1)
    # Differences of forces up to ~1e3 N divided by 0.01 m/s: round-off ~1e-13 * 1e5.
    np.testing.assert_allclose(c, 1e5 * s**2 * (3 - 2 * s), rtol=1e-9, atol=1e-6)
    # Continuous across the end of the ramp.
    d = 1e-5
    lo, hi = rvdyn.impact_force(np.array([d - 1e-15, d + 1e-15]), 0.3, K)
    assert abs(hi - lo) < 1e-6


def test_impact_never_pulls():
    x = np.linspace(-1e-5, 3e-5, 50)
    f = rvdyn.impact_force(x, -50.0, K)
    assert np.all(f >= 0.0)
    assert np.all(f[x <= 0] == 0.0)
    # A fast separation inside the ramp is clamped to zero force.
    assert rvdyn.impact_force(1e-5, -10.0, K) == 0.0


def test_impact_other_laws_and_broadcasting():
    # Linear spring, no damping: F = k x exactly.
    f = rvdyn.impact_force([1e-6, 2e-6], 1.0, 1e9, exponent=1.0, cmax=0.0)
    np.testing.assert_allclose(f, [1e3, 2e3], rtol=1e-15)
    # e = 1.3: 2e8 * (1e-5)^1.3 = 63.2455532 N.
    assert rvdyn.impact_force(1e-5, 5.0, 2e8, exponent=1.3, cmax=0.0) == \
        pytest.approx(63.2455532, rel=1e-8)
    grid = rvdyn.impact_force(np.linspace(0, 1e-5, 4)[:, None], np.array([-0.1, 0.0, 0.1]), K)
    assert grid.shape == (4, 3)


def test_plot_stiffness_draws_both_conditions():
    from rvdyn.plotting import plot_stiffness

    fig = plot_stiffness(widths=np.linspace(1e-3, 2e-2, 30))
    ax = fig.axes[0]
    curves = [line for line in ax.get_lines() if len(line.get_xdata()) == 30]
    assert len(curves) == 2
    # The plotted data are the binding's values, widths in mm.
    np.testing.assert_allclose(curves[0].get_xdata(), np.linspace(1, 20, 30))
    np.testing.assert_allclose(
        curves[1].get_ydata(),
        rvdyn.contact_stiffness(np.linspace(1e-3, 2e-2, 30), 0.01, 0.1035, "convex-concave"))
    # Maxima marked and annotated (at the range edge: the curves decrease with width).
    assert any("no interior maximum" in t.get_text() for t in ax.texts)
