"""The mixed (Ciarlet-Raviart) bending form: the curvature kappa = r'' as its own field.

Unknowns (r, alpha, kappa) on P_p x P_p x P_p (kappa: 3 components).  The
bending force of Eq. (33) is -F_L' = -mu r''''; its weak form with the
interior-penalty form of :mod:`rawehelix.forms.rod` is mu int r''.v''.
Here kappa carries r'' instead:

1. kappa = r'' weakly.  For every eta with eta(0) = eta(1) = 0,

       int kappa.eta = int r''.eta = [r'.eta]_0^1 - int r'.eta'
                     = - int r'.eta',

   i.e.  int kappa.eta + int r'.eta' = 0.  The zero-curvature ends r'' = 0
   (Eq. 37) are *essential*: kappa(0) = kappa(1) = 0 on the dofs, so the
   number of eta (interior dofs) is the number of unknown kappa dofs.

2. The bending term.  For the test v of Eq. (30) (v = 0 at the ends,
   Eqs. 35-36) and a smooth solution, by parts once:

       mu int r''.v'' = mu int kappa.v'' = mu [kappa.v']_0^1 - mu int kappa'.v'
                      = - mu int kappa'.v',

   since kappa = 0 at both ends (37).  Only first derivatives remain: the
   operator is second order (condition number ~ N^2 instead of the N^4 of
   the fourth-order IP form, whose Jacobian entries grow like mu p^4 N^3).

The residual adds  -bending mu int kappa'.v'  to the centre-line equation
and  -mu (int kappa.eta + int r'.eta')  as the kappa equation.  Scaling the
kappa equation by -mu makes the Jacobian symmetric (the (v, kappa) block
-mu int dkappa'.v' is the transpose of the (eta, r) block -mu int dr'.eta')
and of the size of the bending rows.  It is *not* scaled by the
``bending`` switch (0 drops the bending force only; kappa still enters
F_NL, Eq. 32, as r'' does in the IP form).

Every other r'' and r''' of the rod (-mu kappa^2 r' and beta tau (r' x r'')
in F_NL, Eq. 32; gamma of Eq. 34) is kappa and kappa' (the ``k`` argument of
:mod:`rawehelix.forms.kinematics`).  The bending energy is mu/2 int |kappa|^2:
with kappa = -M^-1 B r (M the kappa mass, B_{eta,r} = int r'.eta') its
derivative in r is -mu int kappa'.v', the bending term above.

kappa has no inertia and no damping: in time it is an algebraic field (an
index-1 DAE, linear in (r, kappa)), and the modal M and C are zero on it.
"""

from __future__ import annotations

import ufl

from rawehelix.forms.kinematics import d


def bending_force(kappa, v, dx):
    """-int kappa'.v' = int r''.v'' for v = 0 and kappa = 0 at the ends (see above)."""
    return -ufl.inner(d(kappa), d(v)) * dx


def curvature_equation(r, kappa, eta, dx):
    """int kappa.eta + int r'.eta' (= 0: kappa = r'' weakly, eta = 0 at the ends)."""
    return (ufl.inner(kappa, eta) + ufl.inner(d(r), d(eta))) * dx


def energy(kappa, dx):
    """1/2 int |kappa|^2: the bending energy per unit mu."""
    return 0.5 * ufl.inner(kappa, kappa) * dx
