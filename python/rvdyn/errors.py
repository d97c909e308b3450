"""Exceptions raised by rvdyn.

Every error of the Rust core is raised as one of these classes (the mapping lives in one place,
``rust/python/errors.rs``). Bad input is a ``ValueError`` as well, so generic code that catches
``ValueError`` keeps working:

==================  ==========================================================
``GeometryError``   a geometry that cannot exist or mesh (``ValueError``)
``ParameterError``  a value outside its domain: NaN, inf, negative, wrong shape,
                    unknown option (``ValueError``)
``SceneError``      a scene that cannot be read or is inconsistent (``ValueError``)
``ConvergenceError``a numerical query that did not converge (``ArithmeticError``)
``SimulationError`` a dynamic run that cannot go on (``RuntimeError``)
``RunnerError``     a tolerance study's runner lost every task of a chunk
                    (``RuntimeError``; ``rvdyn.study.RunnerError``, raised by
                    the Python study layer, not by the core)
==================  ==========================================================

A run interrupted with Ctrl-C raises the built-in ``KeyboardInterrupt``. A result too large
for memory (e.g. a broadcast of two long arrays into a 2**40-element grid) raises the built-in
``MemoryError`` before anything is computed, as numpy does. An argument of the wrong type (None
or a dict where a number belongs, and in the compiled functions any string) raises ``TypeError``,
as everywhere in Python; a traceback names the argument (the compiled functions add the note
``while processing 'eccentricity'``, the Python functions put it in the message). A value of the
right kind that cannot be read (an integer beyond the float range or a count beyond 2**32 - 1,
and where a Python function converts with ``float()``, a string that is not a number) raises
``ParameterError`` with Python's own error chained as its ``__cause__``.
"""

from __future__ import annotations

__all__ = [
    "RvdynError",
    "GeometryError",
    "ParameterError",
    "SceneError",
    "ConvergenceError",
    "SimulationError",
]


class RvdynError(Exception):
    """Base class of every error raised by rvdyn."""


class GeometryError(RvdynError, ValueError):
    """A geometry that cannot exist or cannot mesh; the message names the rule broken."""


class ParameterError(RvdynError, ValueError):
    """A parameter outside its domain (non-finite, negative, wrong shape, unknown option)."""


class SceneError(RvdynError, ValueError):
    """A scene description that cannot be read or is inconsistent."""


class ConvergenceError(RvdynError, ArithmeticError):
    """A numerical query that did not converge (e.g. the exact pin gap)."""


class SimulationError(RvdynError, RuntimeError):
    """A dynamic run that cannot go on (non-finite state, step size collapse, ...)."""
