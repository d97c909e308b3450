"""Regression tests for the bad inputs found by fuzzing simulate, scenes and results."""

from __future__ import annotations

import functools
import json
import math

import numpy as np
import pytest

import rvdyn


@pytest.fixture(scope="module")
def run() -> rvdyn.Result:
    return rvdyn.simulate(rvdyn.Scene.paper("rated"), 0.01)


@pytest.mark.parametrize("kwargs", [
    {"max_samples": 10**8, "record_interval": 5e-324},   # 1.8e10 values: an abort before
    {"max_samples": 10**12, "record_interval": 1e-15},
    {"max_samples": 2**64 - 1, "record_interval": 5e-324},  # once an empty Result
    {"max_samples": -1},
    {"max_samples": 10**400},
])
def test_sample_counts_are_bounded_before_allocating(kwargs):
    with pytest.raises(rvdyn.ParameterError, match="max_samples") as info:
        rvdyn.simulate(rvdyn.Scene.paper("rated"), 0.01, **kwargs)
    assert len(str(info.value)) < 300


def test_work_is_bounded():
    with pytest.raises(rvdyn.ParameterError, match="steps"):
        rvdyn.simulate(rvdyn.Scene.paper("rated"), 0.01, dt=1e-300)
    with pytest.raises(rvdyn.ParameterError, match="threads must be at most 1024") as info:
        rvdyn.sweep([rvdyn.Scene.paper("idle")], 0.001, threads=10**5)
    assert "Some(" not in str(info.value)


def test_pin_numbers_and_times_are_checked(run):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    for pins in ([0], [25], [float("nan")]):
        with pytest.raises(rvdyn.ParameterError, match="pin number"):
            run.plot_pin_moments(pins=pins)
    ax = run.plot_pin_moments(pins=[24])
    np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(), run.pin_moment[:, 0, 23])
    for time in (float("nan"), math.inf, -1.0, 1.0):
        with pytest.raises(rvdyn.ParameterError, match="time"):
            run.largest_moment_pin(time)
    with pytest.raises(rvdyn.ParameterError, match="disc"):
        run.largest_moment_pin(0.005, 5)
    with pytest.raises(rvdyn.ParameterError, match="disc"):
        run.plot_disc_center(2)
    assert 1 <= run.largest_moment_pin(0.005) <= 24


@pytest.mark.parametrize("call", [
    lambda r: r.disc_path_radius(t_start=100.0),
    lambda r: r.loaded_pin_stats(float("nan")),
    lambda r: r.mean_output_speed(-1.0),
    lambda r: r.steady_window(10**400),
])
def test_analysis_arguments_outside_the_run_are_parameter_errors(run, call):
    # A raw ValueError ("zero-size array") escaped before.
    with pytest.raises(rvdyn.ParameterError):
        call(run)


def test_deeply_nested_scene_values_are_scene_errors():
    deep = functools.reduce(lambda a, _: [a], range(100_000), [])
    with pytest.raises(rvdyn.SceneError, match="nested too deeply"):
        rvdyn.Scene.paper("rated").replace(name=deep)


def test_saved_metadata_is_strict_json(tmp_path):
    r = rvdyn.simulate(rvdyn.Scene.paper("rated"), 0.005, "dopri5")
    path = r.save(tmp_path / "r.npz")
    meta = np.load(path)["__meta__"]
    text = meta.item() if meta.dtype.kind == "U" else bytes(meta.tobytes()).decode()

    def reject(token: str) -> float:
        raise AssertionError(f"non-standard JSON token {token}")

    json.loads(text, parse_constant=reject)  # dopri5's stats["dt"] was written as NaN
