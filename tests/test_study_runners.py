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
    """Kills its worker process for the largest d_rrp samples (a crashed worker)."""
    if scene["cycloid.d_rrp"] > 2e-6:
        os._exit(3)
    return {"y": scene["cycloid.d_rrp"], "threads": float(os.environ.get("RAYON_NUM_THREADS", "0"))}


def test_a_dead_worker_is_recorded_not_dropped(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("RAYON_NUM_THREADS", raising=False)
    ctx = multiprocessing.get_context("spawn")
    tols = [Tolerance("cycloid.d_rrp", tol=1e-5)]
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=ctx) as ex:
        t = rvdyn.study(SCENE, FunctionKernel(dying_metric, ("y", "threads")), tols, samples=12, seed=0,
                        runner=ex, chunk_size=4)
    assert list(t["sample"]) == list(range(12))
    dies = t["cycloid.d_rrp"] > 2e-6
    assert dies.any()
    assert t["error"][dies].str.startswith("runner failed").all()
    ok = t["error"] == ""
    # Samples that ran before the pool broke ran single-threaded.
    assert ok.any() and (t["threads"][ok] == 1.0).all()
    assert np.isnan(t["y"][~ok]).all()
