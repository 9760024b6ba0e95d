# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # The power curve up to the helix's first limit
#
# Put a rotor at the top of the Sec. 5.2 helix and a generator at the ground,
# and let the wind blow. At each wind speed the machine settles to a relative
# equilibrium: the helix still, spinning at one rate Omega. `rh.operate`
# solves these states directly, one wind speed after another. Omega comes
# from the torque balance of the rotor and the generator, and the helix's
# shape is the stationary state under the rotor's torque. The run stops at
# the first wind speed where the helix reaches one of its limits.
#
# The scene `rotor_example` is Table 2's helix with an illustrative rotor
# (R = 2 m, a made-up Cp/CT table, not a measured rotor) and an MPPT generator,
# tau = k Omega^2. The gain k gives the paper's 25 N m at 120 rpm at 6.61 m/s.
#
# Run it with `.venv/bin/python docs/tutorials/power_curve.py`
# (`RAWEHELIX_TUTORIAL_SMALL=1`: N = 4 and fewer wind speeds, as the tests do).

# %%
import math
import os
from pathlib import Path

import scipy.interpolate
import scipy.optimize

import rawehelix as rh
from rawehelix.operation.rotor import from_params as rotor_of

SMALL = os.environ.get("RAWEHELIX_TUTORIAL_SMALL") == "1"
OUT = Path(os.environ.get("RAWEHELIX_TUTORIAL_OUT", "results/tutorials"))
OUT = OUT / "power_curve"
N = 4 if SMALL else 8
STEP = 1.0 if SMALL else 0.5  # m/s between wind speeds

# %% [markdown]
# ## The run
#
# `wind_m_s` is the wind at the reference height (the scene's `[wind]`
# profile; uniform here). The rotor sees V_n, the wind along its axis: the
# helix's end tangent, about V cos 45 deg. `rh.operate` traces the torque
# balance's branches through any fold in the wind, then solves the helix at
# each wind speed on each branch. That takes at most 3 stationary solves a
# point.

# %%
scene = rh.load_scene("rotor_example", elements=N)
winds = [3.0 + STEP * k for k in range(int(12 / STEP) + 1)]  # 3 to 15 m/s
result = rh.operate(scene, wind_m_s=winds)
s = result.summary
solves = s["stationary_solves"]
print(f"{len(s['points'])} points, {solves['total']} stationary solves "
      f"(at most {solves['max_per_point']} a point), {s['wall_s']:.1f} s")
print(" V [m/s]  rpm     P [W]   Q [N m]  T min..max [N]   twist [deg]")
for p in s["points"]:
    T = f"{p['tension_min_N']:5.1f}..{p['tension_max_N']:5.1f}"
    print(f"{p['wind_m_s']:7.1f}  {p['rotor_rpm']:5.1f}  {p['power_W']:7.1f}  "
          f"{p['torque_top_Nm']:6.2f}   {T}   {p['twist_deg']:7.1f}")

# %% [markdown]
# ## The first limit, and why the curve stops
#
# Every point carries the `limits` block that every command reports.
# `first_limit` is the first wind speed where a point reaches one of the
# limits: a slack tether, a saturated moment, or Tulloch's torsional collapse
# where the scene gives its rings. `stopped` says why the curve ends.

# %%
first = s["first_limit"]
print("first limit:", first["kind"], "at", first["wind_m_s"], "m/s, s =",
      round(first["s_m"], 3), "m")
print("stopped:", s["stopped"])
assert first["wind_m_s"] == s["points"][-1]["wind_m_s"]  # the curve ends there

# %% [markdown]
# ## A check against the rotor's table alone
#
# Under tau = k Omega^2 the rotor runs at one tip-speed ratio at every wind
# speed. That ratio is the root of Cp(lambda) = k lambda^3 / (1/2 rho pi R^5),
# and the power is 1/2 rho pi R^2 V_n^3 Cp(lambda), with V_n the wind along the
# solved helix's end tangent (`details[].v_n_m_s`). Below, scipy finds the
# root on the table's own monotone cubic, which knows nothing of the helix or
# of rawehelix's laws.

# %%
rotor = rotor_of(scene)
R, k = rotor.radius_m, scene.generator.mppt_gain_Nms2
Cp = scipy.interpolate.PchipInterpolator(rotor.table_tsr, rotor.table_cp)
c = 0.5 * 1.225 * math.pi * R**5
lam = scipy.optimize.brentq(lambda x: Cp(x) - k * x**3 / c,
                            rotor.table_tsr[0], rotor.table_tsr[-1], xtol=1e-14)
for p, d in zip(s["points"], s["details"]):
    closed = 0.5 * 1.225 * math.pi * R**2 * d["v_n_m_s"]**3 * float(Cp(lam))
    assert abs(p["power_W"] / closed - 1) < 1e-9 and abs(p["tsr"] / lam - 1) < 1e-9
print(f"tsr = {lam:.6f} (the table's best: {rotor.tsr_opt:g}) and "
      f"P = 1/2 rho pi R^2 V_n^3 Cp(tsr) at all {len(s['points'])} points, to 1e-9")

# %% [markdown]
# ## Results on disk
#
# `write` puts `summary.json` and `power_curve.png` in the folder. The figure
# shows the power, the rotor's speed, the tension (max and min along s) and
# the smallest tether force on one wind axis, with the first limit marked.
# Unstable branches are dashed. The command line does the same:
# `rawehelix operate rotor_example --wind 3:15:0.5 --elements 8 -o DIR`.

# %%
result.write(OUT)
print("written:", OUT)
