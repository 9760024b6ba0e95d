"""The discretisation schemes' decisions that the solvers need (the scheme's
scheme-independent core): what a scheme is, below the solvers, so that
``solvers/`` asks the scheme object instead of testing its name.

The studies' registry (studies/schemes.py) extends each class here with what the
studies need of it (its stationary state, spectrum, integrators); it sits in
``studies/``, above the solvers it calls, and ``solvers/`` cannot import it
(.importlinter).  The names are :data:`SCHEMES`; :func:`get` refuses any other
name once, with the list.
"""

from __future__ import annotations

from rawehelix.parameters.checks import ParameterError
from rawehelix.parameters.numerics import BESIDE_CONTINUUM, SCHEMES
from rawehelix.registry import Registry


class SchemeCore:
    """A scheme's decisions below the solvers (one class per name)."""

    name: str
    #: the run has a Lagrange degree p (FE) or not (spline)
    has_degree: bool
    #: the run steps in time with a fixed ``time.dt_s`` (FE: generalised-alpha), not
    #: adaptively (spline: Radau); the step-size rule of solvers/stepsize.py applies
    fixed_time_step: bool
    #: the FE solvers of ``solvers/`` assemble it: the rod's fields along s on a mesh,
    #: the IP bending form and its limit, the FE linearisations (response, cantilever)
    fe_assembled: bool
    #: its time integrator, in a result's description
    integrator: str

    #: why harmonic balance cannot trace its orbits (None: it can; studies/orbit_method.py)
    harmonic_balance_refusal: str | None = None
    #: a model of its own, run beside the FE continuum (numerics.BESIDE_CONTINUUM)
    beside_continuum: bool = False
    #: the ``rawehelix`` commands that run it (None: every command that takes a scene)
    commands: tuple[str, ...] | None = None

    def command_refusal(self, command: str) -> str | None:
        """Why the command ``command`` does not run this scheme (None: it does)."""
        if self.commands is None or command in self.commands:
            return None
        return (f"'{self.name}' runs {', '.join(repr(c) for c in self.commands)} only, not "
                f"'{command}': use --scheme fe or spline")

    def unknowns(self, params, planar: bool = False) -> int:
        """The unknowns of the rod's discrete state."""
        raise NotImplementedError

    def period_state_size(self, params) -> int:
        """The entries of its period map's state X (an orbit's unknown when shooting)."""
        raise NotImplementedError

    def memory_bytes(self, params, step: str) -> tuple[float, str]:
        """(the working memory [bytes] of a run whose heaviest step is ``step``:
        "stationary", "dynamics" or "modes", how it was counted), above the base of
        studies/resources.py (whose docstring gives the measurements)."""
        raise NotImplementedError


class FECore(SchemeCore):
    name, has_degree, fixed_time_step, fe_assembled = "fe", True, True, True
    integrator = "generalised-alpha"
    #: bytes per FE unknown of each heaviest step (studies/resources.py's docstring)
    BYTES_PER_UNKNOWN = {"stationary": 1.5e3, "dynamics": 1.5e3, "modes": 22e3}

    def unknowns(self, params, planar=False):
        """(r, alpha) in P_p, 4 components (2 on the planar (x, z) rod), + 3 for the
        mixed form's curvature, + DG_(p-1) z for the hysteretic torsion
        (compat.rod_element)."""
        disc = params.discretisation
        nodes = disc.degree * disc.elements + 1
        comps = 2 if planar else 4 + 3 * (disc.bending == "mixed")
        internal = disc.degree * disc.elements if params.model.torsion_hysteresis.active else 0
        return comps * nodes + internal

    def period_state_size(self, params):
        return 3 * self.unknowns(params)  # (U, V, A) of generalised-alpha

    def memory_bytes(self, params, step):
        n, each = self.unknowns(params), self.BYTES_PER_UNKNOWN[step]
        return each * n, f"{n} unknowns at {each / 1e3:g} kB each"


class SplineCore(SchemeCore):
    name, has_degree, fixed_time_step, fe_assembled = "spline", False, False, False
    integrator = "Radau"
    harmonic_balance_refusal = ("the spline reference has a period map only: use --method shooting, "
                                "or --scheme fe for harmonic balance")
    BYTES_PER_N2 = 4.5e3  # its dense matrices: bytes per N^2 (studies/resources.py)

    def unknowns(self, params, planar=False):
        """8 N: the spline-Galerkin state (references/spline_galerkin)."""
        return 8 * params.discretisation.elements

    def period_state_size(self, params):
        return self.unknowns(params)

    def memory_bytes(self, params, step):
        return (self.BYTES_PER_N2 * float(params.discretisation.elements) ** 2,
                f"the spline scheme's dense matrices, {self.BYTES_PER_N2 / 1e3:g} kB N^2")


class NetworkCore(SchemeCore):
    """The ring-and-tether network (references/network): a model of its own, run beside
    the FE continuum; a stationary solve, modes, and its own time integration
    (simulate, sweep); no period map (orbits) nor harmonic balance."""

    name, has_degree, fixed_time_step, fe_assembled = "network", False, False, False
    beside_continuum = True
    commands = ("stationary", "modes", "section", "simulate", "sweep")
    integrator = "Strang splitting of the rigid rings (references/network/dynamics.py)"
    harmonic_balance_refusal = ("the network reference has no harmonic balance: use "
                                "--scheme fe, or 'sweep' with --scheme network")
    #: the dense eigenproblem's K, M, their eigenvectors and eigh's work: bytes per dof^2
    BYTES_PER_DOF2 = 40.0

    def unknowns(self, params, planar=False):
        """6 (rings - 2): each interior ring's centre and rotation (the end rings held)."""
        return 6 * max(params.model.section.ring_count(params.helix.length_m) - 2, 1)

    def period_state_size(self, params):
        return 2 * self.unknowns(params)

    def memory_bytes(self, params, step):
        n = self.unknowns(params)
        return (self.BYTES_PER_DOF2 * float(n) ** 2,
                f"the network's dense matrices, {n} dofs at {self.BYTES_PER_DOF2:g} B dof^2")


#: every scheme's core by name
CORES: Registry[SchemeCore] = Registry("discretisation.scheme",
                                       (FECore(), SplineCore(), NetworkCore()),
                                       error=ParameterError)
assert CORES.names() == SCHEMES, "the cores name the schemes of SCHEMES"
assert tuple(c.name for c in CORES.values() if c.beside_continuum) == BESIDE_CONTINUUM
#: the scheme core of a name; any other name is refused as a scene's is
get = CORES.get


def of(params) -> SchemeCore:
    """The scheme core of a scene (``discretisation.scheme``)."""
    return get(params.discretisation.scheme)


__all__ = ["CORES", "FECore", "NetworkCore", "SchemeCore", "SplineCore", "get", "of"]
