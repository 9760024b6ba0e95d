"""The discretisation schemes, chosen by name (``discretisation.scheme``,
``--scheme``): the one registry that every study asks instead of testing the
name.

* ``fe``: FEniCSx, C0 interior penalty in space and generalised-alpha (or a
  PETSc TS) in time (:mod:`rawehelix.solvers`);
* ``spline``: the paper's spline-Galerkin reference (Sec. 3), integrated by
  Radau with adaptive steps (:mod:`rawehelix.references.spline_galerkin`);
* ``network``: the tensegrity as rigid rings and tension-only tethers
  (:mod:`rawehelix.references.network`), its stationary state, modes and its own time
  integration (simulate, sweep); ``stationary`` prints it beside the FE continuum
  (:meth:`Scheme.stationary_beside`).

A :class:`Scheme` gives what the studies need of a scheme: the stationary
tension, the spectrum of the linearised stationary state, the forced
integrator of the sweeps, the period map of the orbits, the lateral natural
frequencies of the orbits' step control and the spin-up time series of the
refinement studies.  The names are :data:`rawehelix.parameters.SCHEMES`,
where a scene's scheme is checked; :func:`get` refuses any other name with the
same message.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from mpi4py import MPI

from rawehelix.families import LATERAL
from rawehelix.parameters import SCHEMES, Parameters
from rawehelix.parameters.checks import ParameterError
from rawehelix.parameters.schemes import CORES, FECore, NetworkCore, SchemeCore, SplineCore
from rawehelix.registry import Registry


@dataclass
class Spectrum:
    """The modes of the linearised stationary state, as a scheme computes them.

    ``shapes(chosen)`` and ``centre_line()`` are collective on the FE
    communicator; ``info`` (the run's description) is complete on ``root``."""

    modes: list  # every mode found (eigenvalue normalised, family, dominant, fractions)
    info: dict
    missing: dict | None = None  # families with too few modes (None: not checked by the solver)
    shapes: Callable = lambda chosen: [None] * len(chosen)  # normalised (s, u, alpha) or None
    centre_line: Callable = lambda: None  # the stationary centre line (n, 3), None: no shapes
    comm: object = None  # the communicator the result is broadcast on (None: computed on each)


class Scheme(SchemeCore):
    """What a study needs of a discretisation scheme (one instance per name), beyond
    the decisions of its core below the solvers (parameters/schemes.py: its degree,
    time step, FE assembly, unknowns, memory, harmonic balance)."""

    #: why ``rawehelix simulate`` refuses the scheme (None: it runs it)
    simulate_refusal: str | None = None

    def stationary_beside(self, params: Parameters) -> dict | None:
        """The scheme's own stationary state, summarised beside the FE continuum's by
        ``rawehelix stationary`` (None: the scheme is not run beside it)."""
        return None

    def size_label(self, info: dict) -> str:
        """The discretisation's size in a modes report's header, ``info`` the run's."""
        return f"N = {info['elements']} ("

    def time_series(self, params: Parameters, until_s: float):
        """``rawehelix simulate`` by the scheme's own integrator: (rows, summary, why it
        stopped early or None, its perf_counter start), which studies/simulate.py makes
        its TimeSeries; or None: the FE's dynamics solver runs it."""
        return None

    def stationary_tension_N(self, params: Parameters) -> float:
        """The stationary tension at s = 0 [N] (Sec. 5.1), on this rank."""
        raise NotImplementedError

    def spectrum(self, params: Parameters, comm=None, scene: str = "scene", nev=None,
                 shapes: bool = True) -> Spectrum:
        """The stationary state's modes (Sec. 5.1, Table 3)."""
        raise NotImplementedError

    def forced_backend(self, params: Parameters, comm=MPI.COMM_SELF, accurate: bool = False,
                       ts_type: str | None = None):
        """The integrator of the forced response (:mod:`rawehelix.solvers.periodic`);
        ``accurate``: the tolerances of the refinement studies."""
        raise NotImplementedError

    def period_map(self, params: Parameters):
        """The period map of the orbits on this rank."""
        raise NotImplementedError

    def driven_frequencies(self, params: Parameters, m, f_max_Hz: float,
                           natural_modes: Callable) -> tuple[list[float], float]:
        """The lateral natural frequencies [Hz] up to f_max about the stationary
        state and its tension at s = 0 [N], on this rank (``m``: the scene's
        period map; ``natural_modes``: :func:`rawehelix.studies.response.natural_modes`)."""
        raise NotImplementedError

    def spin_series(self, params: Parameters, until_s: float, every_s: float,
                    ts_type: str | None = None, fixed_steps: bool = False):
        """(t [s], spin [rpm] at s = 0, L0/2, L0) of the Sec. 5.2 run from the
        stationary state, sampled every ``every_s`` (every step with ``fixed_steps``)."""
        raise NotImplementedError


class FE(FECore, Scheme):

    def size_label(self, info):
        return f"N = {info['elements']}, p = {info['degree']} ({info['dofs']} dofs, "

    def stationary_tension_N(self, params):
        from rawehelix.solvers.stationary import StationarySolver
        result = StationarySolver(params, MPI.COMM_SELF).solve()
        return params.normalised().tension_N(result.tension[0])

    def spectrum(self, params, comm=None, scene="scene", nev=None, shapes=True):
        from rawehelix.solvers.spin_modes import static_modal_solver
        comm = comm or MPI.COMM_WORLD
        solver = static_modal_solver(params, comm, scene=scene)  # a [rotor]'s J lumped
        if not shapes:  # eigenvalues only
            return Spectrum(solver.solve(keep_vectors=False, require_families=False), {})
        found = solver.solve(nev=nev, require_families=False)
        disc = params.discretisation
        info = {"degree": disc.degree, "dofs": solver.rod.dof_count(), "ranks": comm.size,
                "gamma": params.model.gamma, "model": params.describe_model(),
                "mean_tension_N": float(params.normalised().tension_N(
                    solver.mean_tension_value))}
        return Spectrum(found, info, solver.missing,
                        lambda chosen: [solver.mode_shape(m) for m in chosen],
                        lambda: solver.centre_line()[1], comm)

    def forced_backend(self, params, comm=MPI.COMM_SELF, accurate=False, ts_type=None):
        from rawehelix.solvers.forced import FEBackend
        if not accurate:
            return FEBackend(params, comm)
        # full Newton: the refinement studies measure discretisation errors down to 1e-6
        return FEBackend(params, comm, options={
            **FEBackend.FULL_NEWTON, **({"ts_type": ts_type} if ts_type else {})})

    def period_map(self, params):
        from rawehelix.solvers.orbits import AlphaMap
        return AlphaMap(params, comm=MPI.COMM_SELF)

    def driven_frequencies(self, params, m, f_max_Hz, natural_modes):
        from rawehelix.solvers.response import HarmonicResponse
        # the FE linearisation about the circle's centre (R1 = 0), as `rawehelix response`;
        # undamped: a site is f_n / k within a 5 % window, which structural damping moves
        # by its second order (< 0.1 %, docs/explanation/model.md), and the damped pencil is a PEP
        # that SLEPc does not always close at small N
        if params.model.damping.active:
            params = params.replace(damping={"axial_s": 0.0, "bending_s": 0.0, "torsion_s": 0.0})
        solver = HarmonicResponse.from_stationary(params, MPI.COMM_SELF, scene=params.name)
        T0 = params.normalised().tension_N(solver.modal.stationary_result.tension)[0]
        return ([x["frequency_Hz"] for x in natural_modes(solver, f_max_Hz, margin=1.0)
                 if x["family"] in LATERAL], float(T0))

    def spin_series(self, params, until_s, every_s, ts_type=None, fixed_steps=False):
        from rawehelix.solvers.dynamics import DynamicsSolver
        q = params.normalised()
        options = {"ts_type": ts_type} if ts_type else {}
        if fixed_steps:
            options["ts_adapt_type"] = "none"
        else:  # adaptive steps, tight enough that space dominates the error
            options.update({"ts_rtol": 1e-6, "ts_atol": 1e-6})
        solver = DynamicsSolver.from_stationary(params, MPI.COMM_SELF, options=options)
        rows = []

        def sample(s):
            v = s.probes.values()
            rows.append((s.t, v["spin0"], v["spin_mid"], v["spin1"]))

        if fixed_steps:
            sample(solver)
            solver.advance(until_s / q.t_scale, on_step=sample)
        else:
            solver.advance(until_s / q.t_scale, on_output=sample, output_every=every_s / q.t_scale)
        rows = np.array(rows)
        return q.time_s(rows[:, 0]), q.spin_rpm(rows[:, 1:])


class Spline(SplineCore, Scheme):
    simulate_refusal = ("'simulate' runs the FE scheme (the spline reference is "
                        "solvers.spline_galerkin.dynamics)")

    @staticmethod
    def _stationary(params):
        """(the Galerkin system, its stationary state): Newton from the shooting solution."""
        from rawehelix.references.spline_galerkin import stationary
        from rawehelix.references.spline_galerkin.system import SplineGalerkin
        system = SplineGalerkin(params.normalised(), params.discretisation.elements)
        return system, stationary.solve(system).x

    def stationary_tension_N(self, params):
        system, x = self._stationary(params)
        return params.normalised().tension_N(system.tension(x, 0.0, s=np.array([0.0]))[0])

    def spectrum(self, params, comm=None, scene="scene", nev=None, shapes=True):
        from rawehelix.references.spline_galerkin import spectrum
        found = spectrum.modes(*self._stationary(params))
        return Spectrum(found, {"gamma": "off", "model": params.describe_model()})

    def forced_backend(self, params, comm=MPI.COMM_SELF, accurate=False, ts_type=None):
        from rawehelix.references.spline_galerkin.forced import SplineBackend
        tolerances = {"rtol": 1e-9, "atol": 1e-11} if accurate else {}
        return SplineBackend(params.normalised(), params.discretisation.elements, **tolerances)

    def period_map(self, params):
        from rawehelix.references.spline_galerkin.orbits import SplineMap
        return SplineMap(params)

    def driven_frequencies(self, params, m, f_max_Hz, natural_modes):
        from rawehelix.references.spline_galerkin import spectrum
        # the spline scheme linearises about its period map's stationary state
        to_Hz = 1.0 / (2 * np.pi * m.q_base.t_scale)
        y0 = m.embed(m.X_stationary)
        f = [abs(x.eigenvalue.imag) * to_Hz
             for x in spectrum.modes(m.system, y0) if x.family in LATERAL]
        T0 = m.q_base.tension_N(m.system.tension(y0, 0.0, s=np.array([0.0])))[0]
        return sorted(x for x in f if x <= f_max_Hz), float(T0)

    def spin_series(self, params, until_s, every_s, ts_type=None, fixed_steps=False):
        from rawehelix.references.spline_galerkin.dynamics import time_series
        ts = time_series(params, until_s=until_s, output_every_s=every_s, rtol=1e-9)
        return ts.time_s, ts.spin_rpm


class Network(NetworkCore, Scheme):

    @staticmethod
    def _refused(params, command: str):
        from rawehelix.studies.scene import SceneError
        raise SceneError(params.name, "discretisation.scheme",
                         f"'network' runs 'stationary' and 'modes' only, not {command}: use "
                         "--scheme fe or spline")

    @staticmethod
    def _stationary(params):
        from rawehelix.references.network import Network as RingNetwork, solve
        return solve(RingNetwork.from_parameters(params))

    def stationary_tension_N(self, params):
        return float(self._stationary(params).tension_N()[0])

    def stationary_beside(self, params):
        import time
        start = time.perf_counter()
        result = self._stationary(params)
        f_min, bay, _ = result.smallest_tether_force
        T = result.tension_N()
        net = result.network
        return {"scheme": self.name, "rings": net.count, "spacing_m": net.spacing_m,
                "sag_m": result.sag_m(), "tension_s0_N": float(T[0]),
                "tension_s1_N": float(T[-1]), "smallest_tether_force_N": f_min,
                # the bay's middle along the unstretched helix
                "smallest_at_s_m": (bay + 0.5) * net.spacing_m,
                "slack_tethers": len(result.slack), "newton_iterations": result.iterations,
                # the top ring's turn about the chord beyond the lay (a torque end's twist)
                "twist_end_to_end_rad": result.state.theta + net.end_twist_rad,
                "wall_s": time.perf_counter() - start}

    def size_label(self, info):
        return f"{info['rings']} rings ({info['dofs']} dofs, "

    def spectrum(self, params, comm=None, scene="scene", nev=None, shapes=True):
        from rawehelix.references.network import modes
        result = self._stationary(params)
        found = modes.modes(result)
        t_scale = params.normalised().t_scale
        out = [NetworkMode(complex(0.0, 2 * np.pi * m.frequency_Hz * t_scale), m.family,
                           {k: v for k, v in m.fractions.items()}, [modes.DOFS_OF[m.family]])
               for m in found]
        P = len(found)
        return Spectrum(out, {"rings": result.network.count, "dofs": P, "gamma": "off",
                              "model": "network of rigid rings and tension-only tethers "
                                       "(references/network)"})

    def time_series(self, params, until_s):
        from rawehelix.studies import network_simulate
        return network_simulate.compute(params, until_s)

    def forced_backend(self, params, comm=MPI.COMM_SELF, accurate=False, ts_type=None):
        from rawehelix.references.network.forced import NetworkBackend
        return NetworkBackend(params)

    def period_map(self, params):
        self._refused(params, "orbits")

    def driven_frequencies(self, params, m, f_max_Hz, natural_modes):
        self._refused(params, "a forced response")

    def spin_series(self, params, until_s, every_s, ts_type=None, fixed_steps=False):
        self._refused(params, "a spin-up")


@dataclass
class NetworkMode:
    """A network mode as the studies read one (the spline's and FE's fields)."""

    eigenvalue: complex  # normalised (i omega sqrt(L0/g))
    family: str
    fractions: dict
    dominant: list


#: every scheme by name
SCHEME_REGISTRY: Registry[Scheme] = Registry("discretisation.scheme",
                                             (FE(), Spline(), Network()),
                                             error=ParameterError)
assert SCHEME_REGISTRY.names() == SCHEMES == CORES.names(), \
    "the registry names the schemes of parameters.SCHEMES, each with its core"
#: the scheme of a name; any other name is refused as a scene's is
get = SCHEME_REGISTRY.get


def of(params: Parameters) -> Scheme:
    """The scheme of a scene (``discretisation.scheme``)."""
    return get(params.discretisation.scheme)


__all__ = ["FE", "Network", "SCHEME_REGISTRY", "Scheme", "Spectrum", "Spline", "get", "of"]
