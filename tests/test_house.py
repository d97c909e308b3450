"""The compiled Scene, the Options object, the channel registry, sweep results, and the
robustness details (Ctrl-C in sweeps, dopri5 on a stiff scene)."""

from __future__ import annotations

import json
import os
import pickle
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import rvdyn
from rvdyn import Options, Result, Scene, simulate, sweep
from rvdyn.result import CHANNEL_SPECS

# A child Python that restores the default SIGINT handler first: a parent started from a
# background job ignores SIGINT and the child would inherit that, so the tests check rvdyn and
# not the environment.
RESTORE_SIGINT = "import signal; signal.signal(signal.SIGINT, signal.default_int_handler)\n"


# ------------------------------------------------------------------------------ Scene
def test_paper_takes_the_load_case_by_keyword() -> None:
    # load= is the load case, not a dotted-path change that would fail later.
    assert Scene.paper(load="rated") == Scene.paper("rated")
    assert Scene.paper(load="idle")["load"] == {"kind": "idle"}
    with pytest.raises(rvdyn.SceneError, match="idle"):
        Scene.paper(load="heavy")
    with pytest.raises(rvdyn.SceneError, match="load case"):
        Scene.paper(load=5.0)


@pytest.mark.parametrize("changes", [
    {"load": {"kind": "idle", "torque": 5e4}},
    {"joints": {"kind": "rigid", "stiffness": 1e9}},
    {"inertias.sun": {"mass": 1.0, "inertia": 0.1, "inertia_about_axis": 5}},
    {"load": {"kind": "constant", "torque": 1.0, "extra": 5}},
    {"drive.spede": 1.0},
])
def test_unknown_fields_are_rejected_everywhere(changes: dict[str, object]) -> None:
    # Unknown fields are errors also in unit variants of tagged enums and in inertias.*.
    with pytest.raises(rvdyn.SceneError, match="unknown"):
        Scene.paper("idle").replace(**changes)
    data = Scene.paper("idle").to_dict()
    data["joints"] = {"kind": "rigid", "stiffness": 1e9}
    with pytest.raises(rvdyn.SceneError, match="unknown"):
        Scene(data)


@pytest.mark.parametrize(("path", "value", "says"), [
    ("joints.eccentric_bearing.rollers.count", 3.5, "joints.eccentric_bearing.rollers.count must be an integer, got 3.5"),
    ("load.torque", "4e4", 'load.torque must be a number [N m], got "4e4"'),
    ("contact.pin.damping.ratio", [0.1], "contact.pin.damping.ratio must be a number, got [0.1]"),
    ("discs", [{"phase": "pi"}, {"phase": 0.0}], 'discs[0].phase must be a number [rad], got "pi"'),
    ("crank_layout", {"bearings": [0.0, 0.1], "discs": [0.0, 0.0], "planet": None},
     "crank_layout.planet must be a number [m], got null"),
])
def test_a_value_of_the_wrong_type_is_named_by_its_path(path: str, value: object, says: str) -> None:
    # Inside the tagged objects (joints, load, contact laws) too, through replace and from a file.
    with pytest.raises(rvdyn.SceneError, match=re.escape(says)):
        Scene.physical("rated").replace(**{path: value})
    data = Scene.physical("rated").to_dict()
    node = data
    *parents, last = path.split(".")
    for key in parents:
        node = node[key]
    node[last] = value
    with pytest.raises(rvdyn.SceneError, match=re.escape(says)):
        Scene.from_json(json.dumps(data))


def test_equal_scenes_hash_equal() -> None:
    # 0.0 and -0.0 compare equal, so they must hash equal.
    a = Scene.paper("rated", **{"cycloid.d_delta": 0.0})
    b = Scene.paper("rated", **{"cycloid.d_delta": -0.0})
    assert a == b and hash(a) == hash(b) and len({a, b}) == 1
    assert a != Scene.paper("idle")


