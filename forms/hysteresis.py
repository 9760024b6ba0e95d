"""Hysteretic torsion (the scene's ``[torsion_hysteresis]``): a Bouc-Wen internal twist z.

The paper's torsion test (Sec. 4, Fig. 5) finds that the moment is not a
function of the twist alone, Eq. (65) M = GJ alpha / L0 being one value of a
loop.  Its Sec. 6 leaves open how to model it and names "additional ordinary
differential equations".  Here that is the Bouc-Wen model (Bouc 1967, in the
form of Wen 1976, J. Eng. Mech. Div. ASCE 102, 249-263): the moment is shared
between the elastic twist tau and an internal twist z,

    m = rho tau + (1 - rho) z                                 (moment / GJ)
    z_t = A tau_t - beta |tau_t| |z|^(n-1) z - gamma tau_t |z|^n,

everywhere the paper has GJ tau: the twist equation (31), delta m psi', and
the moment's force on the centre line beta m (r' x r'') in F_NL (Eq. 32).
The z equation is rate independent (z_t is homogeneous of degree one in
tau_t: a loop is a curve in the (tau, m) plane, whatever the speed).  A
virgin material (z = 0) has the tangent GJ (rho + (1 - rho) A); loading
saturates z at z_u = (A / (beta + gamma))^(1/n), and the loop is traversed
clockwise in (tau, m) and dissipates (Wen's condition beta > 0, |gamma| <=
beta, parameters/hysteresis.py).  rho = 1 is the paper's elastic rod.  Normalised like
the twist (tau~ = L0 tau, z~ = L0 z), so beta~ = beta / L0^n
(parameters.Normalised).

Where z lives.  z is a field of the state: the rod's mixed space W gets a
scalar DG_(p-1) field (compat.rod_element(..., internal=True)), the space
of alpha' (the twist of a P_p alpha with gamma off).  Its equation is the
L2 projection on DG_(p-1) of the pointwise ODE, cell by cell (no coupling
between cells), with the quadrature of the rod (3p):

    int (z_t - rate(z, tau_t)) zeta = 0      for every zeta in DG_(p-1).

How it runs under PETSc TS.  alpha2 (TSALPHA2) integrates M U'' + ... = 0
for the whole U = (r, alpha, z): it solves F(t, U, V, A) = 0 at the
alpha-points, with the Newmark relations linking U_(n+1), V_(n+1) and A_(n+1).
The z rows of F read V_z (= z_t) and (U, V) of the rod (tau_t needs alpha_t,
and r_t with the Frenet torsion), never A: for z, F = 0 is a first-order ODE
posed on V, and alpha2's U update  U_(n+1) = U_n + dt V_n + dt^2 ((1/2 -
beta_N) A_n + beta_N A_(n+1))  integrates it, its A the discrete rate of
V.  The Jacobian dF/dU + v_shift dF/dV (+ a_shift dF/dA, zero on these rows)
is ufl.derivative of the one residual, so the tangent includes z's equation
and its coupling both ways (the consistent tangent of the implicit update;
the z block is the identity times v_shift plus the derivative of -rate).
tests/test_hysteresis.py measures the order of the scheme on z against
scipy's solve_ivp: second order in dt, as for the rod.  alpha2's local error
estimate is not: the start (A_z = 0 while z_tt != 0) and each reversal of
tau_t (a kink of z_t) inflate it, so solvers/dynamics.py leaves z's dofs out
of the step-size control (infinite absolute tolerance); z follows tau, whose
error is controlled (docs/explanation/model.md measures both).  The first-order TS
types (FirstOrder in solvers/ts_forms.py) are refused: they would need z
once more as a first-order unknown.

The stationary solver and the modal solver.  A stationary state has no rate,
so z cannot evolve; the stationary residual holds z = 0 (the virgin state),
which is the state of Sec. 5.1 (no twist).  The modal solver refuses the
switch: about z = 0 the linearised z equation is z_t = A tau_t, i.e. z = A tau,
an elastic rod of stiffness GJ (rho + (1 - rho) A) with a zero eigenvalue per
z dof that linearise.py is not set up to separate.

Energy.  The hysteretic moment stores no energy: forms/energy.py's
beta/2 tau^2 is the elastic moment's (rho = 1).  The work of m over a closed
twist cycle is the dissipated energy of the loop, what tests/test_hysteresis.py
compares with the scipy reference.
"""

