"""Checks of the Python-side arguments, in one place: a bad value is a ParameterError that names
the argument, its unit and the form expected (never a bare TypeError, ValueError or
OverflowError from deep inside)."""

from __future__ import annotations

import math
import operator
from typing import Any

import numpy as np

from .errors import ParameterError


def short(value: Any, limit: int = 40) -> str:
    """``repr(value)`` cut to ``limit`` characters (a 400-digit int prints as 40)."""
    try:
        text = repr(value)
    except Exception:  # pragma: no cover - a repr that raises
        text = f"<{type(value).__name__}>"
    return text if len(text) <= limit else text[:limit] + "..."


def real(name: str, value: Any, unit: str | None = None) -> float:
    """``value`` as a finite float. A value of the wrong type (None, a list) is a TypeError, one
    Python cannot read as a number (a string that is not one, an int beyond the float range) or
    a non-finite one a ParameterError; both name ``name`` (and ``unit`` when given), with
    Python's own error chained."""
    label = f"{name} [{unit}]" if unit else name
    try:
        x = float(value)
    except TypeError as e:
        raise TypeError(f"{label} must be a real number, got {type(value).__name__}") from e
    except (OverflowError, ValueError) as e:
        raise ParameterError(f"{label} must be a finite real number, got {short(value)}") from e
    if not math.isfinite(x):
        raise ParameterError(f"{label} must be a finite real number, got {x!r}")
    return x


def whole(name: str, value: Any, lo: int, hi: int) -> int:
    """``value`` as an int in ``[lo, hi]`` (Python or numpy integers; not bool or float)."""
    if isinstance(value, (bool, np.bool_)):
        raise ParameterError(f"{name} must be a whole number from {lo} to {hi}, got {value!r}")
    try:
        n = operator.index(value)
    except TypeError as e:
        raise ParameterError(
            f"{name} must be a whole number from {lo} to {hi}, got {short(value)}"
        ) from e
    if not lo <= n <= hi:
        raise ParameterError(f"{name} must be a whole number from {lo} to {hi}, got {short(n)}")
    return n


def pair(name: str, value: Any, unit: str) -> tuple[float, float]:
    """``value`` as two finite floats ``(a, b)`` with ``a < b`` (e.g. a time window)."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 2:
        raise ParameterError(f"{name} must be a pair (start, end) [{unit}], got {short(value)}")
    a, b = real(f"{name}[0]", value[0], unit), real(f"{name}[1]", value[1], unit)
    if not a < b:
        raise ParameterError(f"{name} must be a pair (start, end) [{unit}] with start < end, got ({a}, {b})")
    return a, b


def read_only(a: np.ndarray) -> np.ndarray:
    """A read-only view of ``a`` (no copy; the caller's array keeps its own flags): a result's
    arrays cannot be changed in place, which would change the analyses computed from them."""
    v: np.ndarray = a.view()
    v.flags.writeable = False
    return v