def test_scene_is_frozen_picklable_and_round_trips(tmp_path: Path) -> None:
    s = Scene.paper("rated").with_compliant_joints(crank_bearing="rigid")
    with pytest.raises(AttributeError):
        s.foo = 1  # type: ignore[misc]
    t = pickle.loads(pickle.dumps(s))
    assert t == s and hash(t) == hash(s)
    assert Scene.from_json(s.to_json()) == s
    assert Scene.from_toml(s.to_toml()) == s
    assert Scene.load(s.save(tmp_path / "s.toml")) == s
    assert Scene.load(s.save(tmp_path / "s.json")) == s
    assert s["joints.crank_bearing"] is None
    assert s["discs.1.phase"] == pytest.approx(np.pi)
    with pytest.raises(rvdyn.SceneError, match="no field"):
        s["discs.5"]
    with pytest.raises(rvdyn.SceneError, match="no field"):
        s.replace(**{"discs.2.phase": 0.0})
    # replace changes only what it names, and leaves the original alone.
    r = s.replace(**{"cycloid.d_rrp": 2e-5})
    assert r["cycloid.d_rrp"] == 2e-5 and s["cycloid.d_rrp"] == 0.0


def test_scene_errors_name_the_field() -> None:
    with pytest.raises(rvdyn.SceneError, match="NaN"):
        Scene.paper().replace(**{"load.torque": float("nan")})
    with pytest.raises(rvdyn.SceneError, match="dotted path"):
        Scene.paper().replace(**{"load..torque": 1.0})


# ------------------------------------------------------------------------------ Options
def test_options_are_validated_once_and_recorded() -> None:
    o = Options("rk4", dt=1e-5, channels="motion")
    assert (o.integrator, o.dt, o.channels) == ("rk4", 1e-5, ["motion"])
    assert pickle.loads(pickle.dumps(o)) == o and Options(**o.to_dict()) == o
    assert o.replace(atol=1e-8).atol == 1e-8 and o.atol == 1e-9
    for bad in ({"dt": -1.0}, {"rho_inf": 2.0}, {"atol": 0.0}, {"max_samples": 1}, {"channels": ["sound"]}):
        with pytest.raises(rvdyn.ParameterError):
            Options(**bad)  # type: ignore[arg-type]
    with pytest.raises(rvdyn.ParameterError, match="unknown integrator"):
        Options("euler")
    # The options actually used are on the result, and survive save/load.
    r = simulate(Scene.paper("rated"), 1e-3, options=o, dt=3e-5)
    assert r.options["integrator"] == "rk4" and r.options["t_end"] == 1e-3
    assert r.options["dt"] == pytest.approx(1e-3 / 34)  # ceil(1e-3 / 3e-5) = 34 equal steps
    assert isinstance(r.stats["steps"], int) and r.stats["steps"] == 34
    assert rvdyn.INTEGRATORS[0] == "generalized-alpha" and set(rvdyn.INTEGRATORS) == {
        "generalized-alpha", "generalized-alpha-adaptive", "dopri5", "rk4"}


def test_result_save_load_keeps_options_and_never_unpickles(tmp_path: Path) -> None:
    r = simulate(Scene.paper("rated"), 2e-3, "dopri5")
    assert r.stats["dt"] is None and isinstance(r.stats["evaluations"], int)
    back = Result.load(r.save(tmp_path / "r.npz"))
    assert back.options == r.options and back.stats == r.stats and back.scene == r.scene
    np.testing.assert_array_equal(back.pin_force, r.pin_force)
    assert back.loaded_pins.dtype == np.int64
    # An .npz holding a pickled object is refused, not executed.
    np.savez(tmp_path / "evil.npz", __meta__=np.array({"a": 1}, dtype=object), t=np.zeros(2))
    with pytest.raises(ValueError):
        Result.load(tmp_path / "evil.npz")


