"""The examples in the docstrings of the public entry points run, and print what they show.

The installed package is tested (not the source tree), so this works for a wheel install too.
"""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = ["rvdyn", "rvdyn.scene", "rvdyn.simulation", "rvdyn.result", "rvdyn.bearing", "rvdyn.analysis.ltca"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name: str) -> None:
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} doctest examples failed in {name}"


def test_entry_points_have_examples() -> None:
    # The doctests above must not pass by having nothing to run.
    finder = doctest.DocTestFinder()
    import rvdyn

    for obj in (rvdyn.Scene, rvdyn.Scene.paper, rvdyn.simulate, rvdyn.sweep):
        tests = finder.find(obj)
        assert any(t.examples for t in tests), obj
