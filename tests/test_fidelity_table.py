"""Smoke test of benchmarks/fidelity.py's table builder on tiny hand-made rows (no solve)."""

import importlib.util
from pathlib import Path

SPEC = importlib.util.spec_from_file_location(
    "fidelity", Path(__file__).resolve().parents[1] / "benchmarks" / "fidelity.py")
fidelity = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(fidelity)


def _modes(f, decay, cpu):
    return {"cpu_s": cpu, "first": {"torsional": {"frequency_Hz": f, "decay_per_s": decay}}}


def test_table_changes_costs_and_pending_rows():
    results = {
        "modes": {"paper": _modes(2.0, 0.0, 1.0), "damping": _modes(1.9, 0.25, 3.0)},
        "simulate": {"paper": {"cpu_s": 2.0, "settling_time_s": 4.0,
                               "peak_ground_torque_Nm": 10.0, "max_spin_lag_rpm": 16.0,
                               "tension_range_N": [198.0, 203.0]},
                     "damping": {"cpu_s": 3.0, "paper_cpu_s": 1.0, "settling_time_s": None,
                                 "peak_ground_torque_Nm": 11.0, "max_spin_lag_rpm": 10.0,
                                 "tension_range_N": [198.5, 202.5]}},
        "orbits": {"paper": {"cpu_s": 10.0, "cpu_per_point_s": 1.0, "points": 10,
                             "fold": {"f1_Hz": 12.7, "tension_max_N": 540.0},
                             "peak": {"f1_Hz": 12.6, "tension_max_N": 560.0, "at_end": False},
                             "f1_last_Hz": 12.69},
                   "damping": {"cpu_s": 30.0, "cpu_per_point_s": 1.5, "points": 20, "fold": None,
                               "peak": {"f1_Hz": 12.9, "tension_max_N": 420.0, "at_end": True},
                               "f1_last_Hz": 12.9}}}
    results["sweep"] = {name: {"cpu_s": cpu, "jump_Hz": jump, "jump_N": [T, 120.0],
                               "peak": {"f1_Hz": jump[0], "tension_max_N": T}}
                        for name, cpu, jump, T in (("paper", 2.0, [12.7, 12.8], 500.0),
                                                   ("damping", 1.0, [11.9, 12.0], 400.0))}
    results["modes"][fidelity.HYSTERESIS] = {"refused": "no modes with z"}
    results["orbits"]["EI law + damping"] = {"failed": "Newton did not converge"}
    table = fidelity.build_table(results)
    rows = {line.split(" | ")[0] + " | " + str(i): line
            for i, line in enumerate(table.splitlines()) if line.startswith("| damping")}
    modes, sim, orb, sweep = rows.values()
    assert "1.9000, 0.2500 (-5.00 %, +0.2500)" in modes and modes.endswith("x3.00 |")
    assert "not settled" in sim and "11.000 (+10.00 %)" in sim and sim.endswith("x3.00 |")  # its own process's paper
    assert "| 10.000 | 198.50-202.50 |" in sim
    assert "none to 12.90 Hz" in orb and "12.9000 (window end) +0.300 Hz" in orb
    assert "420.0 (-25.00 %)" in orb and "1.50 s (x1.50)" in orb
    assert sweep == "| damping | 11.9-12.0 (400 -> 120) | 400.0 (11.9) -20.00 % | x0.50 |"
    refused = [x for x in table.splitlines() if x.startswith(f"| {fidelity.HYSTERESIS} |")][0]
    assert refused == f"| {fidelity.HYSTERESIS} | refused: no modes with z | - |"
    # every option without a row says so in all three tables
    failed = [x for x in table.splitlines() if x.startswith("| EI law + damping |")][2]
    assert failed == "| EI law + damping | failed: Newton did not converge | - | - | - | - |"
    for name in fidelity.OPTIONS:
        if name not in ("paper", "damping", "EI law + damping"):
            lines = [x for x in table.splitlines() if x.startswith(f"| {name} |")]
            assert len(lines) == 4 and all("pending" in x for x in lines)