# ------------------------------------------------------------------------------ channels
def test_channels_come_from_the_core_registry() -> None:
    attrs = {n for n in dir(Result) if isinstance(getattr(Result, n), rvdyn.result._Channel)}
    assert attrs == set(CHANNEL_SPECS)
    r = simulate(Scene.paper("rated"), 1e-3, channels=["motion", "pins", "contact_points", "mesh", "energy", "bearings"])
    assert set(r.channels) == set(CHANNEL_SPECS)
    layout = {"discs": 2, "pins": 24, "cranks": 3, "meshes": 3, "2": 2}
    for name, spec in CHANNEL_SPECS.items():
        a = getattr(r, name)
        assert a.shape == (11,) + tuple(layout[d] for d in spec["shape"]), name
        assert a.dtype == np.dtype(spec["dtype"]), name
        assert spec["unit"] in (Result.__dict__[name].__doc__ or ""), name
    with pytest.raises(AttributeError, match="not recorded"):
        simulate(Scene.paper("rated"), 1e-3, channels=["motion"]).pin_force


# ------------------------------------------------------------------------------ sweep
def test_sweep_checks_options_once_and_raises_like_simulate() -> None:
    # Bad options raise once, before any run, not as one ParameterError per run.
    s = Scene.paper("idle")
    for kwargs in ({"t_end": float("nan")}, {"t_end": 1e-3, "dt": -1.0}, {"t_end": 1e-3, "max_samples": 1}):
        t_end = kwargs.pop("t_end")
        with pytest.raises(rvdyn.ParameterError):
            sweep([s, s], t_end, **kwargs)  # type: ignore[arg-type]
        with pytest.raises(rvdyn.ParameterError):
            simulate(s, t_end, **kwargs)  # type: ignore[arg-type]
    with pytest.raises(rvdyn.ParameterError, match="threads"):
        sweep([s], 1e-3, threads=10**5)


def test_sweep_returns_results_with_ok_and_error() -> None:
    good = Scene.paper("rated")
    out = sweep([good, good], 1e-3, "rk4", dt=5e-4, channels=["motion"])
    assert [r.ok for r in out] == [False, False]
    assert all(isinstance(r.error, rvdyn.SimulationError) for r in out)
    with pytest.raises(AttributeError, match="failed"):
        out[0].t
    ok = sweep([good], 1e-3)
    assert ok[0].ok and ok[0].error is None and ok[0].t.shape == (11,)


def _interrupt(code: str, wait_for_ready: bool = True) -> tuple[float, str, int]:
    proc = subprocess.Popen([sys.executable, "-c", RESTORE_SIGINT + code], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=dict(os.environ, RUST_BACKTRACE="0"))
    assert proc.stdout is not None
    assert proc.stdout.readline().strip() == "ready"
    time.sleep(1.0)
    t0 = time.monotonic()
    proc.send_signal(signal.SIGINT)
    # A run that ignored the signal would take minutes: communicate() raises on a hang.
    _, err = proc.communicate(timeout=120)
    return time.monotonic() - t0, err, proc.returncode


def test_ctrl_c_stops_a_sweep() -> None:
    # Ctrl-C stops the runs of a sweep and raises KeyboardInterrupt, not PanicException after
    # every run has finished. The interval is not asserted (no timed assertions); a hang fails
    # through the timeout.
    code = ("import rvdyn\ns = rvdyn.Scene.paper('rated')\nprint('ready', flush=True)\n"
            "rvdyn.sweep([s, s], 600.0, threads=2, channels=['motion'], max_samples=1000)\n")
    _, err, rc = _interrupt(code)
    assert rc != 0
    assert "KeyboardInterrupt" in err and "PanicException" not in err


def test_ctrl_c_stops_a_run_with_sigint_restored() -> None:
    code = ("import rvdyn\nprint('ready', flush=True)\n"
            "rvdyn.simulate(rvdyn.Scene.paper('rated'), 600.0, channels=['motion'], max_samples=1000)\n")
    _, err, rc = _interrupt(code)
    assert rc != 0 and "KeyboardInterrupt" in err


