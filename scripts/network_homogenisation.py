"""The homogenisation measured (issue 45, first pass): the ring-and-tether network
(references/network) against the FE continuum of the same members, for the Table 2
helix with the tensegrity section identified from the lab tests (issue 29: beta = 0,
P0 = 632.6 N per tether, bars EA_b = EA / 2; docs/explanation/section.md), at several
ring counts; and the network's own EA, EI, GJ from the lab tests of Sec. 4 on the
6.76 m segment.  Prints the tables of docs/explanation/network.md.

    .venv/bin/python scripts/network_homogenisation.py [--rings 5,9,17,33,65,129]

About 2 minutes (the FE runs); the network's part is seconds.
"""

from __future__ import annotations

import argparse
import math

import numpy as np
from mpi4py import MPI

from rawehelix.references.network import Network, solve
from rawehelix.references.network import energy as en
from rawehelix.references.network.modes import lowest_of_each, modes
from rawehelix.studies import modes as fe_modes
from rawehelix.studies import scene, stationary

FAMILIES = ("lateral_in_plane", "lateral_out_of_plane", "torsional", "longitudinal")
#: the tensegrity section that fits the axial and torsion tests (section.md's table)
SECTION = {"law": "tensegrity", "torsion": "members", "self_stress_N": 632.6, "bar_EA_N": 18200.0}
#: the other fit of the axial and torsion tests: a lay with the end held (section.md)
LAID = {"self_stress_N": 0.0, "bar_EA_N": 0.0, "lay_angle_deg": 16.8, "tether_EA_N": 6910.2}
LAB_LENGTH_M, LAB_TENSIONS_N = 6.76, (90.0, 181.0, 259.0)


def table2():
    return scene.load("stationary_table2", elements=16, degree=3).replace(
        model={"kinematics": "extensible"}, section=SECTION)


def continuum(p):
    """The FE continuum's stationary (sag, T(0), smallest member force) and lowest modes."""
    st = stationary.compute(p, MPI.COMM_SELF).summary
    found = fe_modes.compute(p, comm=MPI.COMM_SELF)
    low = {}
    for m in sorted(found, key=lambda m: m.frequency_Hz):
        if m.period_s is not None:
            low.setdefault(m.family, m.frequency_Hz)
    return {"sag_m": st["sag_m"], "T0_N": st["tension_N"]["s0"],
            "f_min_N": st["limits"]["min_member_force_N"]["value"], "modes": low}


def network(p, rings, continuum_inertia=False):
    """The network's stationary and lowest modes; ``continuum_inertia``: each ring's polar
    inertia the continuum's twist inertia 2 (M / L0) EI / EA (Eq. 27's delta) times l."""
    h = p.helix
    sec = {"rings": rings}
    if continuum_inertia:
        l = h.length_m / (rings - 1)
        sec["ring_polar_inertia_kgm2"] = 2 * h.mass_kg / h.length_m * h.EI_Nm2 / h.EA_N * l
    r = solve(Network.from_parameters(p.replace(section=sec)))
    f_min = r.smallest_tether_force[0]
    return {"sag_m": r.sag_m(), "T0_N": float(r.tension_N()[0]), "f_min_N": f_min,
            "modes": lowest_of_each(modes(r)), "slack": len(r.slack)}


def lab(p, rings_per_m, T, section=None):
    """The network's EA, apparent EI (Eq. 63, tip force) and GJ of the 6.76 m segment
    clamped at the ground ring, the top ring pulled by the dead tension T: the top
    ring's compliance at the straight state (the interior condensed).  The top ring is
    free but for its turn about the axis in the axial and bending tests (the lab's end
    fixture holds a laid segment's twist: unheld, its lay unwinds, section.md)."""
    p = p.replace(section=section) if section else p
    members = p.model.section.members(p.helix)
    EA = members.taut_moduli()["EA"]
    rings = max(2, round(LAB_LENGTH_M * rings_per_m) + 1)
    q = p.replace(helix={"length_m": LAB_LENGTH_M}, ends={"elongation": T / EA},
                  model={"gravity": False, "drag": False}, section={"rings": rings})
    net = Network.from_parameters(q)
    H = en.gradient_hessian(net, en.State(*net.reference()))[1].toarray()[6:, 6:]
    top, E = H.shape[0] - 6, net.frame
    B = np.eye(H.shape[0])  # the top ring's dofs in the chord frame (e1, e2, e3)
    B[top:top + 3, top:top + 3] = B[top + 3:, top + 3:] = E
    H = B.T @ H @ B

    def compliance(dof, hold_twist):
        keep = [i for i in range(H.shape[0]) if not (hold_twist and i == top + 5)]
        load = np.zeros(len(keep))
        load[keep.index(top + dof)] = 1.0
        return float(np.linalg.solve(H[np.ix_(keep, keep)], load)[keep.index(top + dof)])

    L = float(np.linalg.norm(net.chord_m))
    return {"rings": rings, "EA_N": L / compliance(2, True),
            "EI_apparent_Nm2": L**3 / (3 * compliance(0, True)),
            "GJ_Nm2": L / compliance(5, False)}


def tensioned_cantilever_EI(EI, T, L):
    """The apparent EI of Eq. (63) of an Euler-Bernoulli cantilever of stiffness EI under
    the dead tension T (labtest.md): T L^2 / (3 (1 - tanh(kL) / (kL))), k^2 = T / EI."""
    kL = math.sqrt(T / EI) * L
    return T * L * L / (3 * (1 - math.tanh(kL) / kL))


