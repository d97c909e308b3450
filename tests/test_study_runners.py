"""The same study gives bit-identical tables in threads, processes, a Dask LocalCluster with
2 worker processes and Ray; lost workers are rows with an error, never dropped."""

from __future__ import annotations

import concurrent.futures
import multiprocessing
import os

import numpy as np
import pytest

import rvdyn
from rvdyn.study import FunctionKernel, LatinHypercube, Tolerance

SCENE = rvdyn.Scene.paper("rated")
TOLS = [Tolerance("cycloid.d_rrp", tol=1e-5), Tolerance("pin_errors.radius", tol=5e-6, dist="uniform"),
        Tolerance("discs.1.d_rp", lower=-1e-5, upper=0.0, dist="uniform")]
ARGS = dict(samples=LatinHypercube(6), seed=11, kernel_options={"t_end": 0.01})


def _bytes(table: object) -> list[bytes]:
    import pandas as pd

    assert isinstance(table, pd.DataFrame)
    return [table[c].to_numpy().tobytes() if c != "error" else "\n".join(table[c]).encode() for c in table.columns]


@pytest.fixture(scope="module")
def reference() -> object:
    pytest.importorskip("pandas")
    return rvdyn.study(SCENE, "dynamic", TOLS, runner=1, **ARGS)


def test_threads_are_identical(reference: object) -> None:
    t = rvdyn.study(SCENE, "dynamic", TOLS, runner=concurrent.futures.ThreadPoolExecutor(2), **ARGS)
    assert _bytes(t) == _bytes(reference)
    assert (reference["error"] == "").all()  # type: ignore[index]


def test_processes_are_identical(reference: object) -> None:
    ctx = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=ctx) as ex:
        t = rvdyn.study(SCENE, "dynamic", TOLS, runner=ex, batch_size=2, **ARGS)
    assert _bytes(t) == _bytes(reference)


# Dask warns when its scratch folder takes > 1 s to create (a busy CI machine): not a failure.
@pytest.mark.filterwarnings("ignore:Creating scratch directories is taking:UserWarning")
def test_dask_local_cluster_is_identical(reference: object, tmp_path: os.PathLike[str],
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    distributed = pytest.importorskip("distributed")
    monkeypatch.delenv("RAYON_NUM_THREADS", raising=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40) as cluster, distributed.Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        t = rvdyn.study(SCENE, "dynamic", TOLS, runner=client, out=os.path.join(tmp_path, "d.parquet"),
                        chunk_size=4, **ARGS)
        # the workers ran with one native thread each
        env = client.run(lambda: os.environ.get("RAYON_NUM_THREADS"))
    assert _bytes(t) == _bytes(reference)
    assert set(env.values()) == {"1"}


def test_ray_pool_is_identical(reference: object) -> None:
    ray = pytest.importorskip("ray", reason="Ray is not installed (pip install 'rvdyn[ray]')")
    from ray.util.multiprocessing import Pool

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        pool = Pool(processes=2)
        t = rvdyn.study(SCENE, "dynamic", TOLS, runner=pool, **ARGS)
        pool.terminate()
    finally:
        ray.shutdown()
    assert _bytes(t) == _bytes(reference)


def dying_metric(scene: rvdyn.Scene) -> dict[str, float]:
    """Kills its worker process for the largest d_rrp samples while the file named by
    $RVDYN_TEST_DIE exists (a crashed worker)."""
    marker = os.environ.get("RVDYN_TEST_DIE", "")
    if scene["cycloid.d_rrp"] > 2e-6 and marker and os.path.exists(marker):
        os._exit(3)
    return {"y": scene["cycloid.d_rrp"], "threads": float(os.environ.get("RAYON_NUM_THREADS", "0"))}


def test_a_dead_worker_is_recorded_not_dropped(monkeypatch: pytest.MonkeyPatch, tmp_path: os.PathLike[str]) -> None:
    pytest.importorskip("pyarrow")
    marker = os.path.join(tmp_path, "die")
    open(marker, "w").close()
    monkeypatch.setenv("RVDYN_TEST_DIE", marker)
    monkeypatch.delenv("RAYON_NUM_THREADS", raising=False)
    out = os.path.join(tmp_path, "s.parquet")
    ctx = multiprocessing.get_context("spawn")
    tols = [Tolerance("cycloid.d_rrp", tol=1e-5)]
    kernel = FunctionKernel(dying_metric, ("y", "threads"))
    args = dict(samples=12, seed=0, out=out, chunk_size=4)
    # The pool breaks when a worker dies; once it has lost a whole chunk the study stops.
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=ctx) as ex:
        with pytest.raises(rvdyn.study.RunnerError, match="lost every task"):
            rvdyn.study(SCENE, kernel, tols, runner=ex, **args)
    t = rvdyn.study.read(out)
    dies = t["cycloid.d_rrp"] > 2e-6
    assert len(t) >= 4 and dies.any()
    assert list(t["sample"]) == list(range(len(t)))  # every attempted sample is a row
    assert t["error"][dies].str.startswith("runner failed").all()
    assert np.isnan(t["y"][t["error"] != ""]).all()
    # Resume with a working pool: the lost samples run again, none is missing.
    os.remove(marker)
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=ctx) as ex:
        t2 = rvdyn.study(SCENE, kernel, tols, runner=ex, retry_failed=True, **args)
    assert list(t2["sample"]) == list(range(12)) and (t2["error"] == "").all()
    assert (t2["threads"] == 1.0).all()  # workers ran single-threaded


