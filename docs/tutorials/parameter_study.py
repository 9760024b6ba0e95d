# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # A parameter study and a calibration
#
# The experiment of the paper saw the tension of its helix rise from 3.5 Hz
# and the helix fail near 5 Hz, while the model's lateral resonance sits near
# 9.85 Hz.  How does the lowest lateral frequency depend on the bending
# stiffness EI, and what EI would put it at 5 Hz?
#
# - `rawehelix.studies.study.compute` evaluates named quantities
#   (`lateral_frequency_Hz`, `tension_s0_N`, `sag_m`, `peak_Hz`, ...; each
#   computes the least it needs, a modal one never integrates in time) over a
#   design of dotted scene keys, with the sensitivities $\partial \ln Q / \partial \ln p$ at the
#   base point.  The command is `rawehelix study`.
# - `rawehelix.studies.calibrate.compute` fits scene keys to target
#   quantities by least squares.  The command is `rawehelix calibrate`.
#
# Both deal their points to the MPI ranks and keep every finished point in
# their output folder, so a killed run resumes.
#
# Run it with `.venv/bin/python docs/tutorials/parameter_study.py` (N = 16,
# about 15 s of CPU); `RAWEHELIX_TUTORIAL_SMALL=1`: N = 4 and a coarser grid.

# %%
import math
import os
from pathlib import Path

import numpy as np

import rawehelix as rh
from rawehelix.studies import calibrate, study

SMALL = os.environ.get("RAWEHELIX_TUTORIAL_SMALL") == "1"
OUT = Path(os.environ.get("RAWEHELIX_TUTORIAL_OUT", "results/tutorials"))
OUT = OUT / "parameter_study"
N = 4 if SMALL else 16
COUNT = 4 if SMALL else 12  # grid points in EI

# %% [markdown]
# ## The study
#
# A `Source` says how each point's scene is made (the scene, N and any base
# overrides); a `Variable` is one key with its range, written as on the
# command line (`KEY=START:STOP:COUNT`).  Every point's scene is validated
# before anything runs.

# %%
source = study.Source("mobile_end", elements=N)
ei = study.parse_vary(f"helix.EI_Nm2=500:6000:{COUNT}")
result = study.compute(source, [ei], ["lateral_frequency_Hz", "tension_s0_N"],
                       OUT / "study")
for EI, f, T in zip(result.keys_of()[:, 0], result.column("lateral_frequency_Hz"),
                    result.column("tension_s0_N")):
    print(f"EI = {EI:7.1f} N m^2: lateral {f:6.3f} Hz, T(0) = {T:.2f} N")
sens = result.summary["sensitivities"]["lateral_frequency_Hz"]["helix.EI_Nm2"]
print(f"d ln f / d ln EI at Table 4's EI: {sens:.3f}")
result.write(OUT / "study")  # study.csv, summary.json, study.png, tornado.png

# %% [markdown]
# The frequency grows with EI, but slower than $\sqrt{EI}$: the tension
# carries part of the stiffness.  For a pinned beam under the mean tension T,
#
# $$\omega^2 = \frac{T k^2 + EI\,k^4}{m}, \quad k = \frac{\pi}{L_0},
# \qquad\text{so}\qquad
# \frac{\partial \ln f}{\partial \ln EI} = \frac{EI\,k^2}{2\,(T + EI\,k^2)} < \frac{1}{2}.$$

# %%
f = result.column("lateral_frequency_Hz")
assert np.all(np.diff(f) > 0) and 0 < sens < 0.5

# %% [markdown]
# ## The calibration
#
# One key, one target: the fit reports the value, the residual, the
# condition number of the scaled Jacobian (1 here) and the linearised
# uncertainty of the key for a 1 % uncertainty of the target.

# %%
fit = calibrate.compute(source, ["helix.EI_Nm2"], {"lateral_frequency_Hz": 5.0},
                        OUT / "calibrate")
print(calibrate.report(fit))
fit.write(OUT / "calibrate")
EI = fit.summary["fitted"]["helix.EI_Nm2"]

# %% [markdown]
# ## Against the closed form
#
# The tensioned pinned beam gives $EI = (m\,\omega^2 - T k^2) / k^4$ at 5 Hz, with
# the mean tension of the fitted scene's stationary state (Table 4 has
# EI = 4381 N m^2; the fit is about 769 N m^2).

# %%
fitted_scene = source.load(fit.summary["fitted"])
T = rh.modes(fitted_scene).info["mean_tension_N"]
h = fitted_scene.helix
k, m, omega = math.pi / h.length_m, h.mass_kg / h.length_m, 2 * math.pi * 5.0
closed = (m * omega**2 - T * k**2) / k**4
print(f"fitted EI = {EI:.3f} N m^2, closed form {closed:.3f} N m^2 "
      f"({EI / closed - 1:+.1e})")
assert abs(EI / closed - 1) < 1e-2
print("written:", OUT)
