"""Tolerance studies: seeded Monte Carlo / Latin hypercube samples of a scene's toleranced
fields, evaluated by a kernel (a dynamic run reduced to metrics, ...) on threads, processes or
a Dask / Ray cluster, streamed to Parquet, with statistics and plots.

``rvdyn.study(...)`` is :func:`run` (this module is callable)::

    import rvdyn
    from rvdyn.study import Tolerance, Criterion, LatinHypercube

    table = rvdyn.study(rvdyn.Scene.paper("rated"), "dynamic",
                        tolerances=[Tolerance("cycloid.d_rrp", tol=1e-5),
                                    Tolerance("pin_errors.radius", tol=5e-6, dist="uniform")],
                        samples=LatinHypercube(200), seed=1, runner="processes:2",
                        kernel_options={"t_end": 0.5}, out="study.parquet")
    rvdyn.study.yield_rate(table, [Criterion("peak_pin_force", max=2e5)])
    rvdyn.study.src(table, "peak_pin_force").top(3)

Modules: :mod:`.spec` (tolerances, correlations, criteria), :mod:`.sampling`,
:mod:`.kernels`, :mod:`.runners`, :mod:`.storage`, :mod:`.stats`, :mod:`.plots`,
:mod:`.config` (the ``rvdyn study spec.toml`` command).
"""

from __future__ import annotations

import sys
import types
from typing import Any

from .driver import run
from .kernels import (DYNAMIC_METRICS, KERNELS, LTCA_BEARING_METRICS, LTCA_CRANK_METRICS, LTCA_METRICS, DynamicKernel,
                      FunctionKernel, LtcaKernel, get_kernel, register_kernel)
from .plots import plot_histogram, plot_sensitivity
from .runners import RUNNER_FAILED, RunnerError, RunnerFailureWarning, ThreadRunner, evaluate, evaluate_batch
from .sampling import LatinHypercube, MonteCarlo, design
from .spec import Correlation, Criterion, Tolerance, expand
from .stats import Interval, Sensitivity, YieldResult, describe, sobol, src, yield_rate
from .storage import read

__all__ = [
    "run", "read", "Tolerance", "Correlation", "Criterion", "MonteCarlo", "LatinHypercube", "design", "expand",
    "DynamicKernel", "LtcaKernel", "FunctionKernel", "KERNELS", "DYNAMIC_METRICS", "LTCA_METRICS", "LTCA_BEARING_METRICS",
    "LTCA_CRANK_METRICS",
    "register_kernel",
    "get_kernel",
    "RunnerError", "RunnerFailureWarning", "RUNNER_FAILED", "ThreadRunner", "evaluate", "evaluate_batch",
    "describe", "yield_rate", "src", "sobol", "Interval",
    "YieldResult", "Sensitivity", "plot_histogram", "plot_sensitivity",
]


class _CallableModule(types.ModuleType):
    """Makes ``rvdyn.study(...)`` a shortcut for ``rvdyn.study.run(...)``."""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return run(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