def dask_dying_metric(scene: rvdyn.Scene) -> dict[str, float]:
    """Kills its worker once: the first task to find the file named by $RVDYN_TEST_DIE removes
    it and dies."""
    marker = os.environ.get("RVDYN_TEST_DIE", "")
    if marker:
        try:
            os.remove(marker)
        except FileNotFoundError:
            pass
        else:
            os._exit(3)
    return {"y": scene["cycloid.d_rrp"]}


@pytest.mark.filterwarnings("ignore:Creating scratch directories is taking:UserWarning")
def test_dask_reruns_the_task_of_a_dead_worker(monkeypatch: pytest.MonkeyPatch, tmp_path: os.PathLike[str]) -> None:
    distributed = pytest.importorskip("distributed")
    marker = os.path.join(tmp_path, "die")
    open(marker, "w").close()
    monkeypatch.setenv("RVDYN_TEST_DIE", marker)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=50) as cluster, distributed.Client(cluster) as client:
        t = rvdyn.study(SCENE, FunctionKernel(dask_dying_metric, ("y",)), [Tolerance("cycloid.d_rrp", tol=1e-5)],
                        samples=6, seed=0, runner=client)
    assert not os.path.exists(marker)  # a worker died ...
    assert list(t["sample"]) == list(range(6)) and (t["error"] == "").all()  # ... and its task ran again


def rarely_dying_metric(scene: rvdyn.Scene) -> dict[str, float]:
    """As :func:`dying_metric`, for the largest d_rrp samples only (above 4e-6 m)."""
    marker = os.environ.get("RVDYN_TEST_DIE", "")
    if scene["cycloid.d_rrp"] > 4e-6 and marker and os.path.exists(marker):
        os._exit(3)
    return {"y": scene["cycloid.d_rrp"]}


@pytest.mark.filterwarnings("ignore:Creating scratch directories is taking:UserWarning")
def test_dask_samples_that_always_kill_their_worker_are_rows(monkeypatch: pytest.MonkeyPatch,
                                                            tmp_path: os.PathLike[str]) -> None:
    # The shared task is scattered to the workers; when every copy died with its worker the
    # other tasks of the batch were cancelled and the study stopped with a raw
    # FuturesCancelledError, on every resume again. Now the cancelled tasks run once more with
    # the shared task sent along: the killing samples are failed rows (so may be tasks queued
    # on the workers they killed: Dask's allowed-failures), none is dropped, and a resume
    # without the fault completes the table.
    distributed = pytest.importorskip("distributed")
    pytest.importorskip("pyarrow")
    marker = os.path.join(tmp_path, "die")
    open(marker, "w").close()
    monkeypatch.setenv("RVDYN_TEST_DIE", marker)
    out = os.path.join(tmp_path, "k.parquet")
    tols = [Tolerance("cycloid.d_rrp", tol=1e-5)]
    kernel = FunctionKernel(rarely_dying_metric, ("y",))
    args: dict[str, object] = dict(samples=12, seed=0, chunk_size=12, retries=1, out=out)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=50) as cluster, distributed.Client(cluster) as client:
        try:
            rvdyn.study(SCENE, kernel, tols, runner=client, **args)  # type: ignore[arg-type]
        except rvdyn.study.RunnerError:
            pass  # the chunk was lost as a whole (a loaded machine): its rows are kept all the same
        t = rvdyn.study.read(out)
        dies = t["cycloid.d_rrp"] > 4e-6
        assert list(t["sample"]) == list(range(12)) and dies.any() and (~dies).any()
        assert t["error"][dies].str.startswith("runner failed").all()
        os.remove(marker)
        t2 = rvdyn.study(SCENE, kernel, tols, runner=client, retry_failed=True, **args)  # type: ignore[arg-type]
    assert list(t2["sample"]) == list(range(12)) and (t2["error"] == "").all()


