"""Tolerance specifications, correlated groups and pass criteria, validated against a scene.

A :class:`Tolerance` names one scene field by its dotted path (``"cycloid.d_rrp"``,
``"pin_errors.radius"``, ``"discs.1.d_rp"``, ...) and the band of its deviation from the
nominal value. The spec is generic over paths: any numeric field (or numeric list field) that
the scene has can be toleranced, so error fields added to the scene later work unchanged.

Band convention: the deviation lies in ``[lower, upper]`` (SI units of the field; ``tol=t`` is
the symmetric band ``[-t, +t]``).

* ``dist="normal"``: mean = band centre, standard deviation sigma = (upper - lower) / 6, i.e.
  the band is +-3 sigma (band = 6 sigma, process capability Cp = 1; about 0.27 % of the parts
  fall outside the band, the normal is not truncated).
* ``dist="truncnorm"``: the same normal truncated to the band (``scipy.stats.truncnorm`` at
  +-3 sigma): parts outside the band are rejected by inspection, so no sample leaves it.
* ``dist="uniform"``: uniform on ``[lower, upper]``.

A list field (one value per pin, ...) is toleranced element by element: each element is an
independent variable with the same band (input columns ``"<path>.<i>"``), unless a
:class:`Correlation` ties them together.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from ..errors import ParameterError, SceneError
from ..scene import Scene

__all__ = ["Tolerance", "Correlation", "Criterion", "Variable", "DISTRIBUTIONS", "expand", "check_criteria",
           "apply_values", "nominal_scene"]

#: Distributions a :class:`Tolerance` accepts.
DISTRIBUTIONS = ("normal", "truncnorm", "uniform")

# List fields that are empty in a scene until set, with the shape they take (as scene paths or
# numbers): an empty list means "no errors", i.e. zeros of this shape.
_EMPTY_LIST_SHAPES: dict[str, Callable[[Scene], tuple[int, ...]]] = {
    "pin_errors.radius": lambda s: (int(s["cycloid.pins"]),),
    "pin_errors.position": lambda s: (int(s["cycloid.pins"]), 2),
    "errors.crank_eccentricity": lambda s: (int(s["cranks"]),),
    "errors.crank_phase": lambda s: (int(s["cranks"]),),
    "errors.disc_holes": lambda s: (int(s["cranks"]) * len(s["discs"]), 2),
    "errors.carrier_seats": lambda s: (int(s["cranks"]), 2),
}


def _is_number(value: Any) -> bool:
    """A real number: int or float (numpy's too), not a bool or a string such as "1e-5"."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def _finite(name: str, what: str, value: Any) -> float:
    if not _is_number(value):
        raise ParameterError(f"tolerance {name!r}: {what} must be a number [field units], got {value!r}"
                             + (" (true/false is not a number)" if isinstance(value, (bool, np.bool_)) else ""))
    v = float(value)
    if not math.isfinite(v):
        raise ParameterError(f"tolerance {name!r}: {what} must be finite, got {v}")
    return v


@dataclass(frozen=True)
class Tolerance:
    """Tolerance of one scene field (SI units of that field).

    path: dotted scene path. tol: symmetric band half-width (deviation in [-tol, +tol]), or
    lower/upper: the deviation band. dist: ``"normal"`` (band = 6 sigma), ``"truncnorm"`` (the
    same normal truncated to the band: inspected parts) or ``"uniform"``.
    shape: shape of a list field that is empty in the scene (inferred for the known ones, e.g.
    ``pin_errors.radius`` -> (pins,)). nominal: value the deviation is added to, for fields
    that are null in the scene (``discs.<k>.d_rp`` etc. default to ``cycloid.<name>``).
    """

    path: str
    tol: float | None = None
    lower: float | None = None
    upper: float | None = None
    dist: str = "normal"
    shape: tuple[int, ...] | None = None
    nominal: Any = None

    def band(self) -> tuple[float, float]:
        """The validated deviation band (lower, upper)."""
        if not isinstance(self.path, str) or not self.path:
            raise ParameterError(f"a tolerance path must be a non-empty dotted string, got {self.path!r}")
        name = self.path
        if self.tol is not None:
            if self.lower is not None or self.upper is not None:
                raise ParameterError(f"tolerance {name!r}: give either tol or lower/upper, not both")
            t = _finite(name, "tol", self.tol)
            if t < 0:
                raise ParameterError(f"tolerance {name!r}: tol must be >= 0 (a band half-width), got {t}")
            lo, hi = -t, t
        else:
            if self.lower is None or self.upper is None:
                raise ParameterError(f"tolerance {name!r}: give tol (symmetric band) or both lower and upper")
            lo, hi = _finite(name, "lower", self.lower), _finite(name, "upper", self.upper)
            if hi < lo:
                raise ParameterError(f"tolerance {name!r}: the band is negative (upper {hi} < lower {lo})")
        if self.dist not in DISTRIBUTIONS:
            raise ParameterError(f"tolerance {name!r}: dist must be one of {DISTRIBUTIONS}, got {self.dist!r}")
        return lo, hi


@dataclass(frozen=True)
class Correlation:
    """Correlated tolerances: the listed paths (list fields expand to all their elements, in
    order) are drawn with the correlation ``matrix`` (square, symmetric positive definite, unit
    diagonal), or with one coefficient ``rho`` between every pair.

    Correlation is imposed with a Gaussian copula: correlated standard normals z = L u (L the
    Cholesky factor of the matrix) are mapped to each variable's distribution. For normal
    variables the Pearson correlation is the given one; for uniform ones it is
    (6 / pi) asin(rho / 2) (Kruskal 1958)."""

    paths: tuple[str, ...]
    rho: float | None = None
    matrix: Any = None


@dataclass(frozen=True)
class Criterion:
    """Pass criterion on one metric: ``min <= value <= max`` (either bound may be omitted)."""

    metric: str
    max: float | None = None
    min: float | None = None

    def check(self) -> None:
        if not isinstance(self.metric, str) or not self.metric:
            raise ParameterError(f"a criterion needs a metric name, got {self.metric!r}")
        if self.max is None and self.min is None:
            raise ParameterError(f"criterion on {self.metric!r}: give max and/or min")
        for what, v in (("max", self.max), ("min", self.min)):
            if v is None:
                continue
            if not _is_number(v):
                # A string such as "1e5" passed float() here and failed after the whole study
                # had run, when the values were compared with it.
                raise ParameterError(f"criterion on {self.metric!r}: {what} must be a number, got {v!r}"
                                     + (" (write it without quotes)" if isinstance(v, str) else ""))
            if not math.isfinite(float(v)):
                raise ParameterError(f"criterion on {self.metric!r}: {what} must be finite, got {v!r}")
        if self.max is not None and self.min is not None and float(self.min) > float(self.max):
            raise ParameterError(
                f"criterion on {self.metric!r}: min {self.min} is above max {self.max}, so no value passes")

    def passes(self, values: np.ndarray) -> np.ndarray:
        """Boolean mask of values meeting the criterion (NaN, i.e. a failed sample, fails)."""
        ok: np.ndarray = np.isfinite(values)
        if self.max is not None:
            ok &= values <= self.max
        if self.min is not None:
            ok &= values >= self.min
        return ok

    def label(self) -> str:
        parts = []
        if self.min is not None:
            parts.append(f"{self.min:g} <=")
        parts.append(self.metric)
        if self.max is not None:
            parts.append(f"<= {self.max:g}")
        return " ".join(parts)


@dataclass(frozen=True)
class Variable:
    """One scalar random input: ``column`` (table column), the tolerance ``path`` it belongs to,
    the ``index`` inside a list field (() for a scalar), the nominal value, the band and the
    distribution."""

    column: str
    path: str
    index: tuple[int, ...]
    nominal: float
    lower: float
    upper: float
    dist: str

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """Values [field units] for uniform quantiles ``u`` in (0, 1)."""
        from scipy.special import ndtri  # type: ignore[import-untyped, import-not-found, unused-ignore]

        if self.dist == "uniform":
            dev = self.lower + (self.upper - self.lower) * u
        elif self.dist == "truncnorm" and self.upper > self.lower:
            dev = np.asarray(self.scipy_dist().ppf(u), dtype=float) - self.nominal
        else:
            dev = 0.5 * (self.lower + self.upper) + (self.upper - self.lower) / 6.0 * ndtri(u)
        return self.nominal + dev

    def scipy_dist(self) -> Any:
        """The frozen scipy.stats distribution of this variable's value."""
        from scipy import stats  # type: ignore[import-untyped, import-not-found, unused-ignore]

        if self.dist == "uniform":
            return stats.uniform(loc=self.nominal + self.lower, scale=self.upper - self.lower)
        if self.dist == "truncnorm":
            return stats.truncnorm(-3.0, 3.0, loc=self.nominal + 0.5 * (self.lower + self.upper),
                                   scale=(self.upper - self.lower) / 6.0)
        return stats.norm(loc=self.nominal + 0.5 * (self.lower + self.upper), scale=(self.upper - self.lower) / 6.0)


@dataclass
class Layout:
    """Expanded variables of a set of tolerances and the correlation groups (column indices)."""

    tolerances: list[Tolerance]
    variables: list[Variable]
    groups: list[tuple[list[int], np.ndarray]] = field(default_factory=list)
    shapes: dict[str, tuple[int, ...]] = field(default_factory=dict)
    nominals: dict[str, Any] = field(default_factory=dict)

    @property
    def columns(self) -> list[str]:
        return [v.column for v in self.variables]


def _resolve_shape(scene: Scene, path: str, tol: Tolerance, value: Any) -> tuple[int, ...] | None:
    if tol.shape is not None:
        try:
            shape = tuple(int(s) for s in tol.shape)
        except (TypeError, ValueError):
            raise ParameterError(f"tolerance {path!r}: shape must be a tuple of ints, got {tol.shape!r}") from None
        if any(s < 1 for s in shape):
            raise ParameterError(f"tolerance {path!r}: shape entries must be >= 1, got {shape}")
        return shape
    if isinstance(value, list):
        if value:
            arr = np.asarray(value, dtype=float)
            return tuple(arr.shape)
        rule = _EMPTY_LIST_SHAPES.get(path)
        if rule is None:
            raise ParameterError(f"tolerance {path!r}: the scene's list is empty; give its shape=(...)")
        return rule(scene)
    return None


def _nominal(scene: Scene, path: str, tol: Tolerance) -> Any:
    try:
        value = scene[path]
    except SceneError as exc:
        raise ParameterError(f"tolerance path {path!r}: {exc}") from None
    if tol.nominal is not None:
        return tol.nominal
    if value is None:
        parts = path.split(".")
        if len(parts) == 3 and parts[0] == "discs":  # per-disc modification defaults to the cycloid's
            try:
                return scene[f"cycloid.{parts[2]}"]
            except SceneError:
                pass
        raise ParameterError(f"tolerance {path!r}: the scene's value is null; give nominal=")
    if isinstance(value, bool) or not isinstance(value, (int, float, list)):
        raise ParameterError(f"tolerance {path!r}: the field is not numeric (value {value!r})")
    return value


def expand(scene: Scene, tolerances: Sequence[Tolerance | dict[str, Any]],
           correlations: Sequence[Correlation | dict[str, Any]] = ()) -> Layout:
    """Validate ``tolerances`` (and ``correlations``) against ``scene`` and expand them into
    scalar :class:`Variable` s. Raises :class:`rvdyn.ParameterError` naming the field."""
    if isinstance(tolerances, (Tolerance, dict)):
        tolerances = [tolerances]
    tols = [t if isinstance(t, Tolerance) else _tolerance_from_dict(t) for t in tolerances]
    if not tols:
        raise ParameterError("tolerances: give at least one Tolerance")
    seen: set[str] = set()
    layout = Layout(tolerances=tols, variables=[])
    for tol in tols:
        lo, hi = tol.band()
        path = tol.path
        if path in seen:
            raise ParameterError(f"tolerance {path!r} is given twice")
        seen.add(path)
        nominal = _nominal(scene, path, tol)
        shape = _resolve_shape(scene, path, tol, nominal)
        if shape is None:
            try:
                nom = float(nominal)
            except (TypeError, ValueError):
                raise ParameterError(f"tolerance {path!r}: nominal must be a number, got {nominal!r}") from None
            layout.variables.append(Variable(path, path, (), nom, lo, hi, tol.dist))
            layout.nominals[path] = nom
            continue
        base = np.asarray(nominal, dtype=float) if isinstance(nominal, list) and nominal else None
        if base is None:
            base = np.zeros(shape) if not isinstance(nominal, (int, float)) else np.full(shape, float(nominal))
        if base.shape != shape:
            raise ParameterError(f"tolerance {path!r}: shape {shape} does not match the scene's {base.shape}")
        layout.shapes[path] = shape
        layout.nominals[path] = base
        for idx in np.ndindex(*shape):
            col = path + "".join(f".{i}" for i in idx)
            layout.variables.append(Variable(col, path, tuple(int(i) for i in idx), float(base[idx]), lo, hi, tol.dist))
    # Check that the nominal scene with every toleranced field set is a valid scene.
    try:
        apply_values(scene, layout, np.array([v.nominal for v in layout.variables]))
    except (SceneError, ValueError) as exc:
        raise ParameterError(f"tolerances: the scene does not accept the toleranced fields: {exc}") from None
    for c in correlations:
        layout.groups.append(_group(layout, c if isinstance(c, Correlation) else _correlation_from_dict(c)))
    used: set[int] = set()
    for cols, _ in layout.groups:
        if used & set(cols):
            raise ParameterError("correlations: a tolerance belongs to two correlation groups; merge them")
        used |= set(cols)
    return layout


def _group(layout: Layout, c: Correlation) -> tuple[list[int], np.ndarray]:
    paths = [c.paths] if isinstance(c.paths, str) else list(c.paths)
    cols: list[int] = []
    for p in paths:
        idx = [i for i, v in enumerate(layout.variables) if v.path == p or v.column == p]
        if not idx:
            raise ParameterError(f"correlation: {p!r} is not a toleranced path")
        cols += idx
    if len(set(cols)) != len(cols):
        raise ParameterError(f"correlation {paths}: a path is listed twice")
    n = len(cols)
    if (c.rho is None) == (c.matrix is None):
        raise ParameterError(f"correlation {paths}: give rho or matrix (one of them)")
    if c.rho is not None:
        if not _is_number(c.rho):
            raise ParameterError(f"correlation {paths}: rho must be a number in (-1/(n-1), 1) = "
                                 f"({-1.0 / max(n - 1, 1):.4g}, 1) for {n} variables, got {c.rho!r}")
        rho = float(c.rho)
        if not (math.isfinite(rho) and -1.0 / max(n - 1, 1) < rho < 1.0):
            raise ParameterError(f"correlation {paths}: rho must lie in (-1/(n-1), 1) = ({-1.0 / max(n - 1, 1):.4g}, 1) "
                                 f"for {n} variables, got {c.rho}")
        m = np.full((n, n), rho)
        np.fill_diagonal(m, 1.0)
    else:
        rows = c.matrix.tolist() if isinstance(c.matrix, np.ndarray) else c.matrix
        if (not isinstance(rows, (list, tuple)) or len(rows) != n
                or any(not isinstance(r, (list, tuple)) or len(r) != n for r in rows)):
            raise ParameterError(f"correlation {paths}: matrix must be {n}x{n}, a list of {n} rows of {n} numbers "
                                 f"(one row and column per variable), got {c.matrix!r}")
        if not all(_is_number(x) for r in rows for x in r):
            raise ParameterError(f"correlation {paths}: matrix entries must be numbers, got {c.matrix!r}")
        m = np.array(rows, dtype=float)
        if m.shape != (n, n):
            raise ParameterError(f"correlation {paths}: matrix must be {n}x{n} (one row per variable), got {m.shape}")
        if not np.all(np.isfinite(m)) or not np.allclose(m, m.T) or not np.allclose(np.diag(m), 1.0):
            raise ParameterError(f"correlation {paths}: matrix must be finite, symmetric, with unit diagonal")
    try:
        chol = np.linalg.cholesky(m)
    except np.linalg.LinAlgError:
        raise ParameterError(f"correlation {paths}: matrix is not positive definite") from None
    return cols, chol


_TOL_KEYS = {"path", "tol", "lower", "upper", "dist", "shape", "nominal"}


def _tolerance_from_dict(d: dict[str, Any]) -> Tolerance:
    if not isinstance(d, dict):
        raise ParameterError(f"a tolerance is a Tolerance or a dict, got {type(d).__name__}")
    extra = set(d) - _TOL_KEYS
    if extra:
        raise ParameterError(f"tolerance {d.get('path')!r}: unknown keys {sorted(extra)} (known: {sorted(_TOL_KEYS)})")
    if "path" not in d:
        raise ParameterError(f"tolerance {d!r}: missing 'path'")
    shape = d.get("shape")
    return Tolerance(path=d["path"], tol=d.get("tol"), lower=d.get("lower"), upper=d.get("upper"),
                     dist=d.get("dist", "normal"), shape=None if shape is None else tuple(shape),
                     nominal=d.get("nominal"))


def _correlation_from_dict(d: dict[str, Any]) -> Correlation:
    if not isinstance(d, dict):
        raise ParameterError(f"a correlation is a Correlation or a dict, got {type(d).__name__}")
    extra = set(d) - {"paths", "rho", "matrix"}
    if extra or "paths" not in d:
        raise ParameterError(f"correlation {d!r}: needs 'paths' and 'rho' or 'matrix' (unknown keys {sorted(extra)})")
    if not isinstance(d["paths"], (str, list, tuple)) or not all(isinstance(x, str) for x in
                                                                 ([d["paths"]] if isinstance(d["paths"], str) else d["paths"])):
        raise ParameterError(f"correlation {d!r}: paths must be a list of toleranced paths (strings), "
                             f"got {d['paths']!r}")
    return Correlation(paths=tuple(d["paths"]) if not isinstance(d["paths"], str) else (d["paths"],),
                       rho=d.get("rho"), matrix=d.get("matrix"))


def criterion_from_dict(d: dict[str, Any]) -> Criterion:
    """A :class:`Criterion` from ``{"metric": ..., "max": ..., "min": ...}``."""
    if not isinstance(d, dict) or "metric" not in d or set(d) - {"metric", "max", "min"}:
        raise ParameterError(f"a criterion is {{metric, max, min}}, got {d!r}")
    return Criterion(metric=d["metric"], max=d.get("max"), min=d.get("min"))


def check_criteria(criteria: Sequence[Criterion | dict[str, Any]], metrics: Sequence[str] | None) -> list[Criterion]:
    """Validate criteria; with ``metrics`` known, a criterion on another metric is an error."""
    out = []
    for c in criteria:
        crit = c if isinstance(c, Criterion) else criterion_from_dict(c)
        crit.check()
        if metrics is not None and crit.metric not in metrics:
            raise ParameterError(f"criterion on unknown metric {crit.metric!r}; the kernel gives {list(metrics)}")
        out.append(crit)
    return out


def apply_values(scene: Scene, layout: Layout, values: np.ndarray) -> Scene:
    """The scene with the toleranced fields set to ``values`` (one per variable, in order)."""
    changes: dict[str, Any] = {}
    arrays = {p: np.array(layout.nominals[p], dtype=float, copy=True) for p in layout.shapes}
    for v, x in zip(layout.variables, values):
        if v.index:
            arrays[v.path][v.index] = x
        else:
            changes[v.path] = float(x)
    for p, a in arrays.items():
        changes[p] = a.tolist()
    return scene.replace(**changes)


def nominal_scene(scene: Scene, layout: Layout) -> Scene:
    """The scene at the nominal values (every deviation 0)."""
    return apply_values(scene, layout, np.array([v.nominal for v in layout.variables]))