# ------------------------------------------------------------------------------ dopri5
def test_dopri5_stops_with_advice_on_a_stiff_scene() -> None:
    # Very light disc on 1e9 N/m eccentric bearings, crank bearings rigid: dopri5's steps fall
    # to ~2e-8 s, so it must stop with advice instead of running for minutes.
    s = Scene.paper("paper").replace(**{
        "inertias": {"sun": {"mass": 41.6, "inertia": 1.0}, "crank": {"mass": 0.01, "inertia": 0.594},
                     "disc": {"mass": 1.0, "inertia": 1.29e-05}, "carrier": {"mass": 1.54, "inertia": 1.0},
                     "load_inertia": 0.0},
        "drive": {"kind": "speed", "speed": 0.567, "start": "step", "ramp_time": 0.0},
        "initial": "steady"}).with_compliant_joints(
        eccentric_bearing={"stiffness": 1e9, "damping": 76160.0}, crank_bearing="rigid")
    with pytest.raises(rvdyn.SimulationError, match="generalized-alpha") as info:
        simulate(s, 5e-3, "dopri5", channels=["motion"])
    assert "Hz" in str(info.value)
    # The implicit method runs the same scene.
    assert simulate(s, 5e-3, channels=["motion"]).ok


def test_work_and_memory_are_bounded() -> None:
    # A sample count that overflows, dt = 1e-300 and a huge max_samples are errors before any
    # work: not an empty Result, an endless run or an allocation abort.
    s = Scene.paper("rated")
    with pytest.raises(rvdyn.ParameterError, match="steps"):
        simulate(s, 0.01, dt=1e-300)
    for n in (2**64 - 1, 10**12):
        with pytest.raises(rvdyn.ParameterError, match="max_samples"):
            simulate(s, 0.01, max_samples=n, record_interval=5e-324)
    with pytest.raises(rvdyn.ParameterError, match="steps"):
        sweep([s], 0.01, "rk4", dt=1e-300)
    # The largest accepted count still runs (the interval is what bounds the samples here).
    r = simulate(s, 1e-3, max_samples=10**8, record_interval=1e-4, channels="motion")
    assert r.t.shape == (11,)


def test_scene_sizes_that_leave_no_reducer_are_scene_errors() -> None:
    # A metre typed for a millimetre was accepted and then blamed on the step or the torque.
    s = Scene.paper("rated")
    for change, match in [({"cycloid.d_rp": 1.0}, "d_rp"), ({"cycloid.d_delta": 0.1}, "d_delta"),
                          ({"discs.1.d_rrp": -0.02}, "d_rrp"),
                          ({"pin_errors.radius": [0.05] * 24}, "overlap"),
                          ({"pin_errors.position": [[1.0, 0.0]] * 24}, "pin_errors.position")]:
        with pytest.raises(rvdyn.SceneError, match=match):
            s.replace(**change)
    # A negative pin radius is named as such (the modification check blamed d_rp = 0).
    with pytest.raises(rvdyn.RvdynError, match="pin_radius") as info:
        s.replace(**{"cycloid.pin_radius": -0.01})
    assert "modification" not in str(info.value)
    # Real sizes pass (and the geometry tests' 2 mm shift).
    s.replace(**{"cycloid.d_rp": -2e-3, "cycloid.d_delta": 1e-4, "pin_errors.radius": [5e-6] * 24})
    # Options of the wrong kind are refused rather than read loosely.
    with pytest.raises(rvdyn.ParameterError, match="skip_separated"):
        simulate(s, 1e-3, skip_separated="no")
    with pytest.raises(rvdyn.ParameterError, match="t_end"):
        simulate(s, True)
    with pytest.raises(rvdyn.ParameterError, match="got -1"):
        simulate(s, 1e-3, max_samples=-1)
    with pytest.raises(rvdyn.ParameterError, match="crank_angles"):
        rvdyn.ltca(s, 4e4, ["a"])


