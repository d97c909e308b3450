"""Runners: where the samples of a study are evaluated.

A runner is anything with ``map(fn, items)``: :class:`ThreadRunner` (the default; the core
releases the GIL, so threads run in parallel), a :mod:`concurrent.futures` executor
(``ThreadPoolExecutor``, ``ProcessPoolExecutor``), a ``dask.distributed.Client`` (its
``map``/``gather`` is used with ``retries``, so a task whose worker died is run again) or
``ray.util.multiprocessing.Pool``. Strings name one: ``"threads"``, ``"threads:4"``,
``"processes:2"`` (a pool rvdyn replaces when a dying worker breaks it), a Dask scheduler
address ``"tcp://host:8786"``, or ``"ray"`` / ``"ray:N"`` / ``"ray://host:10001"`` (Ray tasks,
retried when their worker dies: :class:`RayTasks`).

Tasks are the top-level function :func:`evaluate_batch` bound to a picklable :class:`Task`
(scene, kernel, tolerance layout); each returns small records ``(sample id, metrics, error)``.
A sample whose analysis raises is a record with the error message; a task that the runner
loses (worker died, broken pool) is recorded as failed with a message starting with
:data:`RUNNER_FAILED`: no sample is dropped, and the statistics leave such rows out (with a
:class:`RunnerFailureWarning`). With ``"processes:N"``, Dask and the Ray strings, a sample
that kills its worker fails alone; the other tasks run.
"""

from __future__ import annotations

import concurrent.futures
import functools
import math
import os
import pickle
import traceback
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

from ..errors import ParameterError, RvdynError
from ..scene import Scene
from .spec import Layout, apply_values

__all__ = ["RunnerError", "RunnerFailureWarning", "RUNNER_FAILED", "ThreadRunner", "Task", "Record", "evaluate", "evaluate_batch", "resolve_runner", "THREAD_ENV"]

#: Environment variables set in worker processes so each worker runs single-threaded native
#: code (rayon in the Rust core, BLAS/OpenMP in numpy): n workers use n cores, not n^2.
THREAD_ENV = ("RAYON_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")

#: One evaluated sample: (sample id, {metric: value}, error message or "").
Record = tuple[int, dict[str, float], str]


#: The start of the ``error`` of a sample the runner lost (its worker died, the pool broke):
#: not a result of the analysis. Statistics leave such rows out, with a
#: :class:`RunnerFailureWarning`.
RUNNER_FAILED = "runner failed"


class RunnerFailureWarning(RuntimeWarning):
    """Samples lost by the runner (``error`` starting with ``"runner failed"``) were left out
    of a statistic (``yield_rate``, ``describe``): they say nothing about the parts. Run the
    study again with the same ``out`` and ``retry_failed=True`` to evaluate them."""


class RunnerError(RvdynError, RuntimeError):
    """Samples that could not be evaluated stop the computation.

    In :func:`rvdyn.study.run`: the runner lost every task of a chunk (a broken process pool,
    workers that keep dying). The rows so far (the lost ones with their error) are on disk when
    the study has ``out``; running it again resumes (``retry_failed=True`` reruns the lost
    samples). In :func:`rvdyn.study.sobol`: a sample of the Saltelli design failed (the
    message gives how many and the first error)."""


@dataclass(frozen=True)
class Task:
    """Everything a worker needs besides the sample values (picklable, sent with each task)."""

    scene: Scene
    kernel: Any
    layout: Layout
    threads: int = 1
    driver_pid: int = 0


_configured = False


def _configure_worker(threads: int) -> None:
    global _configured
    if not _configured:
        for name in THREAD_ENV:
            os.environ.setdefault(name, str(threads))
        _configured = True


