"""Seeded samplers: Monte Carlo and Latin hypercube designs over expanded tolerances.

Every design is drawn in the calling process from the seed alone, before any task runs, so the
same seed gives the same samples whatever the runner (threads, processes, a cluster).

A sampler gives uniform quantiles u in (0, 1), shape (n, d). Correlated groups go through a
Gaussian copula: z = Phi^-1(u), z_g <- L z_g (L the Cholesky factor of the group's
correlation matrix), u_g = Phi(z_g). Each variable's value is then its inverse distribution
function at u (:meth:`rvdyn.study.spec.Variable.ppf`).

* :class:`MonteCarlo`: independent uniforms from ``numpy.random.default_rng(seed)`` (PCG64).
* :class:`LatinHypercube`: scipy.stats.qmc.LatinHypercube (McKay, Beckman & Conover 1979),
  one point in each of n equal-probability strata of every variable. The copula keeps the
  stratification of uncorrelated variables only.
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError
from .spec import Layout

__all__ = ["MonteCarlo", "LatinHypercube", "Sampler", "as_sampler", "design"]

# Quantiles are kept inside [EPS, 1 - EPS] so that Phi^-1 stays finite.
_EPS = 2.0**-53


def _count(n: Any) -> int:
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ParameterError(f"samples must be a positive integer, got {n!r}")
    return int(n)


@dataclass(frozen=True)
class MonteCarlo:
    """``n`` independent random samples (simple Monte Carlo)."""

    n: int

    def uniforms(self, d: int, seed: int | None) -> np.ndarray:
        """Uniforms (n, d) in [0, 1)."""
        return np.random.default_rng(seed).random((_count(self.n), d))


@dataclass(frozen=True)
class LatinHypercube:
    """``n``-point Latin hypercube (scrambled: random positions inside the strata)."""

    n: int

    def uniforms(self, d: int, seed: int | None) -> np.ndarray:
        """Uniforms (n, d) in [0, 1)."""
        from scipy.stats import qmc  # type: ignore[import-untyped, import-not-found, unused-ignore]

        n = _count(self.n)
        rng = np.random.default_rng(seed)
        # SciPy >= 1.15 names the generator argument `rng`; older versions call it `seed`.
        key = "rng" if "rng" in inspect.signature(qmc.LatinHypercube).parameters else "seed"
        return np.asarray(qmc.LatinHypercube(d, **{key: rng}).random(n))


Sampler = MonteCarlo | LatinHypercube


def as_sampler(samples: Any) -> Any:
    """``samples`` as a sampler: an int n means ``MonteCarlo(n)``; an object with
    ``uniforms(d, seed)`` and ``n`` is used as is; ``"lhs:N"`` / ``"mc:N"`` strings too."""
    if isinstance(samples, str):
        kind, _, n = samples.partition(":")
        kinds = {"mc": MonteCarlo, "monte-carlo": MonteCarlo, "lhs": LatinHypercube, "latin-hypercube": LatinHypercube}
        if kind not in kinds or not n.isdigit():
            raise ParameterError(f"samples {samples!r}: use 'mc:N' or 'lhs:N', an int, or a sampler object")
        return kinds[kind](int(n))
    if isinstance(samples, (int, np.integer)) and not isinstance(samples, bool):
        return MonteCarlo(_count(samples))
    if hasattr(samples, "uniforms") and hasattr(samples, "n"):
        _count(samples.n)
        return samples
    raise ParameterError(f"samples must be a sample count or a sampler (MonteCarlo, LatinHypercube), got {samples!r}")


def design(layout: Layout, sampler: Any, seed: int | None) -> np.ndarray:
    """Values (n, d) of every variable for every sample [field units], from the seed alone."""
    from scipy.special import ndtr, ndtri  # type: ignore[import-untyped, import-not-found, unused-ignore]

    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0):
        raise ParameterError(f"seed must be a non-negative integer (or None), got {seed!r}")
    d = len(layout.variables)
    u: np.ndarray = np.array(sampler.uniforms(d, seed), dtype=float)
    if u.ndim != 2 or u.shape[1] != d or not np.all((u >= 0) & (u <= 1)):
        raise ParameterError(f"sampler {sampler!r} must give uniforms in [0, 1] of shape (n, {d})")
    np.clip(u, _EPS, 1.0 - _EPS, out=u)
    for cols, chol in layout.groups:
        z = ndtri(u[:, cols])
        u[:, cols] = np.clip(ndtr(z @ chol.T), _EPS, 1.0 - _EPS)
    for j, var in enumerate(layout.variables):  # in place: the design is the largest array of a study
        u[:, j] = var.ppf(u[:, j])
    return u
