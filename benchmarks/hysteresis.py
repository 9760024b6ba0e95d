"""The Sec. 5.2 spin-up with hysteretic torsion ([torsion_hysteresis], forms/hysteresis.py).

``nominal_operation`` (Sec. 5.2: fixed ends, the rotor's 25 Nm ramp, the PD
controller to 120 rpm) with the paper's elastic torsion and with the Bouc-Wen
law of ``FIG5`` (docs/physics.md says how it was chosen): the settling time
(2 % band), the peak ground torque, the final spins and torque, and the CPU
time (time.process_time) of each run after one short run that compiles the
forms.  Both runs: alpha2, the scene's adaptive steps.

    .venv/bin/python benchmarks/hysteresis.py [--elements 16] [--until 30]

Prints the markdown of docs/physics.md (section 'hysteretic torsion').
Serial (COMM_SELF); a benchmark, not a test.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from mpi4py import MPI

from rawehelix.studies import scene, simulate

#: the Bouc-Wen law of docs/physics.md (chosen against the torsion test of Fig. 5)
FIG5 = {"rho": 0.5, "A": 2.39, "beta_m_n": 4.78, "gamma_m_n": 4.78, "n": 1.0}


def run(params, until_s):
    start = time.process_time()
    series = simulate.compute(params, until_s=until_s, comm=MPI.COMM_SELF, progress=False)
    cpu = time.process_time() - start
    rows = series.rows
    s = series.summary
    return {"cpu_s": cpu, "steps": s["steps"], "newton": s["newton_iterations"],
            "settling_s": s["settling_time_s"], "peak_ground_Nm": float(np.max(np.abs(rows[:, 4]))),
            "final_ground_Nm": float(rows[-1, 4]), "final_spin_rpm": float(rows[-1, 1]),
            "tension_range_N": s.get("tension_range_N")}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=16)
    ap.add_argument("--until", type=float, default=30.0)
    args = ap.parse_args()
    base = scene.load("nominal_operation", elements=args.elements)
    hyst = base.replace(torsion_hysteresis=FIG5)
    for p in (base, hyst):  # compile the forms
        run(p, 0.01)
    results = {"paper (elastic GJ)": run(base, args.until), "Bouc-Wen (Fig. 5)": run(hyst, args.until)}
    ref = results["paper (elastic GJ)"]
    print(f"N = {args.elements}, {args.until:g} s simulated, alpha2 adaptive\n")
    print("| torsion | settling (2 %) [s] | peak ground torque [Nm] | final ground torque [Nm] "
          "| final spin s=0 [rpm] | tension range [N] | steps | Newton | CPU [s] | CPU ratio |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, r in results.items():
        tr = r["tension_range_N"]
        settle = "-" if r["settling_s"] is None else f"{r['settling_s']:.3f}"
        print(f"| {name} | {settle} | {r['peak_ground_Nm']:.3f} | {r['final_ground_Nm']:.3f} | "
              f"{r['final_spin_rpm']:.3f} | {tr[0]:.2f}-{tr[1]:.2f} | {r['steps']} | {r['newton']} "
              f"| {r['cpu_s']:.1f} | {r['cpu_s'] / ref['cpu_s']:.2f} |")


if __name__ == "__main__":
    main()