def test_analysis_counts_are_bounded_and_whole() -> None:
    # A count of 1e12 crank angles, loop points or harmonics aborted the interpreter on
    # allocation; a negative one raised a bare OverflowError, a float was truncated.
    from rvdyn.analysis import torque_twist, transmission_error
    from rvdyn.analysis.campbell import campbell
    from rvdyn.analysis.spectrum import excitation_orders
    s = Scene.paper("rated")
    for bad in (10**12, -5, 2.9, True):
        with pytest.raises(rvdyn.ParameterError, match="points"):
            transmission_error(s, 4e4, bad)
        with pytest.raises(rvdyn.ParameterError, match="points"):
            torque_twist(s, 4e4, 0.0, bad)
    for bad in (2**32 - 1, 10**11, -1, 1.5):
        with pytest.raises(rvdyn.ParameterError, match="harmonics"):
            excitation_orders(s, bad)
        with pytest.raises(rvdyn.ParameterError, match="harmonics"):
            campbell(s, harmonics=bad)
    # A loop too small to twist the reducer gave an infinite rigidity.
    with pytest.raises(rvdyn.ParameterError, match="round-off"):
        torque_twist(s, 1e-9, 0.0, 41)
    # The LTCA's Newton tolerance: looser than 1e-6 of the load is refused, not returned.
    for tol in (1e-3, 1.0):
        with pytest.raises(rvdyn.ParameterError, match="tolerance"):
            rvdyn.ltca(s, 4e4, [0.0], tolerance=tol)


def test_damaged_result_files_raise_parameter_error(tmp_path: Path) -> None:
    # Damaged files raise ParameterError, not KeyError, JSONDecodeError, BadZipFile, EOFError...
    good = simulate(Scene.paper("rated"), 1e-3, channels="motion").save(tmp_path / "good.npz")
    cases = {
        "missing.npz": None,
        "text.npz": b"not a zip file",
        "empty.npz": b"",
        "truncated.npz": good.read_bytes()[:200],
    }
    for name, data in cases.items():
        if data is not None:
            (tmp_path / name).write_bytes(data)
    np.savez(tmp_path / "nometa.npz", t=np.zeros(3))
    np.savez(tmp_path / "badmeta.npz", __meta__=np.array("{not json"), t=np.zeros(3))
    np.savez(tmp_path / "listmeta.npz", __meta__=np.array("[1, 2]"), t=np.zeros(3))
    for name in [*cases, "nometa.npz", "badmeta.npz", "listmeta.npz"]:
        with pytest.raises(rvdyn.ParameterError, match="cannot read result file"):
            Result.load(tmp_path / name)
    assert Result.load(good).t.shape == (11,)


def test_numpy_integers_are_accepted_as_counts() -> None:
    s = Scene.paper("rated")
    o = Options(max_samples=np.int64(1000))
    assert o.max_samples == 1000 and isinstance(o.max_samples, int)
    out = sweep([s], 1e-3, threads=np.int64(1), max_samples=np.int32(100))
    assert out[0].ok
    with pytest.raises(rvdyn.ParameterError, match="threads"):
        sweep([s], 1e-3, threads=1.5)  # type: ignore[arg-type]
    with pytest.raises(rvdyn.ParameterError, match="threads"):
        sweep([s], 1e-3, threads=0)


def test_scene_values_may_be_numpy_numbers() -> None:
    s = Scene.paper("rated").replace(**{"cranks": np.int64(3), "load.torque": np.float32(1e4),
                                        "pin_errors.radius": np.zeros(24)})
    assert s["cranks"] == 3 and s["load.torque"] == 1e4 and s["pin_errors.radius"] == [0.0] * 24
    with pytest.raises(rvdyn.SceneError, match="not a number"):
        Scene.paper().replace(**{"load.torque": object()})
    with pytest.raises(rvdyn.SceneError, match="NaN"):
        Scene.paper().replace(**{"load.torque": np.float64("nan")})
