"""The CLI ends with a one-line message, never a traceback, for unusable output locations and
arguments it cannot follow."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest


def rvdyn(*args: str, cwd: str, stdout=subprocess.PIPE) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "rvdyn", *args], cwd=cwd, stdout=stdout,
                          stderr=subprocess.PIPE, text=True, timeout=300)


@pytest.mark.parametrize(
    "args, reason",
    [
        (["plot-geometry", "--out", "afile"], "a file of that name exists"),
        (["plot-geometry", "--out", "afile/sub"], "Not a directory"),
        (["plot-geometry", "--out", "isdir"], "Is a directory"),
        (["plot-stiffness", "--out", "/proc/rvdyn-nope/x"], "cannot write"),
        (["paper", "--t-end", "0.3", "--load", "idle", "--out", "afile/x"], "Not a directory"),
    ],
)
def test_unwritable_output_is_one_line_not_a_traceback(tmp_path, args, reason):
    pytest.importorskip("matplotlib")
    (tmp_path / "afile").write_text("x")
    (tmp_path / "isdir" / "geometry.png").mkdir(parents=True)
    p = rvdyn(*args, cwd=str(tmp_path))
    assert "Traceback" not in p.stderr, p.stderr
    assert p.returncode == 1, p.stderr
    assert p.stderr.startswith(f"rvdyn {args[0]}: cannot write"), p.stderr
    assert reason in p.stderr


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_a_full_stdout_is_reported(tmp_path):
    with open("/dev/full", "w") as full:
        p = rvdyn("info", "--json", cwd=str(tmp_path), stdout=full)
    assert "Traceback" not in p.stderr and "Exception ignored" not in p.stderr, p.stderr
    assert p.returncode == 1
    assert "cannot write standard output" in p.stderr


@pytest.mark.parametrize("t_end", ["0.01", "1e-300", "nan", "-1", "abc"])
def test_paper_rejects_a_run_too_short_to_summarise_before_simulating(tmp_path, t_end):
    # Used to simulate, then fail with advice ("start earlier") the CLI cannot follow.
    p = rvdyn("paper", "--t-end", t_end, "--load", "idle", "--out", "o", cwd=str(tmp_path))
    assert p.returncode == 2, p.stderr
    assert "argument --t-end" in p.stderr and "Traceback" not in p.stderr
    assert not (tmp_path / "o").exists()


def test_empty_output_folder_is_an_argument_error(tmp_path):
    p = rvdyn("plot-geometry", "--out", "", cwd=str(tmp_path))
    assert p.returncode == 2 and "must not be empty" in p.stderr and "Traceback" not in p.stderr