from __future__ import annotations


def moment(tau, z, c):
    """m = rho tau + (1 - rho) z: the torsional moment / GJ (normalised twist units)."""
    return c.hysteresis.moment(tau, z)


def _power(x, n: float):
    """x^n for x >= 0; n = 1 without a power (its derivative is then exact at 0)."""
    return x if n == 1 else x**n


def rate(z, tau_t, c):
    """Bouc-Wen: z_t = A tau_t - beta |tau_t| |z|^(n-1) z - gamma tau_t |z|^n (Wen 1976)."""
    bw = c.hysteresis
    n = bw.n
    z_abs = abs(z)
    odd = z if n == 1 else _power(z_abs, n - 1) * z  # |z|^(n-1) z
    return bw.A * tau_t - bw.beta * abs(tau_t) * odd - bw.gamma * tau_t * _power(z_abs, n)


def evolution_residual(z, z_t, tau_t, zeta, dx, c):
    """int (z_t - rate(z, tau_t)) zeta: the L2 projection of the ODE on z's space."""
    return (z_t - rate(z, tau_t, c)) * zeta * dx


def virgin_residual(z, zeta, dx):
    """int z zeta: the stationary z = 0 (a state without a rate keeps the virgin z)."""
    return z * zeta * dx


#: what the component cannot run with: solver -> (scene key, message) (models/base.py::refuse)
REFUSES = {
    "first_order": ("torsion_hysteresis",
                    "runs with the second-order integrator only (-rawehelix_ts_type alpha2, the "
                    "default): the first-order TS types are not set up for its internal twist z "
                    "(forms/hysteresis.py)"),
    "modal": ("torsion_hysteresis",
              "the modal solver does not linearise the hysteretic torsion "
              "(forms/hysteresis.py); it runs in time only ('simulate')"),
}


class BoucWen:
    """The hysteresis component (the scene's ``[torsion_hysteresis]``,
    parameters/hysteresis.py): its normalised rho, A, beta, gamma (numbers or
    constants) and n (a number: it chooses the form's shape); it adds the field
    z (``fields``), shares the moment with it and contributes z's equation."""

    fields = ("internal_twist",)  # z on DG_(p-1), compat.rod_element(internal=True)
    refuses = REFUSES

    def __init__(self, rho, A, beta, gamma, n: float):
        self.rho, self.A, self.beta, self.gamma, self.n = rho, A, beta, gamma, n

    @classmethod
    def from_normalised(cls, q, make=float):
        """From :class:`rawehelix.parameters.Normalised`; the null object when rho = 1."""
        if not q.hysteretic:
            return NoneHysteresis()
        return cls(make(q.bw_rho), make(q.bw_A), make(q.bw_beta), make(q.bw_gamma), q.bw_n)

    def moment(self, tau, z):
        return self.rho * tau + (1 - self.rho) * z

    def residual(self, z, z_t, tau_t, zeta, dx, c):
        """z's equation: the virgin z = 0 without a rate (``z_t`` or ``tau_t`` None)."""
        if z_t is None or tau_t is None:
            return virgin_residual(z, zeta, dx)
        return evolution_residual(z, z_t, tau_t, zeta, dx, c)


class NoneHysteresis:
    """The paper's elastic moment GJ tau: no field, no equation, refuses nothing."""

    fields = ()
    refuses = {}

    def moment(self, tau, z):
        return tau

    def residual(self, z, z_t, tau_t, zeta, dx, c):
        return 0
