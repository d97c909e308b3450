"""The per-pixel envelope the paper figures draw their long traces with, and what `rvdyn paper`
writes: the same pixels, the same numbers, whichever process draws."""

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

import rvdyn
from rvdyn import paper
from rvdyn.paper import envelope


def _m4_by_loop(x, y, buckets):
    """The M4 aggregation written out bucket by bucket (Jugel et al. 2014): first, smallest,
    largest and last sample of each run, in order, each sample once."""
    edges = np.linspace(0, len(x), buckets + 1).astype(int)
    keep = []
    for a, b in zip(edges[:-1], edges[1:]):
        seg = y[a:b]
        for i in sorted({a, a + int(np.argmin(seg)), a + int(np.argmax(seg)), b - 1}):
            keep.append(i)
    return x[keep], y[keep]


def test_envelope_keeps_every_bucket_extreme_in_order() -> None:
    rng = np.random.default_rng(3)
    x = np.linspace(0.0, 5.0, 50_000)
    y = np.sin(40 * x) + 0.1 * rng.standard_normal(x.size)
    xe, ye = envelope(x, y, 1000)
    assert len(xe) <= 4000 and np.all(np.diff(xe) > 0)
    edges = np.linspace(0, x.size, 1001).astype(int)
    for a, b in zip(edges[:-1], edges[1:]):
        inside = (xe >= x[a]) & (xe <= x[b - 1])
        assert ye[inside].max() == y[a:b].max() and ye[inside].min() == y[a:b].min()
        # The first and last sample of each run are kept: the joins between runs are exact.
        assert xe[inside][0] == x[a] and xe[inside][-1] == x[b - 1]
    # A trace already short enough is not touched.
    xs, ys = envelope(x[:100], y[:100], 1000)
    assert np.array_equal(xs, x[:100]) and np.array_equal(ys, y[:100])


@pytest.mark.parametrize("n, buckets", [(50_000, 551), (25_001, 1000), (4_001, 1000), (9_999, 7)])
def test_envelope_equals_the_bucket_loop_with_ties(n: int, buckets: int) -> None:
    # Values rounded to 0.1 make many ties: the first occurrence is the one kept, as argmin does.
    rng = np.random.default_rng(n)
    x = np.arange(n, dtype=float)
    y = np.round(rng.standard_normal(n), 1)
    for got, want in zip(envelope(x, y, buckets), _m4_by_loop(x, y, buckets)):
        assert np.array_equal(got, want)
    # Integer channels (loaded pins) too.
    yi = rng.integers(10, 14, n)
    for got, want in zip(envelope(x, yi, buckets), _m4_by_loop(x, yi, buckets)):
        assert np.array_equal(got, want)


@pytest.fixture(scope="module")
def short_run() -> tuple[rvdyn.Scene, rvdyn.Result]:
    # 0.5 s at the default 1e-4 s samples: 5001 samples, more than 4 per pixel column of the
    # widest axes (about 550 px), so the long traces are thinned.
    scene = rvdyn.Scene.paper("rated")
    return scene, rvdyn.simulate(scene, 0.5, progress=False, channels=list(paper.PAPER_CHANNELS))


def _render(fig) -> np.ndarray:
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[..., :3].astype(int)


def _column_extents(img: np.ndarray, box) -> tuple[np.ndarray, np.ndarray]:
    """Topmost and bottommost row with ink (any channel below 250 of 255) in each pixel column
    strictly inside ``box`` (an axes' pixel bounding box), over that column and its two
    neighbours (a line 0.6 pt = 0.9 px wide inks the neighbour column of a vertex near the
    column's edge, and the full trace has ~80 such vertices per column, the envelope 4);
    -1 for a blank column."""
    h = img.shape[0]
    x0, x1 = int(np.ceil(box.x0)) + 2, int(np.floor(box.x1)) - 2
    y0, y1 = h - int(np.floor(box.y1)) + 2, h - int(np.ceil(box.y0)) - 2  # image rows run down
    ink = img[y0:y1, x0:x1].min(axis=-1) < 250
    ink = ink | np.roll(ink, 1, axis=1) | np.roll(ink, -1, axis=1)
    any_ink = ink.any(axis=0)
    top = np.where(any_ink, ink.argmax(axis=0), -1)
    bottom = np.where(any_ink, ink.shape[0] - 1 - ink[::-1].argmax(axis=0), -1)
    return top, bottom


