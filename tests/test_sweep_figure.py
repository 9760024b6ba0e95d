"""Fig. 8 as the sweep writes it (studies/sweep.py::sweep_figure): no legend
or panel is drawn over the data, wherever the data lie."""

from __future__ import annotations

import numpy as np
import pytest

from rawehelix.studies import sweep


def _points(f1, tmax, ratio):
    return [{"f1_Hz": f, "tension_max_N": t, "tension_min_N": t - 5.0, "periodic": k != 2,
             "moment_ratio_max": r} for k, (f, t, r) in enumerate(zip(f1, tmax, ratio))]


def _overlap(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


@pytest.mark.parametrize("shape", ["rising", "falling", "peak", "flat"])
def test_no_legend_or_panel_sits_on_the_data(shape):
    f1 = np.linspace(9.0, 13.0, 9)
    tmax = {"rising": 100 + 40 * (f1 - 9), "falling": 300 - 40 * (f1 - 9),
            "peak": 100 + 400 * np.exp(-(f1 - 11) ** 2), "flat": 0 * f1 + 200}[shape]
    t = np.linspace(0.0, 0.4, 100)
    fig = sweep.sweep_figure(_points(f1, tmax, tmax / 100), {10.0: (t, 240 + np.sin(t))},
                             "test")
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    axes = fig.axes
    assert len(axes) == 3  # T max, the moment ratio, T(t) in its own panel
    for i, ax in enumerate(axes):
        legend = ax.get_legend()
        if legend is not None:
            assert not _overlap(legend.get_window_extent(renderer), ax.get_window_extent(renderer))
        for other in axes[i + 1:]:
            assert not _overlap(ax.get_window_extent(renderer), other.get_window_extent(renderer))
        assert not ax.child_axes, "an inset drawn inside a panel"
    import matplotlib.pyplot as plt
    plt.close(fig)
