"""Matplotlib figures of a study: metric histograms with the pass criteria, sensitivity bars."""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from .spec import Criterion, check_criteria
from .stats import Sensitivity, _metric, columns

__all__ = ["plot_histogram", "plot_sensitivity"]


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.subplots(figsize=(6, 4))[1]


def plot_histogram(table: Any, metric: str, criteria: Sequence[Criterion | dict[str, Any]] = (), bins: int = 40,
                   ax: Any = None) -> Any:
    """Histogram of ``metric`` over the samples that ran, with a vertical line at each bound of
    the criteria on that metric. Returns the axes."""
    ax = _axes(ax)
    v = _metric(columns(table), metric)
    x = v[np.isfinite(v)]
    ax.hist(x, bins=bins, color="0.6", edgecolor="0.3", lw=0.5)
    for c in check_criteria(criteria, None):
        if c.metric != metric:
            continue
        for bound, what in ((c.max, "max"), (c.min, "min")):
            if bound is not None:
                ax.axvline(bound, color="C3", ls="--", lw=1.2, label=f"criterion {what} {bound:g}")
    ax.set(xlabel=metric, ylabel="samples", title=f"{metric}: {len(x)} samples" +
           (f", {len(v) - len(x)} failed" if len(v) > len(x) else ""))
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    return ax


def plot_sensitivity(sens: Sensitivity, top: int = 15, ax: Any = None) -> Any:
    """Horizontal bars of a sensitivity ranking (largest first; at most ``top`` inputs)."""
    ax = _axes(ax)
    names = list(sens.names[:top])[::-1]
    vals = list(sens.values[:top])[::-1]
    ax.barh(range(len(names)), vals, color=["C0" if v >= 0 else "C1" for v in vals])
    ax.set_yticks(range(len(names)), names, fontsize="small")
    ax.axvline(0.0, color="k", lw=0.6)
    label = {"src": "standardised regression coefficient", "sobol": "first-order Sobol index"}.get(sens.method,
                                                                                                    sens.method)
    title = f"{sens.metric}"
    if sens.method == "src":
        title += f" (R^2 = {sens.r2:.3f})"
    ax.set(xlabel=label, title=title)
    return ax
