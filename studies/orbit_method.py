"""The periodic-orbit methods (``--method``), chosen by name: the one registry that
the command line, the studies and the resources ask instead of testing the name.

* ``shooting``: Newton on the scheme's period map (studies/schemes.py);
* ``hb``: harmonic balance (solvers/harmonic_balance/, one room: its scope, problem,
  Newton and Hill's method), H chosen by accuracy, Hill's method for the multipliers;
* ``auto``: the rule of :meth:`Auto.choose`, stated once here and reported with every
  result (docs/explanation/harmonic_balance.md, "Where HB is the wrong tool").

An :class:`OrbitMethod` owns every decision made by its name: its refusal of a scene
(with the command-line way out), its periodic-orbit problem (:meth:`~OrbitMethod.problem`: studies/orbits.py's
:func:`~rawehelix.studies.orbits.problem` asks it),
the size of its unknown, the result's description and each command's default
(:func:`default_for`).  :func:`get` refuses an unknown name once, with the list."""

from __future__ import annotations

from rawehelix.errors import SceneError
from rawehelix.parameters import Parameters
from rawehelix.registry import Registry
from rawehelix.solvers.harmonic_balance import scope
from rawehelix.solvers.harmonic_balance.stability import EVERY_POINT, GUARDED


class OrbitMethod:
    """What the commands and studies need of a periodic-orbit method (one instance per
    name)."""

    name: str = ""
    #: the ``--method`` help's words for it
    help: str = ""
    #: True: the problem steps in time with the scene's dt (shooting's period map), so
    #: the result reports dt; False: the result reports its own resolution
    steps_in_time: bool = True
    #: True: the orbits report prints the method line (its reason, H and accuracy)
    reported: bool = False

    def choose(self, params: Parameters) -> tuple[str, str]:
        """(the method that runs, why) for ``params``, or SceneError (bad input) with
        the command-line way out where this method cannot run the scene."""
        return self.name, "as asked"

    def problem(self, params: Parameters, every_point: bool = False):
        """The periodic-orbit problem of this method on this rank (a
        :class:`~rawehelix.periodic_orbits.problem.PeriodicOrbitProblem`); ``every_point``:
        each point of a branch gets its own multipliers (no step that carries them)."""
        raise NotImplementedError

    def state_size(self, params: Parameters) -> int:
        """The entries of an orbit's unknown X (studies/resources.py)."""
        from rawehelix.studies import schemes
        return schemes.of(params).period_state_size(params)

    def store_header(self) -> dict:
        """The method's entry in a stored branch's header (orbits_store.py, which
        refuses a folder holding another branch): its name."""
        return {"method": self.name}

    def discretisation(self, elements: int, degree: int, dt_s: float, branch: list) -> str:
        """The result's description of its FE discretisation (N, p and the period's)."""
        return f"N = {elements}, p = {degree}, dt = {dt_s * 1e3:g} ms"


class Shooting(OrbitMethod):
    name = "shooting"
    help = "shooting on the period map"

    def store_header(self) -> dict:  # the stores written before the methods had none
        return {}

    def problem(self, params: Parameters, every_point: bool = False):
        from rawehelix.studies import schemes
        return schemes.of(params).period_map(params)


