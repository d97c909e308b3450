"""Disc profile error and first-stage gear errors, each against a first-order analytic effect
(docs/model.md#manufacturing-errors-of-profile-and-gears)."""

import math

import numpy as np
import pytest

import rvdyn
from rvdyn import Scene, SceneError

RATED = Scene.paper("rated")
PA = RATED["stage1.pressure_angle"]
R_BS = RATED["stage1.z_sun"] * RATED["stage1.module"] / 2 * math.cos(PA)


def _amplitude(t: np.ndarray, y: np.ndarray, freq: float, t_start: float) -> float:
    """Least-squares amplitude of the sinusoid at ``freq`` [Hz] in ``y`` after ``t_start``
    (with an offset and a linear drift)."""
    w = t > t_start
    tt, yy = t[w], y[w]
    a = np.column_stack([np.sin(2 * math.pi * freq * tt), np.cos(2 * math.pi * freq * tt), np.ones_like(tt), tt])
    c, *_ = np.linalg.lstsq(a, yy, rcond=None)
    return math.hypot(c[0], c[1])


def test_a_constant_profile_offset_is_the_equidistant_modification_with_opposite_sign() -> None:
    # Offset a (material added) = d_rrp = -a: the same profile, so the same run. Pin forces to
    # 1e-6 of the peak: the two evaluate the same distance by different arithmetic and take
    # different adaptive steps; at atol 1e-12 m on penetrations of 2e-4 m the integration error
    # is about 1e-8 of the force.
    # The disc's mass properties are given: computed from the geometry, the d_rrp disc would be
    # heavier by its extra material (the error is a measurement of the profile, not a mass).
    a = 5e-6
    info = RATED.model_info()
    base = RATED.replace(**{"inertias.disc": {"mass": info["disc_mass"], "inertia": info["disc_inertia"]}})
    kw = {"t_end": 5e-3, "integrator": "dopri5", "channels": ["pins"], "record_interval": 1e-4,
          "atol": 1e-12, "rtol": 1e-10}
    offset = rvdyn.simulate(base.replace(**{"discs.0.profile_error": {"harmonics": [[a, 0.0, 0.0]]}}), **kw)
    equidistant = rvdyn.simulate(base.replace(**{"discs.0.d_rrp": -a}), **kw)
    nominal = rvdyn.simulate(base, **kw)
    peak = equidistant.pin_force.max()
    assert np.abs(offset.pin_force - equidistant.pin_force).max() < 1e-6 * peak
    # ... and it is not the nominal disc (the test can fail).
    assert np.abs(nominal.pin_force - equidistant.pin_force).max() > 1e-2 * peak


def test_sun_runout_gives_a_mesh_approach_e_sin_at_the_sun_rotation_order() -> None:
    # Sun runout e: each drive flank approaches by e sin(th_s - th_c + phase - gamma_i + pa)
    # (derivation in docs/model.md), once per revolution of the sun relative to the carrier.
    # The three offsets sum to zero, so with the sun prescribed the carrier cannot absorb them:
    # they become mesh deflection one for one, up to second order in e. Amplitude of the
    # difference to a run without runout, fitted at the relative sun frequency: 1e-3.
    steady = RATED.replace(initial="steady")
    f_rel = steady["drive.speed"] * (1 - 1 / 57) / (2 * math.pi)
    t_end = 8 / f_rel
    kw = {"t_end": t_end, "integrator": "dopri5", "channels": ["motion", "mesh"], "record_interval": 2e-5}
    e = 1e-5
    r0 = rvdyn.simulate(steady, **kw)
    r1 = rvdyn.simulate(steady.replace(**{"gear_errors.sun.runout": e, "gear_errors.sun.runout_phase": 0.4}), **kw)
    for i in range(3):
        d = r1.mesh_deflection[:, i] - r0.mesh_deflection[:, i]
        assert _amplitude(r1.t, d, f_rel, t_end / 4) == pytest.approx(e, rel=1e-3)
        # Not at the mesh's other orders (twice the rotation order).
        assert _amplitude(r1.t, d, 2 * f_rel, t_end / 4) < 1e-2 * e


