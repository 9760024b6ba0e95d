"""The figure of a simulated lab test of Sec. 4 (``rawehelix labtest``), on the
paper's axes (Figs. 3-4): plots take data."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rawehelix.studies.store import writers

__all__ = ["labtest_png"]


def labtest_png(path: Path, result, L0: float) -> Path:
    """The simulated test on the paper's axes: T_e vs strain (Fig. 3), F_N vs
    3 y_e / L0^3 with the regression and Eq. (64)'s lines (Fig. 4), M_t vs alpha / L0;
    ``result``: a :class:`~rawehelix.studies.labtest.LabTest`, ``L0``: its segment [m]."""
    plt = writers._pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    s = result.summary
    if result.test == "axial":
        r = result.rows[0]
        e = np.asarray(r["strain"])
        ax.plot(e, r["tension_N"], "o", label="simulated test")
        ax.plot([0, e.max()], [0, r["apparent_EA_N"] * e.max()], "-",
                label=f"Eq. (62): EA = {r['apparent_EA_N']:.4g} N")
        ax.set_xlabel("strain (L - L0) / L0")
        ax.set_ylabel("T_e [N]")
    elif result.test == "bending":
        for k, r in enumerate(result.rows):
            x = 3 * np.asarray(r["deflection_m"]) / L0**3
            line, = ax.plot(x, r["load_N"], "o", label=f"T_e = {r['tension_N']:g} N: apparent EI "
                            f"{r['apparent_EI_Nm2']:.0f} N m^2")
            xs = np.array([0.0, x.max()])
            ax.plot(xs, r["apparent_EI_Nm2"] * xs, "-", color=line.get_color())
            ax.plot(xs, s["eq64_EI_Nm2"][k] * xs, ":", color=line.get_color())
        ax.plot([], [], "k:", label="Eq. (64)")
        ax.set_xlabel("3 y_e / L0^3 [1/m^2]")
        ax.set_ylabel("F_N [N]")
    else:
        for r in result.rows:
            x = np.asarray(r["angle_rad"]) / L0
            line, = ax.plot(x, r["torque_Nm"], "o", label=f"T_e = {r['tension_N']:g} N: "
                            f"GJ = {r['apparent_GJ_Nm2']:.4g} N m^2")
            ax.plot([0, x.max()], [0, r["apparent_GJ_Nm2"] * x.max()], "-", color=line.get_color())
        ax.set_xlabel("alpha / L0 [rad/m]")
        ax.set_ylabel("M_t [Nm]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    title = f"virtual {result.test} test, {L0} m segment" + (
        " (intrinsic law fitted)" if s.get("fit") else
        f" (rod EI: {s['rod_EI']})" if isinstance(s.get("rod_EI"), str) else "")
    return writers._finish(fig, path, title)
