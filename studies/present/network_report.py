"""The network scheme's line of a ``simulate`` report (studies/network_simulate.py's
summary block ``network``)."""

from __future__ import annotations


def line(summary: dict) -> str:
    """The network's line of a report ("" for another scheme's run)."""
    n = summary.get("network")
    if not n:
        return ""
    slack = ("no tether slack" if n["first_slack_s"] is None
             else f"first slack at t = {n['first_slack_s']:.4f} s")
    return (f"\n  network: {n['rings']} rings (l = {n['spacing_m']:.4g} m), step {n['dt_s']:.3g} s; "
            f"smallest tether force {n['smallest_tether_force_N']:.2f} N, {slack}")
