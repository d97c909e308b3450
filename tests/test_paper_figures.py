"""The per-pixel envelope the paper figures draw their long traces with."""

import numpy as np

from rvdyn.paper import envelope


def test_envelope_keeps_every_bucket_extreme_in_order() -> None:
    rng = np.random.default_rng(3)
    x = np.linspace(0.0, 5.0, 50_000)
    y = np.sin(40 * x) + 0.1 * rng.standard_normal(x.size)
    xe, ye = envelope(x, y, 1000)
    assert len(xe) <= 2000 and np.all(np.diff(xe) >= 0)
    edges = np.linspace(0, x.size, 1001).astype(int)
    for a, b in zip(edges[:-1], edges[1:]):
        inside = (xe >= x[a]) & (xe <= x[b - 1])
        assert ye[inside].max() == y[a:b].max() and ye[inside].min() == y[a:b].min()
    # A trace already short enough is not touched.
    xs, ys = envelope(x[:100], y[:100], 1000)
    assert np.array_equal(xs, x[:100]) and np.array_equal(ys, y[:100])