@pytest.mark.parametrize("name", list(paper.FIGURES))
def test_thinned_figure_covers_the_same_pixel_columns_as_the_full_traces(short_run, name, monkeypatch) -> None:
    scene, result = short_run
    def render(thin: bool):
        fig = paper.Figures().draw(name, "rated", paper._theory(scene), result)
        paper._fixed_layout(fig)
        points = sum(len(line.get_xdata()) for ax in fig.axes for line in ax.get_lines())
        if thin:
            paper._thin_lines(fig)
        kept = sum(len(line.get_xdata()) for ax in fig.axes for line in ax.get_lines())
        return fig, _render(fig), points, kept

    fig, thin_img, points, kept = render(True)
    _, full_img, _, _ = render(False)
    if name in ("output_speed", "disc_center", "loaded_pins", "input_torque"):
        assert kept < points / 2, "the 5001-sample traces should have been thinned"
    for ax in fig.axes:
        (t1, b1), (t2, b2) = _column_extents(thin_img, ax.bbox), _column_extents(full_img, ax.bbox)
        # The same columns carry ink, and each column's highest and lowest inked pixel agree
        # within 1 px, but for a few columns (at most 3 %): anti-aliasing and matplotlib's path
        # simplification (which merges vertices closer than 1/9 px to a line) treat the
        # full trace and its envelope differently where the trace is steep (the start impact,
        # the jumps of the loaded-pin count). An envelope that lost a column's extreme would
        # move that column's extent by up to the trace's height in most columns.
        assert np.array_equal(t1 >= 0, t2 >= 0)
        off = (np.abs(t1 - t2) > 1) | (np.abs(b1 - b2) > 1)
        assert off.mean() <= 0.03, (ax.get_title(), np.flatnonzero(off))
    # The disc centre's path (x back and forth) is drawn in full: an envelope would cut chords.
    if name == "disc_center":
        path = fig.axes[1].get_lines()[0]
        assert len(path.get_xdata()) == len(result.t)


@pytest.fixture(scope="module")
def idle_run() -> tuple[rvdyn.Scene, rvdyn.Result]:
    # Idle: contact forces below 1 N and a ripple of 1e-1 deg/s, the smallest numbers a
    # paper figure shows.
    scene = rvdyn.Scene.paper("idle")
    return scene, rvdyn.simulate(scene, 0.5, progress=False, channels=list(paper.PAPER_CHANNELS))


@pytest.mark.parametrize("load", ["idle", "rated"])
@pytest.mark.parametrize("name", list(paper.FIGURES))
def test_fixed_layout_keeps_every_label_inside_the_figure_and_off_the_other_axes(
        short_run, idle_run, load, name) -> None:
    # The paper figures are laid out with fixed margins, not by measuring their labels
    # (tight_layout): every axes' labels, tick labels, offset texts, title and legend must still
    # fall inside the figure and clear of the neighbouring axes.
    scene, result = idle_run if load == "idle" else short_run
    fig = paper.Figures().draw(name, load, paper._theory(scene), result)
    paper._fixed_layout(fig)
    renderer = fig.canvas.get_renderer()
    width, height = fig.bbox.width, fig.bbox.height
    for ax in fig.axes:
        box = ax.get_tightbbox(renderer)
        assert box.x0 >= 0 and box.y0 >= 0 and box.x1 <= width and box.y1 <= height, (name, ax.get_title(), box)
        for other in fig.axes:
            if other is not ax:
                assert not box.overlaps(other.bbox), (name, ax.get_title(), other.get_title())


@pytest.mark.parametrize("name", list(paper.FIGURES))
def test_a_figure_drawn_again_has_the_pixels_of_a_new_one(short_run, idle_run, name, tmp_path) -> None:
    # rvdyn paper draws each figure kind into one Figure, cleared for the next load case: the
    # PNG must be the one a new Figure gives, from the rated run to the idle one (forces a
    # thousand times smaller, other tick labels) and back, and again for the same run.
    from PIL import Image

    runs = {"rated": short_run, "idle": idle_run}
    again, new = tmp_path / "again", tmp_path / "new"
    again.mkdir()
    new.mkdir()
    reusing = paper.Figures()
    for k, load in enumerate(["rated", "idle", "rated", "rated"]):
        scene, result = runs[load]
        (reused,) = reusing.write(load, paper._theory(scene), result, again, [name])
        (fresh,) = paper.Figures().write(load, paper._theory(scene), result, new, [name])
        a, b = (np.asarray(Image.open(p)) for p in (reused, fresh))
        assert a.shape == b.shape and np.array_equal(a, b), (name, k, load, int((a != b).sum()))
    with pytest.raises(rvdyn.ParameterError, match="unknown paper figure 'speed'"):
        reusing.draw("speed", "rated", 1.0, short_run[1])


def test_thin_lines_keeps_first_last_and_extremes_of_every_pixel_column() -> None:
    # The hard case for an envelope: a trace that goes up and down many times inside every
    # pixel column (50 000 samples of noise over about 740 columns), so that each column's
    # extremes are interior samples. After thinning, each pixel column (by the axes' own
    # transform) must hold exactly the first, smallest, largest and last sample of the full
    # trace in that column, checked column by column with a plain loop.
    rng = np.random.default_rng(7)
    t = np.linspace(0.0, 5.0, 50_000)
    y = np.sin(3 * t) + 0.3 * rng.standard_normal(t.size) * (1 + np.cos(7 * t))
    # Laid out as rvdyn paper does, autoscale still pending: the columns are those of the
    # limits the figure is drawn with, read here after the thinning.
    fig, ax = paper._new_figure((8, 3.5))
    (line,) = ax.plot(t, y, lw=0.6)
    paper._fixed_layout(fig)
    paper._thin_lines(fig)
    ax.get_xlim()
    column = np.floor(line.get_transform().transform(np.column_stack([t, y]))[:, 0])
    xt, yt = (np.asarray(v) for v in line.get_data())
    assert len(xt) <= 4 * (ax.bbox.width + 2)
    kept_column = np.floor(line.get_transform().transform(np.column_stack([xt, yt]))[:, 0])
    columns = np.unique(column)
    assert np.array_equal(np.unique(kept_column), columns)
    for c in columns:
        full, kept = y[column == c], yt[kept_column == c]
        assert kept.min() == full.min() and kept.max() == full.max()
        assert kept[0] == full[0] and kept[-1] == full[-1]
        assert len(kept) <= 4


