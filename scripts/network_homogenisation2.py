"""The homogenisation measured, second pass (issue 45): the network's torque-twist curve
to collapse against the continuum's members law and Tulloch's criterion, and the Sec.
5.2 spin-up, network (references/network/dynamics.py) against the FE continuum, at
several ring spacings.  Prints the tables of docs/explanation/network.md.

    .venv/bin/python scripts/network_homogenisation2.py torque [--rings 5,9,17,33,65]
    .venv/bin/python scripts/network_homogenisation2.py spinup --fe DIR [--rings 5,9,17]
    .venv/bin/python scripts/network_homogenisation2.py forced [--rings 5,9] [--f1 2,4,6]

``spinup`` reads the FE run's time_series.csv from DIR, made by
``rawehelix simulate nominal_operation --until 5 -o DIR`` with the SECTION keys below
(--set section.law=tensegrity --set model.kinematics=extensible --set
section.torsion=members --set section.self_stress_N=632.6 --set section.bar_EA_N=18200).
"""

from __future__ import annotations

import argparse
import csv
import math

import numpy as np

from rawehelix.members import critical_twist
from rawehelix.references.network import Network, NetworkError, solve
from rawehelix.references.network import dynamics as dy
from rawehelix.parameters.normalised import RPM
from rawehelix.studies import scene

SECTION = {"law": "tensegrity", "torsion": "members", "self_stress_N": 632.6, "bar_EA_N": 18200.0}


def fitted(name):
    return scene.load(name).replace(model={"kinematics": "extensible"}, section=SECTION)


def network_collapse(p, rings, step=2.0):
    """(the largest top torque [N m] the network holds, its end-to-end twist [rad]), by
    continuation in growing steps, halved on a failure down to 0.01 N m; and the curve [(Q, twist)]."""
    curve, state, Q = [(0.0, 0.0)], None, 0.0
    while True:
        try:
            r = solve(Network.from_parameters(p.replace(section={"rings": rings}),
                                              end_torque_Nm=Q + step), state=state)
        except NetworkError:
            if step < 0.01:
                return Q, curve[-1][1], curve
            step /= 2
            continue
        Q += step
        state = r.state
        curve.append((Q, r.state.theta))
        step *= 1.5


def continuum_curve(p, rings, Q_values):
    """The continuum's members law at the chord's strain: Q(tau) = dW/dtau; twist tau L0;
    the collapse where the ring twist l tau reaches Tulloch's delta_crit."""
    h = p.helix
    m = p.model.section.members(h)
    eps = p.ends.elongation
    l = h.length_m / (rings - 1)
    l_t = l / math.cos(m.beta)
    tau_crit = critical_twist(m.R, l_t) / l
    taus = np.linspace(0.0, 1.5 * tau_crit if math.isfinite(tau_crit) else 10.0, 3001)
    Q = np.array([m.resultants(eps, 0.0, t)["Q"] for t in taus])
    Q_crit = float(np.interp(tau_crit, taus, Q)) if tau_crit < taus[-1] else math.inf
    return Q_crit, tau_crit * h.length_m, [(float(np.interp(q, Q, taus)) * h.length_m) for q in Q_values]