def evaluate(task: Task, sample: tuple[int, Sequence[float]]) -> Record:
    """Evaluate one sample ``(id, values)``: set the toleranced fields of the scene and run the
    kernel. Any exception becomes the record's error message (the study goes on); so does a
    metric that is NaN or infinite ("metric <name> is not finite: nan ..."; the other metrics
    keep their values)."""
    sid, values = sample
    try:
        scene = apply_values(task.scene, task.layout, np.asarray(values, dtype=float))
        metrics = {str(k): float(v) for k, v in task.kernel(scene).items()}
    except Exception as exc:  # noqa: BLE001 - a failed sample is a row, whatever failed
        msg = f"{type(exc).__name__}: {exc}".strip()
        if not isinstance(exc, ValueError | ArithmeticError | RuntimeError):
            msg += " | " + traceback.format_exc(limit=3).replace("\n", " ")[-400:]
        return int(sid), {}, msg
    # A metric that came back NaN or infinite without an exception (e.g. the dynamic kernel's
    # output_speed_error when the input does not turn) makes the sample a failed one: counted
    # with the failures and named, instead of a silent NaN. The finite metrics keep their values.
    bad = [k for k, v in metrics.items() if not math.isfinite(v)]
    if bad:
        return int(sid), metrics, (f"metric{'s' if len(bad) > 1 else ''} {', '.join(bad)} "
                                   f"{'are' if len(bad) > 1 else 'is'} not finite: "
                                   f"{', '.join(str(metrics[k]) for k in bad)} (returned by the kernel without an error)")
    return int(sid), metrics, ""


def evaluate_batch(task: Task, batch: Sequence[tuple[int, Sequence[float]]]) -> list[Record]:
    """Evaluate a batch of samples in order (one task of a runner)."""
    if task.driver_pid and os.getpid() != task.driver_pid:
        _configure_worker(task.threads)
    return [evaluate(task, s) for s in batch]


