"""The figure of a wind history (issue 44): the hub's wind in time, and beside it its
spectrum's Welch estimate against the target it was generated to: plots take data."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rawehelix.studies.store import writers

__all__ = ["wind_png"]


def wind_png(path: Path, times_s, hub_m_s, f_Hz=None, estimate=None, target=None,
             title: str = "wind at the hub") -> Path:
    """Left: u at the hub [m/s] against t [s]; right (when ``f_Hz`` is given): the Welch
    estimate and the target spectrum [m^2/s^2/Hz] against f [Hz], log-log, without
    the zero frequency."""
    plt = writers._pyplot()
    panels = 2 if f_Hz is not None else 1
    fig, axes = plt.subplots(1, panels, figsize=(5.2 * panels, 4.0), squeeze=False)
    ax = axes[0, 0]
    u = np.asarray(hub_m_s, float)
    ax.plot(times_s, u, lw=0.7)
    ax.axhline(u.mean(), color="k", lw=0.6, ls=":", label=f"mean {u.mean():.3g} m/s, "
               f"std {u.std(ddof=1):.3g} m/s")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("u at the hub [m/s]")
    ax.legend(loc="best", fontsize=8)
    ax.grid(True, alpha=0.3)
    if f_Hz is not None:
        ax = axes[0, 1]
        f = np.asarray(f_Hz, float)
        ax.loglog(f[1:], np.asarray(estimate)[1:], lw=0.8, label="Welch estimate")
        ax.loglog(f[1:], np.asarray(target)[1:], "k--", lw=1.0, label="target (IEC Kaimal)")
        ax.set_xlabel("f [Hz]")
        ax.set_ylabel("S_u [m^2/s^2/Hz]")
        ax.legend(loc="best", fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
    return writers._finish(fig, path, title)
