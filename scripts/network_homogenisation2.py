"""The homogenisation measured, second pass (issue 45): the network's torque-twist curve
to collapse against the continuum's members law and Tulloch's criterion, and the Sec.
5.2 spin-up, network (references/network/dynamics.py) against the FE continuum, at
several ring spacings.  Prints the tables of docs/explanation/network.md.

    .venv/bin/python scripts/network_homogenisation2.py torque [--rings 5,9,17,33,65]
    .venv/bin/python scripts/network_homogenisation2.py spinup --fe DIR [--rings 5,9,17]
    .venv/bin/python scripts/network_homogenisation2.py forced [--rings 5,9] [--f1 2,4,6] [--cache DIR]
    .venv/bin/python scripts/network_homogenisation2.py modes53 [--rings 5,9,17,33,65]
    .venv/bin/python scripts/network_homogenisation2.py operating --fe DIR [--rings 5,9,17,33]
    .venv/bin/python scripts/network_homogenisation2.py step --fe DIR --net DIR

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


def _slack(point):
    """The first slack tether of a point's block: 't = T s (phase P of the period), s = S m',
    or the smallest member force when none goes slack."""
    b = point["limits"]
    first = (b.get("first_by_kind") or {}).get("slack")
    if first:
        phase = (first["t_s"] * point["f1_Hz"]) % 1.0
        return f"t = {first['t_s']:.3f} s (phase {phase:.2f}), s = {first['s_m']:.2f} m"
    f = b.get("min_member_force_N") or {}
    return f"none (min {f.get('value', float('nan')):.0f} N at s = {f.get('s_m', float('nan')):.2f} m)"


def forced(rings_list, f1_list, fe_elements=8, cache=None):
    """Sec. 5.3's sweep points (mobile_end as shipped, the fitted section, lead-in 2 s):
    T max and T min at s = 0 over the recorded periods, the first slack member and the
    largest moment ratio |M| / (N R) (each model's limits block from its own members),
    network against the FE at N = fe_elements; the gap in T max against l and its
    observed order.  ``cache``: a directory that keeps each point (sweep_points)."""
    base = forced_base(fe_elements)
    fe = sweep_points(base, f1_list, cache)
    nets = {r: sweep_points(base.replace(discretisation={"scheme": "network"},
                                         section={"rings": r}), f1_list, cache)
            for r in rings_list}
    print("| f1 [Hz] | model | T max [N] | gap | T min [N] | gap | first slack | "
          "max \\|M\\|/(N R) | gap |")
    print("|---|---|---|---|---|---|---|---|---|")
    for f in f1_list:
        c = fe[f]
        rows = [(f"FE N = {fe_elements}", c)] + [
            (f"network {r} rings (l = {base.helix.length_m / (r - 1):.3g} m)", nets[r][f])
            for r in rings_list]
        for label, x in rows:
            gap = "" if x is c else f"{100 * (x['tension_max_N'] / c['tension_max_N'] - 1):+.1f} %"
            gmin = "" if x is c else f"{100 * (x['tension_min_N'] / c['tension_min_N'] - 1):+.1f} %"
            mr = x.get("moment_ratio_max")
            gmr = "" if x is c or not mr else f"{100 * (mr / c['moment_ratio_max'] - 1):+.0f} %"
            print(f"| {f:g} | {label} | {x['tension_max_N']:.2f} | {gap} | {x['tension_min_N']:.2f} | "
                  f"{gmin} | {_slack(x)} | {mr:.3f} | {gmr} |" if mr is not None else
                  f"| {f:g} | {label} | {x['tension_max_N']:.2f} | {gap} | {x['tension_min_N']:.2f} | "
                  f"{gmin} | {_slack(x)} | - | |")
    ls = [base.helix.length_m / (r - 1) for r in rings_list]
    print("\nthe T max gap against l, and its observed order between successive spacings:")
    for f in f1_list:
        gaps = [nets[r][f]["tension_max_N"] / fe[f]["tension_max_N"] - 1 for r in rings_list]
        diffs = [nets[a][f]["tension_max_N"] - nets[b][f]["tension_max_N"]
                 for a, b in zip(rings_list, rings_list[1:])]
        print(f"  {f:g} Hz: gaps " + ", ".join(f"{100 * g:+.2f} %" for g in gaps)
              + "; network's own differences " + ", ".join(f"{d:+.3f} N" for d in diffs))


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


def operating(rings_list, fe_dir):
    """The machine's relative equilibrium (rotor_example, the fitted section) at each wind
    of the FE's ``rawehelix operate ... -o fe_dir``: the network's rotor rpm, power,
    both ends' axial forces and twist against the FE's (references/network/start.py)."""
    import json
    from rawehelix.references.network.start import operating_state
    with open(f"{fe_dir}/summary.json") as fh:
        fe = json.load(fh)
    details = {d["wind_m_s"]: d for d in fe["details"]}
    print("| wind [m/s] | model | rotor [rpm] | gap | power [W] | gap | T(0) [N] | gap | "
          "T(L0) [N] | twist [deg] | gap | V_n / V |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for e in fe["points"]:
        V, d = e["wind_m_s"], details[e["wind_m_s"]]
        T0 = d["tension_ground_N"]
        print(f"| {V:g} | FE N = {fe['elements'] if 'elements' in fe else '16'} | {e['rotor_rpm']:.3f} | | "
              f"{e['power_W']:.2f} | | {T0:.2f} | | {e['tension_min_N']:.2f}-{e['tension_max_N']:.2f} | "
              f"{e['twist_deg']:.2f} | | {d['v_n_m_s'] / d['hub_wind_m_s']:.5f} |")
        for rings in rings_list:
            p = scene.load("rotor_example").replace(model={"kinematics": "extensible"},
                                                    section={**SECTION, "rings": rings},
                                                    wind={"speed_m_s": V})
            n = operating_state(p)
            print(f"| {V:g} | network {rings} rings | {n['rotor_rpm']:.3f} | "
                  f"{100 * (n['rotor_rpm'] / e['rotor_rpm'] - 1):+.3f} % | {n['power_W']:.2f} | "
                  f"{100 * (n['power_W'] / e['power_W'] - 1):+.3f} % | {n['tension_ground_N']:.2f} | "
                  f"{100 * (n['tension_ground_N'] / T0 - 1):+.2f} % | {n['tension_top_N']:.2f} | "
                  f"{n['twist_deg']:.2f} | {100 * (n['twist_deg'] / e['twist_deg'] - 1):+.2f} % | "
                  f"{n['axis_factor']:.5f} |", flush=True)


def stepped(fe_dir, net_dir, times=(0.0, 5.0, 6.0, 7.0, 8.0, 10.0, 12.0)):
    """The wind step of step_rated: the rotor's (top ring's) spin [rpm] of the network's
    ``simulate`` run against the FE's (their time_series.csv), at ``times``."""
    def read(d):
        with open(f"{d}/time_series.csv") as fh:
            rows = list(csv.reader(fh))
        head = rows[0]
        data = np.array([[float(x) for x in r] for r in rows[1:]])
        return head, data
    hf, fe = read(fe_dir)
    hn, net = read(net_dir)
    col = "spin_L0_rpm"
    top_f, top_n = fe[:, hf.index(col)], net[:, hn.index(col)]
    print("| t [s] | FE rotor [rpm] | network [rpm] | gap |")
    print("|---|---|---|---|")
    for t in times:
        a, b = np.interp(t, fe[:, 0], top_f), np.interp(t, net[:, 0], top_n)
        print(f"| {t:g} | {a:.3f} | {b:.3f} | {100 * (b / a - 1):+.3f} % |")
    common = np.linspace(0.0, min(fe[-1, 0], net[-1, 0]), 2001)
    gap = np.interp(common, net[:, 0], top_n) - np.interp(common, fe[:, 0], top_f)
    print(f"largest |gap| {np.max(np.abs(gap)):.3f} rpm at t = {common[np.argmax(np.abs(gap))]:.2f} s")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("part", choices=("torque", "spinup", "forced", "modes53", "operating", "step"))
    ap.add_argument("--net", default=None, help="step: the network's simulate folder")
    ap.add_argument("--f1", default="2,4,6")
    ap.add_argument("--rings", default=None)
    ap.add_argument("--fe", default=None)
    ap.add_argument("--cache", default=None, help="forced: a directory keeping each point")
    a = ap.parse_args()
    if a.part == "torque":
        torque([int(x) for x in (a.rings or "5,9,17,33,65").split(",")])
    elif a.part == "operating":
        operating([int(x) for x in (a.rings or "5,9,17,33").split(",")], a.fe)
    elif a.part == "step":
        stepped(a.fe, a.net)
    elif a.part == "modes53":
        modes53([int(x) for x in (a.rings or "5,9,17,33,65").split(",")])
    elif a.part == "forced":
        forced([int(x) for x in (a.rings or "5,9").split(",")], [float(x) for x in a.f1.split(",")],
               cache=a.cache)
    else:
        spinup([int(x) for x in (a.rings or "5,9,17").split(",")], a.fe)