def _slow() -> tuple[Scene, float]:
    # A twentieth of the paper's input speed: the tooth-pass orders stay far below the main
    # torsional mode (about 1.2 kHz), so the response is quasi-static.
    w = RATED["drive.speed"] / 20
    return RATED.replace(initial="steady", **{"drive.speed": w}), w * (1 - 1 / 57) / (2 * math.pi)


def test_sinusoidal_pitch_error_at_the_rotation_order() -> None:
    # Cumulative pitch deviation F = A sin(psi + p) of the sun: cos(pa) A on the line of action
    # per mesh, at the sun's rotation order, again summing to zero over the planets: mesh
    # deflection amplitude cos(pa) A (1e-3).
    scene, f_rel = _slow()
    amp = 3e-6
    kw = {"t_end": 0.05 + 2 / f_rel, "integrator": "dopri5", "channels": ["motion", "mesh"], "record_interval": 5e-5}
    r0 = rvdyn.simulate(scene, **kw)
    r1 = rvdyn.simulate(scene.replace(**{"gear_errors.sun.pitch_amplitude": amp, "gear_errors.sun.pitch_phase": 0.2}), **kw)
    for i in range(3):
        d = r1.mesh_deflection[:, i] - r0.mesh_deflection[:, i]
        assert _amplitude(r1.t, d, f_rel, 0.05) == pytest.approx(math.cos(PA) * amp, rel=1e-3)


def test_tooth_to_tooth_pitch_error_shows_at_its_tooth_order_in_the_output() -> None:
    # Alternating single-pitch deviations F_k = f (-1)^k of the 18-tooth sun: a triangle wave
    # of two tooth pitches, fundamental amplitude 8/pi^2 cos(pa) f on the line of action at
    # order 9 (half the tooth-pass order). The three planets sit 6 teeth apart, so all meshes
    # see it in phase: it turns the carrier instead of loading the meshes, a transmission error
    # E / (57 r_bs) of the output at order 9 (1e-2: the order is 9 % of the main torsional
    # mode's frequency at this speed, a dynamic amplification of about 1e-3).
    scene, f_rel = _slow()
    f = 1e-6
    kw = {"t_end": 0.05 + 2 / f_rel, "integrator": "dopri5", "channels": ["motion"], "record_interval": 2e-5}
    r0 = rvdyn.simulate(scene, **kw)
    r1 = rvdyn.simulate(scene.replace(**{"gear_errors.sun.pitch_deviation": [f * (-1) ** k for k in range(18)]}), **kw)
    te = r1.carrier_angle - r0.carrier_angle
    want = 8 / math.pi ** 2 * math.cos(PA) * f / (57 * R_BS)
    assert _amplitude(r1.t, te, 9 * f_rel, 0.05) == pytest.approx(want, rel=1e-2)
    assert _amplitude(r1.t, te, f_rel, 0.05) < 1e-2 * want


@pytest.mark.parametrize(("changes", "match"), [
    ({"discs.0.profile_error": {"harmonics": [[1e-3, 1.0, 0.0]]}}, r"discs\[0\]\.profile_error\.offset bound"),
    ({"discs.1.profile_error": {"harmonics": [[1e-6, 0.5, 0.0]]}}, r"discs\[1\]\.profile_error\.harmonics\[0\] order"),
    ({"discs.0.profile_error": {"table": [[1.0, 0.0], [1.0, 1e-6]]}}, r"table angles must increase"),
    ({"discs.0.profile_error": {"table": [[-0.1, 0.0]]}}, r"table\[0\] angle must be in \[0, 2 pi\)"),
    ({"gear_errors.sun.runout": -1e-6}, r"gear_errors\.sun\.runout must be in \[0, 0\.0003\) m"),
    ({"gear_errors.sun.pitch_deviation": [0.0, 1e-6]}, r"one value per tooth \(18\)"),
    ({"gear_errors.planets": [{"runout": 1e-6}]}, r"one entry per planet \(3\)"),
    ({"gear_errors.planets": [{}, {}, {"pitch_amplitude": 1.0}]}, r"gear_errors\.planets\[2\]\.pitch_amplitude"),
    ({"stage1": None, "gear_errors.sun.runout": 1e-6}, r"gear_errors need a first stage"),
])
def test_bad_errors_are_scene_errors_naming_the_field_and_limit(changes: dict[str, object], match: str) -> None:
    with pytest.raises(SceneError, match=match):
        RATED.replace(**changes)
