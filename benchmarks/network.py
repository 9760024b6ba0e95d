"""Section 15 of benchmarks/run.py (issue 45): the network reference's cost against the
FE continuum's at equal accuracy, CPU time (time.process_time), medians of 3.

Equal accuracy: each model at the coarsest resolution whose own discretisation error
in the compared quantity is at most 1 % of its own converged value (measured in
docs/explanation/network.md, "Cost", with the commands there):

* a Sec. 5.2 spin-up, 1 s simulated of ``nominal_operation`` with the fitted
  tensegrity section, the spin at L0/2 at 1 s: the network at 5 rings (each ring's
  polar inertia the continuum's; +0.78 % from its 33 rings) against the FE at N = 2,
  p = 3 (+0.14 % from its N = 16), both through ``simulate``'s registry;
* a sweep point of ``mobile_end`` at f1 = 3 Hz (sweep.lead_in_s = 2), its T max: the
  network at 9 rings (5 rings are 1.0 % off its finest) against the FE at N = SWEEP_N,
  p = 3, through ``sweep.compute``.  The two models' T max differ by +22 %: a
  modelling gap (network.md), not a discretisation error, so the ratio compares each
  model's cost to its own 1 %.
"""

from __future__ import annotations

import time

from mpi4py import MPI

SECTION = {"law": "tensegrity", "torsion": "members", "self_stress_N": 632.6, "bar_EA_N": 18200.0}
SPIN_RINGS, SPIN_N, SPIN_S = 5, 2, 1.0
SWEEP_RINGS, SWEEP_F1, SWEEP_N = 9, 3.0, 4


def _cpu(fn):
    t0 = time.process_time()
    out = fn()
    return time.process_time() - t0, out


def _spin_params(scheme: str):
    from rawehelix.studies import scene
    p = scene.load("nominal_operation", elements=SPIN_N, degree=3).replace(
        model={"kinematics": "extensible"}, section=SECTION)
    if scheme == "network":
        h = p.helix
        l = h.length_m / (SPIN_RINGS - 1)
        p = p.replace(discretisation={"scheme": "network"}, section={
            "rings": SPIN_RINGS,
            "ring_polar_inertia_kgm2": 2 * h.mass_kg / h.length_m * h.EI_Nm2 / h.EA_N * l})
    return p


def _sweep_params(scheme: str):
    from rawehelix.studies import scene
    p = scene.load("mobile_end", elements=SWEEP_N, degree=3).replace(
        model={"kinematics": "extensible"}, section=SECTION, sweep={"lead_in_s": 2.0})
    if scheme == "network":
        p = p.replace(discretisation={"scheme": "network"}, section={"rings": SWEEP_RINGS})
    return p


def bench_network(stats, repeats: int = 3) -> dict:
    from rawehelix.studies import simulate, sweep
    out = {"spin": {}, "sweep_point": {}}
    for scheme in ("network", "fe"):
        p = _spin_params(scheme)
        cpu, finals = [], None
        for _ in range(repeats):
            c, series = _cpu(lambda: simulate.compute(p, until_s=SPIN_S, comm=MPI.COMM_SELF,
                                                      progress=False))
            cpu.append(c)
            finals = [float(x) for x in series.spin_rpm[-1]]
        out["spin"][scheme] = {"cpu_s": stats(cpu), "spin_rpm_at_1s": finals}
        q = _sweep_params(scheme)
        cpu, point = [], None
        for _ in range(repeats):
            c, result = _cpu(lambda: sweep.compute(q, [SWEEP_F1], comm=MPI.COMM_SELF, track=False,
                                                   log=lambda m: None))
            cpu.append(c)
            point = result.points[0]
        out["sweep_point"][scheme] = {"cpu_s": stats(cpu), "tension_max_N": point["tension_max_N"],
                                      "tension_min_N": point["tension_min_N"],
                                      "periods": point["periods"]}
    for key in out:
        out[key]["ratio_network_over_fe"] = (out[key]["network"]["cpu_s"]["median"]
                                             / out[key]["fe"]["cpu_s"]["median"])
    return out


def markdown(r: dict) -> list[str]:
    s, w = r["spin"], r["sweep_point"]
    n, f = w["network"], w["fe"]
    return [
        f"| 15. network against FE, Sec. 5.2 spin-up, {SPIN_S:g} s simulated, CPU | network "
        f"{SPIN_RINGS} rings {s['network']['cpu_s']['median']:.2f} s against FE N = {SPIN_N}, p = 3 "
        f"{s['fe']['cpu_s']['median']:.2f} s: ratio {s['ratio_network_over_fe']:.2f} at equal "
        f"accuracy, each within 1 % of its own converged spin at 1 s (spin "
        f"{s['network']['spin_rpm_at_1s'][1]:.2f} against {s['fe']['spin_rpm_at_1s'][1]:.2f} rpm) "
        f"| measured (issue 45) |",
        f"| 15. network against FE, a sweep point of `mobile_end` at {SWEEP_F1:g} Hz, CPU | network "
        f"{SWEEP_RINGS} rings {n['cpu_s']['median']:.1f} s ({n['periods']} periods, T max "
        f"{n['tension_max_N']:.2f} N) against FE N = {SWEEP_N} {f['cpu_s']['median']:.1f} s "
        f"({f['periods']} periods, T max {f['tension_max_N']:.2f} N): ratio "
        f"{w['ratio_network_over_fe']:.2f} at equal accuracy (each within 1 % of its own "
        f"converged T max); the models' T max differ by "
        f"{100 * (n['tension_max_N'] / f['tension_max_N'] - 1):+.0f} %, a modelling gap at every "
        f"spacing (network.md) | measured (issue 45) |"]
