# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # A frequency response and its unstable branch (Sec. 5.3)
#
# A brute-force sweep (the Fig. 8 tutorial) sees only the stable response its
# history leads to.  Two other tools see more:
#
# - `rh.response`: the *linear* response to the end's circle, the steady
#   harmonic solution of $(K - \omega^2 M + i \omega C)\,X = 0$ about the stationary state.
#   It is cheap (one LU per f1) and its peaks are the natural frequencies.
# - `rh.orbits`: the *nonlinear* periodic orbits, found by shooting on the
#   period map of the time integrator, with their Floquet multipliers
#   (stable when every |mu| < 1), continued in f1 by pseudo-arclength so that
#   the branch goes round its folds, onto the unstable branch and back.
#
# Run it with `.venv/bin/python docs/tutorials/frequency_response.py` (about
# a minute of CPU at N = 4: 49 orbits); `RAWEHELIX_TUTORIAL_SMALL=1` runs N = 2, whose
# branch has the same shape (both folds) in about 50 s.

# %%
import os
from pathlib import Path

import numpy as np

import rawehelix as rh

SMALL = os.environ.get("RAWEHELIX_TUTORIAL_SMALL") == "1"
OUT = Path(os.environ.get("RAWEHELIX_TUTORIAL_OUT", "results/tutorials"))
OUT = OUT / "frequency_response"
N = 2 if SMALL else 4
scene = rh.load_scene("mobile_end", elements=N)

# %% [markdown]
# ## The linear response
#
# The helix of Sec. 5.3 has no wind, so no damping: the peaks of the linear
# response are poles, at the lateral natural frequencies of the same
# linearisation (`fr.natural`).  Each peak comes with its nearest mode.

# %%
fr = rh.response(scene, f1_Hz=np.arange(0.5, 15.001, 0.05))
for peak in fr.peaks:
    mode = peak["nearest_mode"]
    print(f"peak at {peak['f1_Hz']:.6f} Hz ({', '.join(peak['seen_in'])}): "
          f"{mode['family']} mode at {mode['frequency_Hz']:.6f} Hz")
    assert abs(mode["relative_difference"]) < 1e-6  # undamped: the peak is the pole
fr.write(OUT / "response")

# %% [markdown]
# ## The nonlinear branch through the resonance
#
# The linear pole sits near 9.85 Hz; the nonlinear peak of Fig. 8 is at
# 12.5 Hz, 2.7 Hz above it, because the mean tension rises with the whirl.
# `rh.orbits` traces the branch from 11.5 Hz towards 12.9 Hz; the step keeps
# the change of T max between points within `tension_step`.

# %%
ob = rh.orbits(scene, 11.5, 12.9, tension_step=0.1 if SMALL else None,
               superharmonics=(), max_points=60 if SMALL else 400)
print(f"{len(ob.branch)} orbits, {ob.discretisation}")
for p in ob.branch:
    stability = "stable" if p["stable"] else "UNSTABLE"
    print(f"  f1 = {p['f1_Hz']:8.4f} Hz  T max = {p['tension_max_N']:6.1f} N  "
          f"|mu| max = {p['max_multiplier']:.3f}  {stability}")
for fold in ob.folds:
    print(f"fold at {fold['f1_Hz']:.3f} Hz (+- {fold['f1_error_Hz']:.3f}), "
          f"T max {fold['tension_max_N']:.1f} N")

# %% [markdown]
# The branch rises to its peak, turns at a fold onto an unstable branch
# (a real multiplier above 1), turns again at a second fold onto the lower
# stable branch.  Between the two folds two stable responses coexist; the
# sweep finds one or the other depending on where it comes from.  (At N = 8,
# converged, the folds are at 12.70 and 11.97 Hz: the explanation page on
# orbits.)

# %%
unstable = [p for p in ob.branch if not p["stable"]]
assert len(ob.folds) == 2 and unstable, "the S-curve of Fig. 8 has two folds"
assert all(p["max_multiplier"] > 1 for p in unstable)

# %% [markdown]
# ## The orbit against a brute-force sweep
#
# Below the lower fold there is one stable response only, so a sweep point
# integrated in time until periodic must find the same orbit: an independent
# check of the shooting.

# %%
first = ob.branch[0]
point = rh.sweep(scene, f1_Hz=[first["f1_Hz"]]).points[0]
rel = point["tension_max_N"] / first["tension_max_N"] - 1
print(f"at {first['f1_Hz']} Hz: orbit {first['tension_max_N']:.2f} N, "
      f"sweep {point['tension_max_N']:.2f} N ({rel:+.1e})")
assert abs(rel) < 2e-3

# %%
ob.write(OUT / "orbits")   # summary.json, orbits.png (the bifurcation diagram)
print("written:", OUT)