def crashing_metric(scene: rvdyn.Scene) -> dict[str, float]:
    """Kills its worker process for every sample with d_rrp above 6e-6 m (a segfault or an
    out-of-memory kill on that sample, whatever worker runs it)."""
    if scene["cycloid.d_rrp"] > 6e-6:
        os._exit(3)
    return {"y": scene["cycloid.d_rrp"] / 1e-6}


def _check_only_the_crashing_samples_are_lost(t: object) -> None:
    import pandas as pd

    assert isinstance(t, pd.DataFrame)
    crash = t["cycloid.d_rrp"] > 6e-6
    assert list(t["sample"]) == list(range(len(t))) and crash.any() and (~crash).sum() >= 30
    assert t["error"][crash].str.startswith("runner failed: ").all()
    assert (t["error"][~crash] == "").all()  # every other sample ran (34 of 40 were lost before)
    # The lost samples are not rejected parts: the yield and the summaries leave them out, and say so.
    with pytest.warns(rvdyn.study.RunnerFailureWarning, match=rf"{int(crash.sum())} of 40 samples were lost"):
        y = rvdyn.study.yield_rate(t, [rvdyn.study.Criterion("y", max=10)])
    assert (y.passed, y.n) == (int((~crash).sum()), int((~crash).sum()))
    with pytest.warns(rvdyn.study.RunnerFailureWarning):
        d = rvdyn.study.describe(t, n_resamples=50)["y"]
    assert (d["n"], d["failed"], d["lost"]) == (int((~crash).sum()), 0, int(crash.sum()))


CRASH_ARGS: dict[str, object] = dict(samples=LatinHypercube(40), seed=2)


def test_a_crashing_sample_fails_alone_on_a_process_pool() -> None:
    # The pool broke and every other sample of the chunk became a "runner failed" row (34 of
    # 40), counted by the yield as rejected parts: 0.15 for a true 0.95. Now the pool is
    # replaced and the lost tasks run again one at a time.
    t = rvdyn.study(SCENE, FunctionKernel(crashing_metric, ("y",)), [Tolerance("cycloid.d_rrp", tol=1e-5)],
                    runner="processes:2", **CRASH_ARGS)  # type: ignore[arg-type]
    _check_only_the_crashing_samples_are_lost(t)
    assert t["error"][t["cycloid.d_rrp"] > 6e-6].str.contains("BrokenProcessPool").all()


def test_a_crashing_sample_fails_alone_on_ray(monkeypatch: pytest.MonkeyPatch) -> None:
    # The Ray pool lost the whole chunk and the study stopped with a RunnerError.
    pytest.importorskip("ray", reason="Ray is not installed (pip install 'rvdyn[ray]')")
    # Ray's workers import this module (the kernel's function) from the path they inherit.
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [os.path.dirname(os.path.abspath(__file__)),
                                                                   os.environ.get("PYTHONPATH")])))
    t = rvdyn.study(SCENE, FunctionKernel(crashing_metric, ("y",)), [Tolerance("cycloid.d_rrp", tol=1e-5)],
                    runner="ray:2", retries=0, **CRASH_ARGS)  # type: ignore[arg-type]
    _check_only_the_crashing_samples_are_lost(t)
