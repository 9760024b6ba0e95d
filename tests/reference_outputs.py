"""Reference outputs of the redesign (issue 28): the numbers every step of it must
leave unchanged to round-off (REL = 1e-10 relative, tests/test_reference_outputs.py).

They were recorded on main before the first step, by

    .venv/bin/python tests/reference_outputs.py --record

into tests/data/reference_outputs.json, and are never re-recorded by a refactoring:
a step that moves one of them past REL changes the physics or the numerics, and
must say so in its own commit.  Small N keeps them quick (about 40 s in all).

Each entry is a flat {name: number}; ``compute(kind)`` gives one kind afresh.
The orbit is reached through :func:`_orbit`, the one place that names the
periodic-orbit solver's classes (a refactoring of them changes this adapter, not
the recorded numbers).
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

DATA = Path(__file__).parent / "data" / "reference_outputs.json"
REL = 1e-10  # relative: round-off (issue 28)

FIG5 = {"rho": 0.5, "A": 2.39, "beta_m_n": 4.78, "gamma_m_n": 4.78, "n": 1.0}  # Fig. 5's law
DAMPING = {"axial_s": 1e-4, "bending_s": 1e-3, "torsion_s": 1e-3}  # the fidelity table's


def _rh():
    import rawehelix as rh
    return rh


def _comm():
    from mpi4py import MPI
    return MPI.COMM_SELF


def _orbit(scene, f1_Hz: float):
    """The periodic orbit at f1 from the stationary state (shooting, 5 lead-in periods)."""
    from rawehelix.solvers.orbits import AlphaMap
    m = AlphaMap(scene)
    return m.orbit(m.X_stationary, f1_Hz, lead_in=5)


def _orbit_numbers(o, prefix: str) -> dict:
    out = {f"{prefix}.tension_max_N": o.tension_max_N, f"{prefix}.tension_min_N": o.tension_min_N}
    mod = np.sort(np.abs(np.asarray(o.multipliers)))[::-1][:6]
    out.update({f"{prefix}.multiplier_modulus_{k}": float(v) for k, v in enumerate(mod)})
    return out


def stationary() -> dict:
    """T(0), T(1) and the midpoint of the Sec. 5.1 state (Table 2 helix, N = 8)."""
    rh = _rh()
    st = rh.stationary(rh.load_scene("stationary_table2", elements=8), comm=_comm())
    mid = st.centre_line_m[len(st.s_m) // 2]
    return {"T0_N": float(st.tension_N[0]), "T1_N": float(st.tension_N[-1]),
            "mid_x_m": float(mid[0]), "mid_z_m": float(mid[2])}


def _spectrum(scene, prefix: str) -> dict:
    rh = _rh()
    modes = rh.modes(scene, count=10, comm=_comm())
    out = {}
    for k, m in enumerate(modes):
        out[f"{prefix}.{k}.frequency_Hz"] = float(m.frequency_Hz or 0.0)
        out[f"{prefix}.{k}.decay_per_s"] = float(m.decay_per_s or 0.0)
    return out


def spectrum() -> dict:
    """The ten slowest modes of Table 3's scene (N = 8, FE) and the spline reference."""
    rh = _rh()
    out = _spectrum(rh.load_scene("stationary_table2", elements=8), "fe")
    out.update(_spectrum(rh.load_scene("stationary_table2", elements=2, scheme="spline"),
                         "spline"))
    return out


def damped_spectrum() -> dict:
    """The damped variant of the spectrum (Kelvin-Voigt, N = 8)."""
    rh = _rh()
    return _spectrum(rh.load_scene("stationary_table2", elements=8).replace(damping=DAMPING),
                     "damped")


def sweep_point() -> dict:
    """The brute-force periodic response at 10 Hz (mobile_end, N = 4)."""
    rh = _rh()
    (p,) = rh.sweep(rh.load_scene("mobile_end", elements=4), [10.0], comm=_comm()).points
    return {k: float(p[k]) for k in ("tension_max_N", "tension_min_N", "tension_mean_N")}


def orbit() -> dict:
    """The shooting orbit at 11.5 Hz and its six largest multipliers (mobile_end, N = 4)."""
    rh = _rh()
    return _orbit_numbers(_orbit(rh.load_scene("mobile_end", elements=4), 11.5), "orbit")


def damped_orbit() -> dict:
    """The damped orbit at 11.5 Hz (the fidelity table's retardation times, N = 4)."""
    rh = _rh()
    sc = rh.load_scene("mobile_end", elements=4).replace(damping=DAMPING)
    return _orbit_numbers(_orbit(sc, 11.5), "damped_orbit")


def hysteretic_orbit() -> dict:
    """The hysteretic (Fig. 5 Bouc-Wen) orbit at 11.5 Hz (N = 4), z carried."""
    rh = _rh()
    sc = rh.load_scene("mobile_end", elements=4).replace(torsion_hysteresis=FIG5)
    return _orbit_numbers(_orbit(sc, 11.5), "hysteretic_orbit")


def study_csv() -> dict:
    """study.csv of a two-point EI study (nominal_operation, N = 4): every number."""
    from rawehelix.studies import study
    with tempfile.TemporaryDirectory() as tmp:
        source = study.Source("nominal_operation", elements=4)
        vary = study.parse_vary("helix.EI_Nm2=12000:13000:2")
        result = study.compute(source, [vary], ["tension_s0_N", "lateral_frequency_Hz"],
                               Path(tmp), fd_step=0, comm=_comm())
        result.write(Path(tmp))
        lines = (Path(tmp) / "study.csv").read_text().splitlines()
    head = lines[0].split(",")
    out = {}
    for row in lines[1:]:
        cells = dict(zip(head, row.split(",")))
        for q in ("tension_s0_N", "lateral_frequency_Hz"):
            out[f"EI={cells['helix.EI_Nm2']}.{q}"] = float(cells[q])
    return out


KINDS = {f.__name__: f for f in (stationary, spectrum, damped_spectrum, sweep_point, orbit,
                                 damped_orbit, hysteretic_orbit, study_csv)}


def recorded() -> dict:
    return json.loads(DATA.read_text())


if __name__ == "__main__":
    import petsc4py
    petsc4py.init([])
    if sys.argv[1:] != ["--record"]:
        sys.exit("usage: python tests/reference_outputs.py --record")
    import time
    got = {}
    for name, f in KINDS.items():
        t = time.perf_counter()
        got[name] = f()
        print(f"{name}: {time.perf_counter() - t:.1f} s", flush=True)
    DATA.parent.mkdir(exist_ok=True)
    DATA.write_text(json.dumps(got, indent=1, sort_keys=True) + "\n")
    print("wrote", DATA)