def torque(rings_list):
    p = fitted("stationary_table2").replace(model={"gravity": False, "drag": False})
    print("| rings | l [m] | network collapse torque [N m] | its twist [rad] | continuum at "
          "Tulloch's l tau = delta_crit [N m] | twist [rad] | gap | twist at 5 N m: network | continuum | gap |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for rings in rings_list:
        Qn, th, curve = network_collapse(p, rings)
        Qc, thc, _ = continuum_curve(p, rings, [])
        qs = np.array(curve)
        tw5n = float(np.interp(5.0, qs[:, 0], qs[:, 1]))
        tw5c = continuum_curve(p, rings, [5.0])[2][0]
        l = p.helix.length_m / (rings - 1)
        print(f"| {rings} | {l:.4g} | {Qn:.3f} | {th:.4f} | {Qc:.3f} | {thc:.4f} | "
              f"{100 * (Qn / Qc - 1):+.2f} % | {tw5n:.5f} | {tw5c:.5f} | {100 * (tw5n / tw5c - 1):+.3f} % |")


def spinup(rings_list, fe_dir, times=(1.0, 2.0, 5.0)):
    p = fitted("nominal_operation")
    with open(f"{fe_dir}/time_series.csv") as f:
        fe = np.array([[float(x) for x in row] for row in list(csv.reader(f))[1:]])
    h = p.helix
    fe_at = {t: (np.interp(t, fe[:, 0], fe[:, 2]), np.interp(t, fe[:, 0], fe[:, 5])) for t in times}
    print("continuum (FE N = 16, p = 3): " + ", ".join(
        f"t = {t:g} s: spin(L0/2) {v[0]:.3f} rpm, T(0) {v[1]:.3f} N" for t, v in fe_at.items()))
    print("| rings | l [m] | inertia | " + " | ".join(f"spin(L0/2) at {t:g} s [rpm] | gap" for t in times)
          + " | T(0) at 5 s [N] | gap | wall [s] |")
    print("|---" * (4 + 2 * len(times) + 2) + "|")
    for rings in rings_list:
        for label in ("continuum's", "hoop's"):
            l = h.length_m / (rings - 1)
            sec = {"rings": rings}
            if label == "continuum's":  # 2 (M/L0) EI/EA per unit length (Eq. 27's delta)
                sec["ring_polar_inertia_kgm2"] = 2 * h.mass_kg / h.length_m * h.EI_Nm2 / h.EA_N * l
            q = p.replace(section=sec)
            import time
            t0 = time.perf_counter()
            net = Network.from_parameters(q, end_torque_Nm=0.0)
            st = solve(net)
            drive = dy.Drive.from_parameters(q)
            integ = dy.Integrator(net, drive, dy.default_step(net, st.state, q.time.dt_s))
            mo = dy.at_rest(st.state, 0.0, drive)
            out = {}
            for t in times:
                integ.advance(mo, t, t)
                out[t] = (integ.spin(mo)[net.count // 2] / RPM, dy.bay_tension_N(net, mo.state, 0))
            wall = time.perf_counter() - t0
            cells = " | ".join(f"{out[t][0]:.3f} | {100 * (out[t][0] / fe_at[t][0] - 1):+.2f} %"
                               for t in times)
            T5 = out[times[-1]][1]
            print(f"| {rings} | {l:.4g} | {label} | {cells} | {T5:.3f} | "
                  f"{100 * (T5 / fe_at[times[-1]][1] - 1):+.3f} % | {wall:.1f} |", flush=True)


def forced_base(fe_elements=8):
    """mobile_end as shipped with the fitted section, lead-in 2 s, the FE at N = fe_elements."""
    return scene.load("mobile_end", elements=fe_elements, degree=3).replace(
        model={"kinematics": "extensible"}, section=SECTION, sweep={"lead_in_s": 2.0})


def sweep_points(p, f1_list, cache=None):
    """The sweep's points of ``p`` at f1_list (entries with their limits block), each
    f1 kept in ``cache`` (a directory: one JSON per scheme, rings and f1) once computed."""
    import json
    import os
    from mpi4py import MPI
    from rawehelix.studies import sweep
    out = {}
    for f in f1_list:
        key = (f"{p.discretisation.scheme}-{p.model.section.rings if p.discretisation.scheme == 'network' else p.discretisation.elements}"
               f"-{f:g}.json")
        path = os.path.join(cache, key) if cache else None
        if path and os.path.exists(path):
            with open(path) as fh:
                out[f] = json.load(fh)
            continue
        r = sweep.compute(p, [f], comm=MPI.COMM_SELF, track=True, log=lambda m: None)
        out[f] = r.points[0]
        if path:
            os.makedirs(cache, exist_ok=True)
            with open(path, "w") as fh:
                json.dump(out[f], fh, default=float)
    return out


def forced(rings_list, f1_list, fe_elements=8):
    """Sec. 5.3's sweep points (mobile_end, the fitted section, lead-in 2 s): T max and
    T min at s = 0 over the recorded periods, network against the FE at N = fe_elements."""
    from mpi4py import MPI
    from rawehelix.studies import sweep
    base = scene.load("mobile_end", elements=fe_elements, degree=3).replace(
        model={"kinematics": "extensible"}, section=SECTION, sweep={"lead_in_s": 2.0})

    def points(p):
        r = sweep.compute(p, f1_list, comm=MPI.COMM_SELF, track=False, log=lambda m: None)
        return {x["f1_Hz"]: x for x in r.points}

    fe = points(base)
    print(f"continuum (FE N = {fe_elements}, p = 3): " + ", ".join(
        f"{f:g} Hz: T {fe[f]['tension_min_N']:.2f}-{fe[f]['tension_max_N']:.2f} N" for f in f1_list))
    print("| rings | l [m] | " + " | ".join(f"T max at {f:g} Hz [N] | gap | T min | gap" for f in f1_list)
          + " |")
    print("|---" * (2 + 4 * len(f1_list)) + "|")
    for rings in rings_list:
        net = points(base.replace(discretisation={"scheme": "network"}, section={"rings": rings}))
        cells = " | ".join(
            f"{net[f]['tension_max_N']:.2f} | {100 * (net[f]['tension_max_N'] / fe[f]['tension_max_N'] - 1):+.2f} % | "
            f"{net[f]['tension_min_N']:.2f} | {100 * (net[f]['tension_min_N'] / fe[f]['tension_min_N'] - 1):+.2f} %"
            for f in f1_list)
        print(f"| {rings} | {base.helix.length_m / (rings - 1):.4g} | {cells} |", flush=True)


def modes53(rings_list):
    """The Sec. 5.3 helix at rest (mobile_end, the fitted section, torque and controller
    off, the top at its circle's phase 0): the lowest mode of each family, network
    against the FE continuum (N = 16, p = 3), and the network's own convergence."""
    from network_homogenisation import FAMILIES, _self_convergence, continuum, network
    p = scene.load("mobile_end", elements=16, degree=3).replace(
        model={"kinematics": "extensible"}, section=SECTION,
        controller={"target_rpm": 0.0}, torque={"top_Nm": 0.0})
    c = continuum(p)
    print(f"continuum (FE N = 16, p = 3): sag {c['sag_m']:.5f} m, T(0) {c['T0_N']:.3f} N; "
          + ", ".join(f"{k} {v:.4f} Hz" for k, v in c["modes"].items()), flush=True)
    rows = {n: network(p, n) for n in rings_list}
    rows_J = {n: network(p, n, continuum_inertia=True) for n in rings_list}
    print("| rings | l [m] | sag [m] | gap | " + " | ".join(f"{f} [Hz] | gap" for f in FAMILIES) + " |")
    print("|" + "---|" * (4 + 2 * len(FAMILIES)))
    for n in rings_list:
        r = rows[n]
        cells = [f"{n}", f"{p.helix.length_m / (n - 1):.4g}", f"{r['sag_m']:.5f}",
                 f"{100 * (r['sag_m'] / c['sag_m'] - 1):+.2f} %"]
        for f in FAMILIES:
            mine = (rows_J if f == "torsional" else rows)[n]["modes"].get(f)
            ref = c["modes"].get(f)
            cells += [f"{mine:.4f}" if mine else "-",
                      f"{100 * (mine / ref - 1):+.2f} %" if mine and ref else "-"]
        print("| " + " | ".join(cells) + " |")
    print("(torsional: each ring's polar inertia the continuum's 2 (M/L0) EI/EA l; with the "
          "hoop's: " + ", ".join(f"{n} rings {rows[n]['modes'].get('torsional', float('nan')):.4f} Hz"
                                 for n in rings_list) + ")")
    for key, name in (("sag_m", "sag [m]"),):
        _self_convergence(name, [rows[n][key] for n in rings_list], c[key])
    for f in FAMILIES:
        _self_convergence(f + " [Hz]", [(rows_J if f == "torsional" else rows)[n]["modes"][f]
                                        for n in rings_list], c["modes"][f])


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("part", choices=("torque", "spinup", "forced", "modes53"))
    ap.add_argument("--f1", default="2,4,6")
    ap.add_argument("--rings", default=None)
    ap.add_argument("--fe", default=None)
    a = ap.parse_args()
    if a.part == "torque":
        torque([int(x) for x in (a.rings or "5,9,17,33,65").split(",")])
    elif a.part == "modes53":
        modes53([int(x) for x in (a.rings or "5,9,17,33,65").split(",")])
    elif a.part == "forced":
        forced([int(x) for x in (a.rings or "5,9").split(",")], [float(x) for x in a.f1.split(",")])
    else:
        spinup([int(x) for x in (a.rings or "5,9,17").split(",")], a.fe)
