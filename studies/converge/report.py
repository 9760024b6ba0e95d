"""The report of a refinement study: ``converge.csv``, ``converge.md`` and
``work_precision.png``, from the summary of :func:`rawehelix.studies.converge.study.run`.

The functions take data (the summary, the runs by method, the quantity) and
return text or write one file; they never solve.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from rawehelix.studies.store import writers


def _order(order: float) -> str:
    return "" if not np.isfinite(order) else f"{order:.2f}"


def csv_text(summary: dict, unit: str, components: list) -> str:
    """One row per run: its N and dt, the values [unit], error, observed order, wall time."""
    out = io.StringIO()
    w = csv.writer(out)
    w.writerow(["method", "elements", "dt_s", *[f"{c} [{unit}]" for c in components],
                "rel_error", "observed_order", "wall_s", "failed"])
    for r in summary["runs"]:
        w.writerow([r["method"], r["elements"], "" if r["dt_s"] is None else r["dt_s"],
                    *[f"{v:.12g}" for v in r["value"]],
                    f"{r['error']:.3e}", _order(r["order"]), f"{r['wall_s']:.3f}",
                    r["failed"] or ""])
    return out.getvalue()


def markdown(summary: dict, qty, name: str) -> str:
    """The table of runs, headed by what the errors are measured against."""
    ref, unit = summary["reference"], qty.unit
    var = qty.refinement.methods[0].variable
    lines = [f"# Convergence of `{qty.name}` ({name})", "",
             f"Error: relative to the finest run of {ref['method']} ({var} = {ref[var]}), "
             f"value {np.array2string(np.asarray(ref['value']), precision=10)} {unit}."]
    if summary.get("error_scale") is not None:
        lines.append(f"Errors are |value - reference| / {summary['error_scale']:g} {unit} (the "
                     f"value itself is near zero): {qty.refinement.scale_note}")
    tref = summary.get("time_reference")
    if tref is not None:
        lines.append(f"The dt ladders (fixed steps) are measured against {tref['method']} at "
                     f"dt = {tref['dt_s']:g} s (N = {tref['elements']}), value "
                     f"{np.array2string(np.asarray(tref['value']), precision=10)} {unit}: "
                     f"their error is the time error alone, at that N.")
    if ref["independent"] is not None:
        lines.append(f"That reference differs from the independent one by "
                     f"{ref['independent_rel_diff']:.1e} (relative).")
    elif ref.get("independent_status"):
        status, _, why = ref["independent_status"].partition(": ")
        lines.append(f"The independent reference (shooting): {status} ({why}).")
    lines += ["", f"| method | run | value [{unit}] | rel. error | observed order | wall [s] |",
              "| --- | --- | --- | --- | --- | --- |"]
    for r in summary["runs"]:
        value = ", ".join(f"{v:.8g}" for v in r["value"])
        wall = f"{r['wall_s']:.3f}" if not r["failed"] else f"failed: {r['failed'][:80]}"
        lines.append(f"| {r['method']} | {r['step']} | {value} | {r['error']:.2e} | "
                     f"{_order(r['order'])} | {wall} |")
    return "\n".join(lines) + "\n"


def work_precision_png(path: Path, by_method: dict, qty, name: str) -> Path:
    """Error against wall time, one curve per method (``by_method``: label ->
    runs with ``wall_s``, ``error`` and ``method``); the dt ladders measured
    against the time reference are dashed."""
    plt = writers._pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for label, series in by_method.items():
        pts = [(r.wall_s, r.error) for r in series if r.error > 0 and np.isfinite(r.error)]
        if pts:
            w, e = zip(*pts)
            timed = qty.refinement.time_reference and series[0].method.variable == "dt_s"
            ax.loglog(w, e, "s--" if timed else "o-",
                      label=f"{label}: time error only" if timed else label)
    for level in (1e-2, 1e-3, 1e-4):
        ax.axhline(level, color="0.7", lw=0.8, ls=":")
    ax.set_xlabel("wall time per run [s]")
    ax.set_ylabel("relative error")
    ax.set_title(f"work-precision: {qty.name} ({name})")
    ax.grid(True, which="both", alpha=0.2)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