def rate(gaps, ls):
    """The observed order between successive spacings, log(g1/g2) / log(l1/l2)."""
    return [None] + [math.log(abs(g1 / g2)) / math.log(l1 / l2) if g1 and g2 else None
                     for g1, g2, l1, l2 in zip(gaps, gaps[1:], ls, ls[1:])]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rings", default="5,9,17,33,65,129")
    args = ap.parse_args()
    counts = [int(x) for x in args.rings.split(",")]
    p = table2()
    c = continuum(p)
    print(f"continuum (FE N = 16, p = 3): sag {c['sag_m']:.5f} m, T(0) {c['T0_N']:.3f} N, "
          f"smallest member force {c['f_min_N']:.2f} N; lowest modes "
          + ", ".join(f"{k} {v:.4f} Hz" for k, v in c["modes"].items()))
    rows = {n: network(p, n) for n in counts}
    rows_J = {n: network(p, n, continuum_inertia=True) for n in counts}
    ls = [p.helix.length_m / (n - 1) for n in counts]
    print("\n| rings | l [m] | sag [m] | gap | rate | T(0) [N] | gap | smallest tether [N] | "
          + " | ".join(f"{f} [Hz] | gap" for f in FAMILIES) + " |")
    print("|" + "---|" * (8 + 2 * len(FAMILIES)))
    gaps = {k: [rows[n][k] / c[k] - 1 for n in counts] for k in ("sag_m", "T0_N")}
    sag_rates = rate(gaps["sag_m"], ls)
    for i, n in enumerate(counts):
        r = rows[n]
        cells = [f"{n}", f"{ls[i]:.4g}", f"{r['sag_m']:.5f}", f"{100 * gaps['sag_m'][i]:+.2f} %",
                 "-" if sag_rates[i] is None else f"{sag_rates[i]:.2f}",
                 f"{r['T0_N']:.3f}", f"{100 * gaps['T0_N'][i]:+.3f} %", f"{r['f_min_N']:.2f}"]
        for f in FAMILIES:
            mine = rows_J[n]["modes"].get(f) if f == "torsional" else r["modes"].get(f)
            ref = c["modes"].get(f)
            cells += [f"{mine:.4f}" if mine else "-",
                      f"{100 * (mine / ref - 1):+.2f} %" if mine and ref else "-"]
        print("| " + " | ".join(cells) + " |")
    print("\n(torsional: the network with each ring's polar inertia the continuum's "
          "2 (M/L0) EI/EA l; with the hoop's m R^2, its default:)")
    for n in counts:
        print(f"  rings {n}: torsional {rows[n]['modes'].get('torsional', float('nan')):.4f} Hz")
    members = p.model.section.members(p.helix)
    taut = members.taut_moduli()
    print("\nthe network's own convergence: successive differences d(l) = q(l) - q(l/2), "
          "their observed order, and the gap of the Richardson limit to the continuum")
    for key, name in (("sag_m", "sag [m]"), ("T0_N", "T(0) [N]")):
        q = [rows[n][key] for n in counts]
        _self_convergence(name, q, c[key])
    for f in FAMILIES:
        q = [(rows_J if f == "torsional" else rows)[n]["modes"][f] for n in counts]
        _self_convergence(f + " [Hz]", q, c["modes"][f])
    # the laid layout's bays turn by delta_0 = l tan(beta) / R: 1.6 rad at l = 1 m, past
    # any real helix's; its rows start where delta_0 <= 0.4 rad
    for label, section, spacings in (
            ("self-stressed (beta = 0, P0 = 632.6 N, bars EA/2)", None, (ls[0], ls[-1])),
            ("laid (beta = 16.8 deg, k = 6910.2 N, no self-stress)", LAID, (ls[-2], ls[-1]))):
        members = (p.replace(section=section) if section else p).model.section.members(p.helix)
        taut = members.taut_moduli()
        print(f"\n{label}: members' closed forms EA {taut['EA']:.1f} N, EI {taut['EI']:.1f} "
              f"N m^2, GJ {taut['GJ']:.2f} N m^2 (at zero strain)")
        print("\n| rings per m | T_e [N] | segment rings | EA [N] | GJ [N m^2] | apparent EI, "
              "network [N m^2] | apparent EI, continuum of the members | lab, Eq. (64) |")
        print("|---|---|---|---|---|---|---|---|")
        for per_m in (1 / x for x in spacings):
            for T in LAB_TENSIONS_N:
                x = lab(p, per_m, T, section)
                cont = tensioned_cantilever_EI(taut["EI"], T, LAB_LENGTH_M)
                print(f"| {per_m:.3f} | {T:g} | {x['rings']} | {x['EA_N']:.1f} | "
                      f"{x['GJ_Nm2']:.2f} | {x['EI_apparent_Nm2']:.1f} | {cont:.1f} | "
                      f"{52.4 * T + 2290:.0f} |")


def _self_convergence(name, q, continuum_value):
    d = [a - b for a, b in zip(q, q[1:])]
    orders = [math.log2(abs(a / b)) if a and b else float("nan") for a, b in zip(d, d[1:])]
    order = orders[-1] if orders and math.isfinite(orders[-1]) and orders[-1] > 0.5 else 2.0
    limit = q[-1] - d[-1] / (2**order - 1)  # Richardson
    print(f"  {name}: d = " + ", ".join(f"{x:.3g}" for x in d) + "; orders "
          + ", ".join(f"{x:.2f}" for x in orders)
          + f"; limit {limit:.6g}, continuum {continuum_value:.6g}, gap "
          f"{100 * (limit / continuum_value - 1):+.3f} %")


if __name__ == "__main__":
    main()
