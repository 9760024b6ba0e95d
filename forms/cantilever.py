"""The lab tests' cantilever (Sec. 4, Fig. 2 a-c): a clamped end and dead end loads, in pure UFL.

The segment is clamped on a wall at s = 0 and loaded at its free end s = 1.
r(0) = 0 and alpha(0) = 0 are Dirichlet conditions (solvers/cantilever.py);
the clamp's slope condition, the tangent along the wall's axis e, is a
Nitsche term of the interior-penalty bending energy: the wall is a node whose
outer side has the tangent e, so the node terms of forms/interior_penalty.py::bending
(-{{r''}}.[[r']] + alpha_ip/2 |[[r']]|^2) get the boundary value [[r']] =
(P r'(0)) n, n = -1 the outward normal and P = I - e e the projection normal
to e (the dolfinx biharmonic demo's clamped-edge terms, in 1D):

    U_clamp = mu [ -r''.(P r') n + alpha_ip/2 |P r'|^2 ]  at s = 0.

Only the transverse part P r' is prescribed: |r'| = 1 + eps is the stretch,
free (the tension T_e stretches the segment at the wall too).  Consistency:
int r''.v'' = [r''.v']_0^1 + ..., whose wall term -r''(0).v'(0) is cancelled
on the transverse part by the variation of the first term at the exact
solution (P r' = 0); the axial part of r'' keeps the natural r''.e = 0 of the
paper's bending on the whole r (forms/rod.py).  The variation of the second
term is the penalty, symmetric and coercive for the interior penalty's
alpha_ip = eta p^2 / h (here h of the wall's cell).  The residual is the
variation of U_clamp (ufl.derivative), so it is symmetric like the interior terms.

With ``model.kinematics = "extensible"`` the bending energy lives on the unit
tangent t = r'/|r'| (forms/extensible.py) and so does the clamp:
[[t]] = (t - e) n, U_clamp = -mu t'.(t - e) n + alpha_ip/2 mu |t - e|^2, with
the EI law's mu(eps) at the wall (forms/extensible.py::bending_modulus): the
wall term of int mu t'.dt' is -mu t'.dt, cancelled as above, and the
variation of mu(eps) multiplies t - e = 0 at the exact solution.

The end loads are dead loads, potentials at s = 1: a force P (the tension T_e
along the undeformed axis plus the bending test's F_N normal to it) has the
potential -P.r(1); the end torque is the rod's own natural term tau(1) = m_N,
Eq. (39) (forms/rod.py).  Normalised as forms/energy.py (units of M g L0,
the force P by M g).
"""

from __future__ import annotations

import ufl


def wall_weight(mesh):
    """1 at s = 0 (the wall) and 0 at s = 1 (the free end): selects the wall in ds."""
    return 1 - ufl.SpatialCoordinate(mesh)[0]


def clamp_energy(r, axis, mu, kinematics, degree: int, penalty, ds, moment=None):
    """U_clamp at the wall s = 0 (see above); ``mu`` (a number, constant or UFL
    field) includes the bending switch, ``penalty`` is eta (discretisation.penalty);
    ``kinematics`` the component (c.kinematics): its jump and moment measure at
    the wall, [[r']] n and r'' (paper) or [[t]] n and t' (extensible).  ``moment``: a
    section law's dW/dt' (forms/section_law.py), the wall's moment in place of mu t',
    with ``mu`` its taut bending modulus in the penalty."""
    mesh = ds.ufl_domain()
    n = ufl.FacetNormal(mesh)[0]
    alpha_ip = penalty * degree**2 / ufl.CellDiameter(mesh)
    jump, bend = kinematics.clamp(r, axis)
    if moment is not None:
        return wall_weight(mesh) * (-ufl.dot(moment, jump) * n
                                    + 0.5 * alpha_ip * mu * ufl.dot(jump, jump)) * ds
    return wall_weight(mesh) * mu * (-ufl.dot(bend, jump) * n
                                     + 0.5 * alpha_ip * ufl.dot(jump, jump)) * ds


def end_load_potential(r, force, ds):
    """-P.r(1): the potential of the dead force P (normalised by M g) at s = 1."""
    return -(1 - wall_weight(ds.ufl_domain())) * ufl.dot(force, r) * ds