def _args(out, **kw) -> argparse.Namespace:
    return argparse.Namespace(out=str(out), load=kw.get("load", "rated"), t_end=kw.get("t_end", 0.5),
                              integrator=None)


def test_paper_numbers_equal_a_run_with_every_channel_and_the_defaults(tmp_path) -> None:
    # rvdyn paper records fewer channels (no bearing forces) and runs on a worker thread: the
    # summary must be the one of a plain run with every channel, number for number.
    assert paper.main(_args(tmp_path)) == 0
    got = json.loads((tmp_path / "summary.json").read_text())[0]
    scene = rvdyn.Scene.paper("rated")
    ref = rvdyn.simulate(scene, 0.5, progress=False)
    assert "bearings" not in paper.PAPER_CHANNELS and "crank_bearing_force" in ref.channels
    want = json.loads(json.dumps(paper.summarize("rated", scene, ref, 0.0)))
    got.pop("wall_time_s"), want.pop("wall_time_s")
    assert got == want


def _helper_against_alone(tmp: str) -> None:
    """The comparison of the test below, in a process of its own (no other Python threads, so
    rvdyn paper forks its helper there)."""
    from PIL import Image

    tmp_path = Path(tmp)
    with_helper, alone = tmp_path / "helper", tmp_path / "alone"
    started = []
    start = paper._Helper.start.__func__

    def spy(cls, draw, jobs):
        helper = start(cls, draw, jobs)
        started.append((helper is not None, list(jobs)))
        return helper

    paper._Helper.start = classmethod(spy)
    assert paper.main(_args(with_helper, load="idle")) == 0
    theirs = paper._split([("idle", name) for name in paper.FIGURES])[1]
    assert started == [(True, theirs)], "the helper process should draw here (Linux, no other thread)"
    paper._Helper.start = classmethod(lambda cls, draw, jobs: None)
    assert paper.main(_args(alone, load="idle")) == 0
    names = sorted(p.name for p in alone.glob("*.png"))
    assert len(names) == len(paper.FIGURES)
    assert names == sorted(p.name for p in with_helper.glob("*.png"))
    for n in names:
        assert np.array_equal(np.asarray(Image.open(with_helper / n)), np.asarray(Image.open(alone / n))), n


def _helper_error(tmp: str) -> None:
    """An OSError in the helper process reaches the caller, and the helper is gone (run in a
    process of its own, where the helper is forked)."""
    import multiprocessing

    tmp_path = Path(tmp)
    case, name = paper._split([("idle", name) for name in paper.FIGURES])[1][0]
    (tmp_path / f"{case}_{name}.png").mkdir()
    forked = []
    start = paper._Helper.start.__func__

    def spy(cls, draw, jobs):
        helper = start(cls, draw, jobs)
        forked.append(helper is not None)
        return helper

    paper._Helper.start = classmethod(spy)
    try:
        paper.main(_args(tmp_path, load="idle"))
    except IsADirectoryError as exc:
        assert name in str(exc)
    else:
        raise AssertionError("the helper's error was not raised")
    assert forked == [True]
    assert not multiprocessing.active_children()


def _in_fresh_interpreter(function: str, tmp_path: Path) -> None:
    import subprocess
    import sys

    code = (f"import sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); "
            f"import test_paper_figures as t; t.{function}({str(tmp_path)!r})")
    proc = subprocess.run([sys.executable, "-W", "error", "-c", code], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]


def test_helper_process_writes_the_same_figures_as_this_process(tmp_path) -> None:
    # In a fresh interpreter: this test process may hold other threads (earlier tests' pools),
    # and rvdyn paper then draws everything itself instead of forking.
    _in_fresh_interpreter("_helper_against_alone", tmp_path)


def test_an_error_in_the_forked_helper_reaches_the_caller(tmp_path) -> None:
    _in_fresh_interpreter("_helper_error", tmp_path)


def test_an_error_in_the_helper_reaches_the_caller(tmp_path) -> None:
    # A folder where the helper's PNG should go: its OSError is raised here (the CLI turns it
    # into "cannot write ..."), and the helper process is gone.
    case, name = paper._split([("idle", name) for name in paper.FIGURES])[1][0]
    (tmp_path / f"{case}_{name}.png").mkdir()
    with pytest.raises(OSError):
        paper.main(_args(tmp_path, load="idle"))
    import multiprocessing

    assert not [p for p in multiprocessing.active_children() if p.name == "rvdyn-paper-figures"]
