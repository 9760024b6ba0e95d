"""The paper's published numbers that rawehelix is compared with, typed in once.

Sanchez-Arriaga et al. (/work/shared/paper): Table 3 (modes of the stationary
state of Sec. 5.1, spline-Galerkin N = 2), the outcome of Sec. 5.2 and the
resonance of Fig. 8 (Sec. 5.3) as the text states them.  Eigenvalues are
normalised by t_scale = sqrt(L0/g) (Eq. 25), as in the paper.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ModeRow:
    """One row of Table 3."""
    eigenvalue: complex  # normalised; the row stands for the pair lambda, conj(lambda)
    dominant: str        # dominant components of the eigenvector, as printed
    family: str          # rawehelix's family name (solvers.modal.FAMILIES, or "rigid")
    period_s: float | None


TABLE3_ELEMENTS = 2  # "N = 2"
TABLE3 = (  # the oscillatory pairs
    ModeRow(-2.23 + 271.4j, "xdot_1, zdot_1", "longitudinal", 0.03),
    ModeRow(-2.23 + 37.0j, "xdot_1, zdot_1", "lateral_in_plane", 0.21),
    ModeRow(-1.48 + 37.0j, "ydot_1", "lateral_out_of_plane", 0.21),
    ModeRow(40.0j, "alphadot_0, alphadot_1, alphadot_2", "torsional", 0.20),
    ModeRow(20.0j, "alphadot_0, alphadot_2", "torsional", 0.40),
)
TABLE3_RIGID = ModeRow(0j, "alpha_0, alpha_1, alpha_2", "rigid", None)  # "~ 0 +- 0i"

# Sec. 5.2 (Fig. 6): the controller (40) brings every node to the target spin;
# the tension is "almost constant throughout the helix and equal to around 200 N".
SEC52_TARGET_RPM = 120.0
SEC52_TENSION_N = 200.0

# Sec. 5.3 (Fig. 8, N = 2): "the maximum tension in the simulator raises for
# driving frequencies above around 9 Hz"; "for a tension about 200 N, the
# driving frequency is about 11 Hz".
FIG8_RISE_HZ = 9.0
FIG8_200N_HZ = 11.0
