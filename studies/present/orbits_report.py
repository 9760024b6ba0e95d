"""The text `rawehelix orbits` prints for an :class:`~rawehelix.studies.orbits.OrbitsResult`."""

from __future__ import annotations

import numpy as np

from rawehelix.studies.analysis import branch_limits

#: a branch whose median step in f1 is below this [Hz] gets the hint to harmonic
#: balance when it ran by a method that steps in time (the tester's undamped helix:
#: shooting crawled at about 0.001 Hz a point)
SMALL_STEP_HZ = 0.005
#: ... and at least this many points (a short branch's steps say little)
SMALL_STEP_POINTS = 20


def crawl_hint(branch: list, steps_in_time: bool) -> str | None:
    """The line that suggests ``--method hb`` when a method that steps in time
    (shooting) crawled along ``branch`` (None: no hint)."""
    if len(branch) < SMALL_STEP_POINTS or not steps_in_time:
        return None
    step = float(np.median(np.abs(np.diff([p["f1_Hz"] for p in branch]))))
    if step >= SMALL_STEP_HZ:
        return None
    return (f"  hint: the branch stepped f1 by a median {step:.2g} Hz over {len(branch)} points: "
            f"a lightly damped helix keeps the period map's steps small; --method hb traces "
            f"the same branch by harmonic balance at the cost of a Newton step a point "
            f"(or add [damping])")


def report(result) -> str:
    s = result.summary
    lines = [f"{result.title}: {len(s['branch'])} periodic orbits, {result.discretisation}, "
             f"in {result.wall_s:.1f} s "
             f"(torque: {s['torque']})"]
    if result.method_reported or "auto" in s.get("method_reason", ""):
        acc = [p["accuracy"] for p in s["branch"] if "accuracy" in p]
        lines.append(f"  method: {s['method']} ({s['method_reason']})" + (
            f"; H {min(a['H'] for a in acc)}-{max(a['H'] for a in acc)}, the highest "
            f"harmonic's energy at most {max(a['tail'] for a in acc):.1e} of the oscillation's; "
            f"{acc[0]['stability']}" if acc else ""))
    hint = crawl_hint(s["branch"], s.get("dt_s") is not None)  # dt: the method steps in time
    if hint:
        lines.append(hint)
    unstable = [p["f1_Hz"] for p in s["branch"] if not p["stable"]]
    lines.append(f"  largest Floquet multiplier modulus: "
                 f"{max(p['max_multiplier'] for p in s['branch']):.6f}; unstable points: "
                 f"{len(unstable)}")
    ratio = s.get("limits", {}).get("moment_ratio_max")
    if ratio:
        lines.append(f"  largest |M| / (N R): {ratio['value']:.3f} at f1 = {ratio['f1_Hz']:.4f} Hz")
    if "limits_first_by_kind" in s:
        lines += branch_limits.first_lines(s["limits_first_by_kind"], s["limits"],
                                            scene=s["scene"])
    for w in s["windows"]:
        if "sites_error" in w:
            lines.append(f"  warning, f1 {w['f1_Hz'][0]:g}:{w['f1_Hz'][1]:g} Hz: {w['sites_error']}")
        if "stopped" in w:
            lines.append(f"  stopped early, f1 {w['f1_Hz'][0]:g}:{w['f1_Hz'][1]:g} Hz: "
                         f"{w['stopped']}")
    defects = [p["defects"] for p in s["branch"] if "defects" in p]
    if defects:  # carried entries (hysteretic torsion: z, periodic_orbits/floquet.py)
        internal = [p["internal_multipliers"] for p in s["branch"]
                    if p.get("internal_multipliers", {}).get("count")]
        lines.append("  carried along by the shooting (hysteretic torsion's z): largest drift of "
                     "z over a period " + f"{max(d.get('z', 0.0) for d in defects):.2g}" +
                     " of z, largest residual after it " +
                     f"{max(d.get('carried', 0.0) for d in defects):.2g}" +
                     (f"; z's multipliers (set aside from the stability) within "
                      f"{max(i.get('max_distance_to_1', 0.0) for i in internal):.1g} of 1"
                      if internal else ""))
    for kind, items in (("fold", s["folds"]), ("bifurcation", s["bifurcations"]),
                        ("peak", s["peaks"])):
        for x in items:
            error = f" (+- {x['f1_error_Hz']:.1e} Hz)" if "f1_error_Hz" in x else ""
            if x.get("kind") == "superharmonic":
                error = (f" ({x['order']}:1 of {x['f_n_Hz']:.3f} Hz, |mu - 1| = "
                         f"{x['distance']:.3g}, T max - T min {x['oscillation_N']:.3f} N)")
            lines.append(f"  {x.get('kind', kind)} at f1 = {x['f1_Hz']:.4f} Hz{error}, "
                         f"T max = {x['tension_max_N']:.2f} N")
    for j in s["junctions"]:
        if not j["same_branch"]:
            lines.append(f"  warning: at the cut f1 = {j['f1_Hz']:.4f} Hz between two ranks' "
                         f"windows T max is {j['tension_max_N_left']:.2f} N on the left and "
                         f"{j['tension_max_N_right']:.2f} N on the right: the windows are on "
                         f"different branches there (trace it on one rank)")
    return "\n".join(lines)