class HarmonicBalanceMethod(OrbitMethod):
    name = "hb"
    help = "harmonic balance ('hb': H chosen by accuracy, Hill's method for the multipliers)"
    steps_in_time = False
    reported = True
    #: when a continued point gets a full Hill solve (solvers/harmonic_balance/stability.py):
    #: the guard from drift gave the same folds (to 0.0 Hz) and the same verdicts as Hill at
    #: every point on the Fig. 8 curve at N = 8 (8 Hill solves of 145 points) and N = 32
    #: (20 of 136: 144.5 s of CPU against 584.5 s) (benchmarks/results.md, item 15); the
    #: envelope asks for every point (``every_point``): its PD / NS curves start on its
    #: branches' bands, 0.25 Hz wide on the tensegrity (tests/test_envelope.py)
    stability = GUARDED

    def choose(self, params: Parameters) -> tuple[str, str]:
        if scope.cannot(params):
            raise SceneError("--method", self.name, f"harmonic balance is the wrong tool "
                             f"here: {scope.cannot(params)}")
        why = scope.wrong_tool(params)
        return self.name, f"as asked; warning: {why}" if why else "as asked"

    def problem(self, params: Parameters, every_point: bool = False):
        from rawehelix.solvers.harmonic_balance.problem import HarmonicBalance
        return HarmonicBalance(params, stability=EVERY_POINT if every_point else self.stability)

    def state_size(self, params: Parameters) -> int:
        return scope.state_size(params)

    def discretisation(self, elements: int, degree: int, dt_s: float, branch: list) -> str:
        Hs = [p["accuracy"]["H"] for p in branch if "accuracy" in p] or [0]
        return f"N = {elements}, p = {degree}, harmonic balance H = {min(Hs)}-{max(Hs)}"


class Auto(OrbitMethod):
    """Harmonic balance wherever it can run (solvers/harmonic_balance/scope.py's
    ``cannot``), with its ``wrong_tool`` warning for a non-smooth law: on the tensegrity
    section (mobile_end, N = 4, 10 to 9 Hz) HB traced 5 points in 23 s where shooting failed at the first in 100 s (at
    16 Hz both fail: HB in 52 s, shooting in 8 s).  Its results carry the method that
    ran, never ``auto``."""

    name = "auto"
    help = "'auto' (hb where every law is smooth; the choice and its reason are in summary.json)"

    def choose(self, params: Parameters) -> tuple[str, str]:
        if scope.cannot(params):
            return SHOOTING.name, f"auto: shooting, as {scope.cannot(params)}"
        why = scope.wrong_tool(params)
        if why:
            return HB.name, f"auto: harmonic balance, which runs here; warning: {why}"
        return HB.name, "auto: harmonic balance, as every law of the scene is smooth"

    def problem(self, params: Parameters, every_point: bool = False):
        return get(self.choose(params)[0]).problem(params, every_point)

    def state_size(self, params: Parameters) -> int:  # sized for harmonic balance's
        return HB.state_size(params)


SHOOTING, HB, AUTO = Shooting(), HarmonicBalanceMethod(), Auto()
#: every method by its name, in the order ``--method`` lists them
ORBIT_METHODS: Registry[OrbitMethod] = Registry("--method", (SHOOTING, HB, AUTO),
                                                error=SceneError)
METHODS = ORBIT_METHODS.names()
#: each command's default method: orbits shoots (its reference results), envelope's
#: many branches take harmonic balance
DEFAULTS = {"orbits": SHOOTING.name, "envelope": HB.name}


#: the method of a name; SceneError (bad input) naming the allowed names
get = ORBIT_METHODS.get


def default_for(command: str) -> str:
    """The ``--method`` default of ``command`` (``orbits``, ``envelope``)."""
    return DEFAULTS[command]


def described() -> str:
    """The methods in words, for ``--method``'s help: "a, b or c"."""
    words = [m.help for m in ORBIT_METHODS.values()]
    return ", ".join(words[:-1]) + " or " + words[-1]


def choose(params: Parameters, method: str) -> tuple[str, str]:
    """(the method that runs, why): the method's own rule (:meth:`OrbitMethod.choose`,
    ``auto``'s :meth:`Auto.choose`); an unknown name is refused (:func:`get`), and a
    scene without the controller's integral action by every method, with the way out."""
    from rawehelix.periodic_orbits.problem import FREE_ROTATION
    chosen = get(method)
    if params.normalised().steady_torque().k1 == 0.0:  # neither method: the way out
        raise SceneError("--method", method, FREE_ROTATION)
    return chosen.choose(params)