class ThreadRunner:
    """A thread pool with ``map`` (default ``workers``: the number of CPUs)."""

    def __init__(self, workers: int | None = None):
        if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
            raise ParameterError(f"runner: workers must be a positive integer, got {workers!r}")
        self.workers = workers or os.cpu_count() or 1

    def map(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> list[Any]:
        with concurrent.futures.ThreadPoolExecutor(self.workers) as ex:
            return list(ex.map(fn, items))

    def __repr__(self) -> str:
        return f"ThreadRunner({self.workers})"


class _Failure:
    """A task the runner lost (its message)."""

    def __init__(self, message: str):
        self.message = message


class Mapper:
    """Adapts a runner: ``run(fn, items)`` returns one entry per item, in order: the task's
    result, or a :class:`_Failure` if the runner lost it. ``close()`` shuts down what it started."""

    def __init__(self, runner: Any, owned: bool = False, retries: int = 2, in_process: bool = False,
                 factory: Callable[[], Any] | None = None, workers: int = 1):
        self.runner = runner
        self.owned = owned
        self.retries = retries
        self.in_process = in_process
        #: Makes a new process pool when the current one broke (``"processes:N"`` only).
        self.factory = factory
        self.workers = workers
        self._scattered: tuple[Any, Any] | None = None
        self._pool_ok = False  # a task of this pool (or one it replaced) finished
        mod = type(runner).__module__
        self.is_dask = mod.startswith("distributed") and hasattr(runner, "submit") and hasattr(runner, "gather")

    def run(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> list[Any]:
        if self.is_dask:
            return self._run_dask(fn, items)
        if isinstance(self.runner, RayTasks):
            return self.runner.run(fn, items)
        if self.factory is not None:
            return self._run_pool(fn, items)
        out: list[Any] = []
        try:
            for r in self.runner.map(fn, items):
                out.append(r)
        except Exception as exc:  # noqa: BLE001 - the runner lost the remaining tasks
            msg = f"{RUNNER_FAILED}: {type(exc).__name__}: {exc}"
            out += [_Failure(msg)] * (len(items) - len(out))
        return out

    def _replace_pool(self) -> None:
        assert self.factory is not None
        self.runner.shutdown(wait=False, cancel_futures=True)
        self.runner = self.factory()

    def _run_alone(self, fn: Callable[[Any], Any], item: Any) -> Any:
        """Run one task on the pool with nothing else in it: if the pool breaks, this task did it."""
        try:
            result = self.runner.submit(fn, item).result()
        except concurrent.futures.BrokenExecutor as exc:
            self._replace_pool()
            return _Failure(f"{RUNNER_FAILED}: {type(exc).__name__}: the worker process died while it evaluated "
                            "this task alone (killed by a signal, e.g. a crash in native code or the "
                            "out-of-memory killer, or it exited)")
        except Exception as exc:  # noqa: BLE001 - the task could not be sent or its result returned
            return _Failure(f"{RUNNER_FAILED}: {type(exc).__name__}: {exc}")
        self._pool_ok = True
        return result

    def _run_pool(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> list[Any]:
        """A process pool that rvdyn owns. A worker that dies breaks the pool and fails every
        task in it: the pool is replaced and those tasks run again one at a time, so that only
        the task that kills its worker fails. At most 2 tasks per worker are in the pool, so a
        crash costs at most that many single runs."""
        from collections import deque

        out: list[Any] = [None] * len(items)
        pending = deque(range(len(items)))
        inflight: dict[Any, int] = {}
        window = 2 * self.workers
        while pending or inflight:
            while pending and len(inflight) < window:
                try:
                    inflight[self.runner.submit(fn, items[pending[0]])] = pending[0]
                except concurrent.futures.BrokenExecutor:
                    break  # broke meanwhile: the tasks in it fail now and are handled below
                pending.popleft()
            if not inflight:  # broken with no task of ours in it
                self._replace_pool()
                continue
            done, _ = concurrent.futures.wait(inflight, return_when=concurrent.futures.FIRST_COMPLETED)
            if any(isinstance(f.exception(), concurrent.futures.BrokenExecutor) for f in done):
                # The pool is broken: every task still in it ends now, finished or lost.
                concurrent.futures.wait(inflight)
                done = set(inflight)
            lost: list[int] = []
            for f in done:
                i = inflight.pop(f)
                exc = f.exception()
                if exc is None:
                    out[i] = f.result()
                    self._pool_ok = True
                elif isinstance(exc, concurrent.futures.BrokenExecutor):
                    lost.append(i)
                else:
                    out[i] = _Failure(f"{RUNNER_FAILED}: {type(exc).__name__}: {exc}")
            if not lost:
                continue
            self._replace_pool()
            crashes = 0
            for k, i in enumerate(sorted(lost)):
                out[i] = self._run_alone(fn, items[i])
                crashes = crashes + 1 if isinstance(out[i], _Failure) else 0
                if crashes >= 3 and not self._pool_ok:
                    # No task has ever finished on these pools: the workers cannot start (a main
                    # script without `if __name__ == '__main__':`, ...), not a sample's fault.
                    msg = f"{RUNNER_FAILED}: BrokenProcessPool: no worker process of the pool could run a task"
                    for j in sorted(lost)[k + 1:] + list(pending):
                        out[j] = _Failure(msg)
                    pending.clear()
                    break
        return out

    def _submit(self, fn: Callable[[Any], Any], items: Sequence[Any], inline: bool = False) -> list[Any]:
        if not inline and isinstance(fn, functools.partial) and len(fn.args) == 1 and not fn.keywords:
            # Send the shared task (scene, kernel, layout) to every worker once, not with each item.
            if self._scattered is None or self._scattered[0] is not fn.args[0]:
                [fut] = self.runner.scatter([fn.args[0]], broadcast=True, hash=False)
                self._scattered = (fn.args[0], fut)
            return list(self.runner.map(fn.func, [self._scattered[1]] * len(items), list(items), pure=False,
                                        retries=self.retries))
        return list(self.runner.map(fn, list(items), pure=False, retries=self.retries))

    def _run_dask(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> list[Any]:
        from distributed import wait  # type: ignore[import-untyped, import-not-found, unused-ignore]

        out: list[Any] = [None] * len(items)
        pending = list(range(len(items)))
        # Up to three rounds: a task cancelled because the shared task was lost, or finished
        # on a worker that died before its result was fetched, runs again; a task whose own
        # retries ran out (KilledWorker: it kills its worker) does not.
        for attempt in range(3):
            # The second round sends the shared task with each item: a worker that dies then takes
            # only its own task along, not the copies every other task depends on.
            futures = self._submit(fn, [items[i] for i in pending], inline=attempt > 0)
            try:
                wait(futures)  # type: ignore[no-untyped-call, unused-ignore]
            except Exception:  # noqa: BLE001 - cancelled futures; each one's status says which
                pass
            # One gather for the finished tasks; a result lost meanwhile (its worker died) is
            # fetched, or found missing, one by one.
            done = [f for f in futures if f.status == "finished"]
            try:
                got = dict(zip((f.key for f in done), self.runner.gather(done, errors="raise")))
            except Exception:  # noqa: BLE001
                got = {}
            again: list[int] = []
            for i, f in zip(pending, futures):
                if f.key in got:
                    out[i] = got[f.key]
                    continue
                if f.status == "finished":
                    try:
                        out[i] = f.result()
                        continue
                    except Exception:  # noqa: BLE001 - lost with its worker: as a cancelled one
                        pass
                if f.status != "error" and attempt < 2:
                    # Its input was lost with the workers that held it (a worker that died took
                    # the shared task's copies along): once more.
                    again.append(i)
                else:
                    try:  # retries exhausted (KilledWorker, ...) or cancelled twice
                        exc = f.exception()
                        out[i] = _Failure(f"runner failed: {type(exc).__name__}: {exc}" if exc is not None else
                                          f"runner failed: task {f.status} (a worker died with it or its input)")
                    except BaseException as err:  # noqa: BLE001 - CancelledError is a BaseException
                        out[i] = _Failure(f"runner failed: {type(err).__name__}: {err}")
            del futures, done, got
            if not again:
                break
            pending = again
        return out

    def close(self) -> None:
        self._scattered = None
        if not self.owned:
            return
        if isinstance(self.runner, RayTasks):
            self.runner.close()
            return
        # A Dask client is closed, never shut down (that would stop a shared cluster).
        for name in (("close",) if self.is_dask else ("shutdown", "close")):
            method = getattr(self.runner, name, None)
            if method is not None:
                method()
                break


def _dask_client(address: str, timeout: float) -> Any:
    try:
        from distributed import Client  # type: ignore[import-untyped, import-not-found, unused-ignore]
    except ImportError:
        raise ParameterError(f"runner {address!r} needs Dask: pip install 'rvdyn[dask]'") from None
    try:
        return Client(address, timeout=f"{timeout}s")  # type: ignore[no-untyped-call, unused-ignore]
    except (OSError, TimeoutError) as exc:
        raise ParameterError(f"runner: no Dask scheduler answers at {address!r} within {timeout:g} s ({exc})") from None


def _call_with(func: Callable[[Any, Any], Any], shared: Any, item: Any) -> Any:
    """``func(shared, item)``: the body of a Ray task (top level, so Ray pickles it by name)."""
    return func(shared, item)


def _call(fn: Callable[[Any], Any], item: Any) -> Any:
    return fn(item)


class RayTasks:
    """The ``"ray"`` runners: each task is a Ray task (one CPU), retried ``retries`` times when
    its worker process dies, as the Dask path does; a task whose retries run out (it kills its
    worker) is a :class:`_Failure` of its own and the other tasks are not affected. (A
    ``ray.util.multiprocessing.Pool`` loses a whole ``map`` when one of its actors dies.)"""

    def __init__(self, ray: Any, retries: int, started: bool):
        self.ray = ray
        self.started = started
        self._with = ray.remote(num_cpus=1, max_retries=retries)(_call_with)
        self._plain = ray.remote(num_cpus=1, max_retries=retries)(_call)

    def run(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> list[Any]:
        ray = self.ray
        if isinstance(fn, functools.partial) and len(fn.args) == 1 and not fn.keywords:
            shared = ray.put(fn.args[0])  # the scene, kernel and layout once, not with each task
            refs = [self._with.remote(fn.func, shared, item) for item in items]
        else:
            refs = [self._plain.remote(fn, item) for item in items]
        out: list[Any] = []
        for ref in refs:
            try:
                out.append(ray.get(ref))
            except Exception as exc:  # noqa: BLE001 - this task only (WorkerCrashedError, ...)
                first = (str(exc).strip().splitlines() or [""])[0][:300]
                out.append(_Failure(f"{RUNNER_FAILED}: {type(exc).__name__}: {first}"))
        return out

    def close(self) -> None:
        if self.started:
            self.ray.shutdown()

    def __repr__(self) -> str:
        return "RayTasks()"


def _ray_tasks(address: str | None, workers: int | None, retries: int) -> RayTasks:
    try:
        import ray  # type: ignore[import-untyped, import-not-found, unused-ignore]
    except ImportError:
        raise ParameterError("runner 'ray' needs Ray: pip install 'rvdyn[ray]'") from None
    started = False
    try:
        if not ray.is_initialized():
            ray.init(address=address, num_cpus=None if address else workers, include_dashboard=False,
                     log_to_driver=False)
            started = True
        return RayTasks(ray, retries, started)
    except (ConnectionError, TimeoutError, RuntimeError, ValueError) as exc:
        raise ParameterError(f"runner: no Ray cluster answers at {address!r} ({exc})") from None


def _workers(spec: str, text: str) -> int | None:
    if not text:
        return None
    if not text.isdigit() or int(text) < 1:
        raise ParameterError(f"runner {spec!r}: the worker count must be a positive integer")
    return int(text)


def resolve_runner(runner: Any, retries: int = 2, timeout: float = 10.0) -> Mapper:
    """A :class:`Mapper` for ``runner``: None / int (threads), a string (see the module
    docstring), or any object with ``map``."""
    if runner is None:
        return Mapper(ThreadRunner(), owned=True, in_process=True)
    if isinstance(runner, (int, np.integer)) and not isinstance(runner, bool):
        return Mapper(ThreadRunner(int(runner)), owned=True, in_process=True)
    if isinstance(runner, str):
        kind, _, rest = runner.partition(":")
        if kind == "threads":
            return Mapper(ThreadRunner(_workers(runner, rest)), owned=True, in_process=True)
        if kind == "processes":
            import multiprocessing

            n = _workers(runner, rest) or os.cpu_count() or 1

            def pool() -> concurrent.futures.ProcessPoolExecutor:
                return concurrent.futures.ProcessPoolExecutor(n, mp_context=multiprocessing.get_context("spawn"))

            return Mapper(pool(), owned=True, retries=retries, factory=pool, workers=n)
        if kind in ("tcp", "tls", "ucx", "inproc"):
            return Mapper(_dask_client(runner, timeout), owned=True, retries=retries)
        if kind == "ray":
            address = runner if rest.startswith("//") else None
            workers = None if rest.startswith("//") else _workers(runner, rest)
            return Mapper(_ray_tasks(address, workers, retries), owned=True, retries=retries)
        raise ParameterError(f"runner {runner!r}: use 'threads[:N]', 'processes[:N]', a Dask address "
                             "'tcp://host:port', 'ray[:N]' or 'ray://host:port', or an object with map()")
    if not callable(getattr(runner, "map", None)):
        raise ParameterError(f"runner must have a map(fn, items) method (a thread pool, executor, Dask client, "
                             f"Ray pool), got {type(runner).__name__}")
    in_process = isinstance(runner, (ThreadRunner, concurrent.futures.ThreadPoolExecutor))
    return Mapper(runner, owned=False, retries=retries, in_process=in_process)


def check_picklable(task: Task) -> None:
    """Raise a clear error if a task cannot be sent to another process."""
    try:
        pickle.dumps(functools.partial(evaluate_batch, task))
    except Exception as exc:  # noqa: BLE001
        raise ParameterError(f"kernel {task.kernel!r} cannot be sent to worker processes (pickle: {exc}); "
                             "use a top-level function or a kernel name") from None
