"""The mode families of the spectrum (Table 3), shared by the FE scheme and the references.

numpy-free on purpose: the spline and shooting references import it too.
"""

#: every family, in the order of the tables and summaries; ``rigid`` is the
#: free rotation alpha = const (the zero eigenvalue of torque-free ends)
FAMILIES = ("longitudinal", "lateral_in_plane", "lateral_out_of_plane", "torsional", "rigid")

#: the families the upper end's circular motion drives (Sec. 5.3)
LATERAL = FAMILIES[1:3]

#: the families of vibrations, with a classical model each (solvers.analytic)
VIBRATIONS = FAMILIES[:-1]

#: the shearable rod's modes with most of their kinetic energy in the sections' rotary
#: inertia (forms/shearable.py): shear modes, and the director's gauge |n|; not a vibration
#: of Table 3's families, listed when a window holds one
ROTATION = "rotation"

#: the labels of Table 3
FAMILY_LABELS = {
    "longitudinal": "Longitudinal",
    "lateral_in_plane": "Lateral (x-z)",
    "lateral_out_of_plane": "Lateral (y)",
    "torsional": "Torsional",
    "rigid": "Rigid rotation",
    "rotation": "Section rotation (shear)",
    "overdamped": "Overdamped",
}

#: a real eigenvalue (no oscillation) of a damped spectrum, not the rigid zero:
#: one root of an overdamped pair; it belongs to no family's oscillating modes
OVERDAMPED = "overdamped"

#: |Im lambda| <= REAL_TOL |lambda|: a real eigenvalue.  Real arithmetic returns 0 for
#: an isolated real root, but nearly coincident real roots (the overdamped cluster at
#: -1/tau of structural damping) can come out as a pair with |Im| up to about
#: sqrt(eps) |lambda| (SLEPc 3.22: 1.8e-10 |lambda|).  A pair whose period is a million
#: times its decay time does not oscillate either.
REAL_TOL = 1e-6


def is_overdamped(eigenvalue: complex) -> bool:
    """True for a nonzero real eigenvalue: a decay without oscillation."""
    lam = complex(eigenvalue)
    return lam != 0 and abs(lam.imag) <= REAL_TOL * abs(lam)
