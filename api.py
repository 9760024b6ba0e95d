"""The public Python API of rawehelix: compose a run in a few lines.

Example::

    import rawehelix as rh

    st = rh.stationary(rh.load_scene("stationary_table2", elements=8))
    print(st.summary["tension_N"])     # st.s_m, st.centre_line_m, st.tension_N, st.summary
    scene = rh.load_scene("nominal_operation", elements=8)
    ts = rh.simulate(scene, until_s=10.0)
    print(ts.spin_rpm[-1], ts.summary["settling_time_s"])
    ts.write("results/spin_up")        # computing never writes files; write() does

Every function takes a validated scene (:func:`load_scene`) and returns a
result with SI numpy arrays, the ``summary`` dict that ``summary.json`` holds,
and ``write(outdir)``.  Bad input raises :class:`SceneError`, whose message
names the file or command, the key and what is allowed (the command line
prints the same message); a solve that fails raises :class:`SolverError`
saying what failed, where and what to try.  Under MPI every function is
collective (``comm``: default MPI.COMM_WORLD); the arrays are on rank 0.
"""

from __future__ import annotations

from rawehelix.errors import SceneError, SolverError
from rawehelix.parameters import Parameters
from rawehelix.studies.orbit_method import default_for

__all__ = ["load_scene", "section", "stationary", "modes", "response", "simulate", "sweep", "orbits",
           "envelope", "operate", "campbell",
           "labtest", "torsion_loop", "SceneError", "SolverError", "Parameters"]


def _world(comm):
    """The communicator of a call: MPI.COMM_WORLD unless given (imported late:
    ``import rawehelix`` loads neither MPI nor FEniCSx)."""
    if comm is not None:
        return comm
    from mpi4py import MPI
    return MPI.COMM_WORLD


def _ready(scene: Parameters, command: str, comm, f1_Hz=None) -> Parameters:
    """The scene a command runs: refused, before anything is allocated, if the run is
    past this machine's memory (:mod:`rawehelix.studies.resources`: one estimate for
    every command); with the elongation found for ``ends.tension_N``
    (:func:`rawehelix.solvers.tension_target.resolve`: unchanged if the scene gives
    ``ends.elongation``)."""
    from rawehelix.solvers import tension_target
    from rawehelix.studies import resources
    resources.check_run(scene, command, f1_Hz)
    return tension_target.resolve(scene, comm)


def load_scene(name_or_path, elements: int | None = None, degree: int | None = None,
               scheme: str | None = None, overrides: dict | None = None) -> Parameters:
    """The validated scene: a TOML file, or the name of a shipped scene
    (``stationary_table2``, ``nominal_operation``, ``mobile_end``).

    Args:
        name_or_path: a shipped scene's name or the path of a TOML scene file.
        elements: the number of elements N (default: the scene's
            ``discretisation.elements``).
        degree: the polynomial degree p of the FE scheme (default: the scene's).
        scheme: "fe" (finite elements) or "spline" (the paper's scheme).
        overrides: dotted scene keys and their values, e.g.
            ``{"helix.EI_Nm2": 9000.0, "time.dt_s": 5e-4}``, validated like the file.

    Raises:
        SceneError: a key or value the scene does not allow."""
    from rawehelix.studies import scene
    return scene.load(name_or_path, elements=elements, degree=degree, scheme=scheme,
                      overrides=overrides)


def section(scene: Parameters):
    """EA, EI and GJ of the scene's section's members (closed forms, no solve), what
    they come from, and the lab tests' values: :mod:`rawehelix.studies.section_moduli`
    (``rawehelix section``).  ``result.summary``, ``result.write(outdir)``.

    Args:
        scene: the validated scene (:func:`load_scene`); its ``[section]`` gives the
            members (tethers, their EA, radius, lay angle, self-stress, bars)."""
    from rawehelix.studies import section_moduli
    return section_moduli.compute(scene)


def stationary(scene: Parameters, comm=None):
    """The stationary state with fixed ends (Sec. 5.1) under the ends' balanced
    torque (torque.top_Nm, held by the ground: a twisted state, Omega = 0; a
    controller that spins the helix up, controller.k1 > 0 with a target_rpm, raises
    SceneError), checked against the shooting reference where it applies: a
    :class:`~rawehelix.studies.stationary.Stationary` with ``s_m``,
    ``centre_line_m`` (n x 3), ``tension_N`` and ``summary`` (``summary["limits"]``:
    the structure's limits in that state; ``"ends"``: the elongation, and the
    tension asked for with ``ends.tension_N``; ``"torque"``: the twist;
    ``"shooting"``: "compared", "not applicable: why" or "did not converge: why").

    Args:
        scene: the validated scene (:func:`load_scene`).
        comm: the MPI communicator (default ``MPI.COMM_WORLD``)."""
    comm = _world(comm)
    scene = _ready(scene, "stationary", comm)
    from rawehelix.studies import stationary as study
    return study.compute(scene, comm)


def operate(scene: Parameters, wind_m_s, comm=None):
    """The operating points of the scene's rotor (``[rotor]``) and generator
    (``[generator]``) at the wind speeds ``wind_m_s`` [m/s]: relative
    equilibria (the spin Omega closed by the torque balance, the helix's stationary state
    under the rotor's torque), every branch of the balance traced through folds in the
    wind, up to the helix's first limit.  An :class:`~rawehelix.studies.operate.Operate`
    with ``points`` and ``summary`` (``summary["points"]``: wind_m_s, rotor_rpm, tsr,
    power_W, rotor_power_W, torque_top_Nm, torque_ground_Nm, thrust_N, tension_max_N,
    tension_min_N, twist_deg, stable, branch; ``"limits"`` with ``first_limit``;
    ``"stopped"``: why the curve ends).  A scene without a rotor or generator, or wind
    speeds with no operating point in the rotor's table, raise SceneError.

    Args:
        scene: the validated scene (:func:`load_scene`).
        wind_m_s: the wind speeds [m/s] at the reference height (ascending or not).
        comm: the MPI communicator (default ``MPI.COMM_WORLD``)."""
    comm = _world(comm)
    from rawehelix.studies import operate as study
    winds = study.check_winds(wind_m_s)
    # the elongation of ends.tension_N first (the plan's axis reads the chord), then the
    # table's refusals before the operating points' FE work
    scene = _ready(scene, "operate", comm)
    planned = study.plan(scene, winds)
    return study.compute(scene, winds, comm, planned)


def modes(scene: Parameters, count: int | None = None, comm=None):
    """The natural modes about the stationary state (Table 3): a list of modes
    in ascending frequency (the order of ``rawehelix modes``' table), each
    with ``family``, ``frequency_Hz``, ``decay_per_s``, ``period_s``,
    ``eigenvalue`` (normalised) and its shape in SI; ``.summary``.

    Default: the lowest 3 oscillating modes of each family, the rigid
    rotation, and the slowest real eigenvalues of a damped spectrum, if found,
    as family ``overdamped`` (a decay rate, no period; listed last); ``count``:
    the ``count`` slowest modes.  ``scene.discretisation.scheme`` picks FE
    (SLEPc) or the paper's spline scheme.

    Args:
        scene: the validated scene (:func:`load_scene`).
        count: how many of the slowest modes to compute (default: the list above).
        comm: the MPI communicator (default ``MPI.COMM_WORLD``)."""
    comm = _world(comm)
    scene = _ready(scene, "modes", comm)
    from rawehelix.studies import modes as study
    return study.compute(scene, count=count, comm=comm)


def campbell(scene: Parameters, wind_m_s, envelope: dict | None = None, comm=None):
    """The Campbell diagram of the helix: at the operating points of the
    scene's ``[rotor]`` and ``[generator]`` at each wind speed, the lowest modes of each
    family about the relative equilibrium (the rotor's spin inertia and aerodynamic
    damping, the generator's dtau/dOmega in the torsional family), each point's
    stability, and every crossing of the 1P, 2P and BP (blades) lines with a mode:
    :mod:`rawehelix.studies.campbell` (``rawehelix campbell``).  ``result.summary``
    (``points[]``, ``crossings[]``), ``result.write(outdir)``.

    Args:
        scene: the validated scene (:func:`load_scene`), with a ``[rotor]``.
        wind_m_s: the wind speeds [m/s] at the wind's reference height.
        envelope: an ``envelope`` run's summary (its summary.json as a dict): the band
            of forcing frequencies where the forced helix slackens, on the figure.
        comm: the MPI communicator (default ``MPI.COMM_WORLD``)."""
    comm = _world(comm)
    scene = _ready(scene, "campbell", comm)
    from rawehelix.studies import campbell as study
    return study.compute(scene, wind_m_s, comm=comm, envelope=envelope)


def response(scene: Parameters, f1_Hz=None, comm=None):
    """The linear frequency response to the upper end's circle (Sec. 5.3, Eq. 70)
    at each f1 [Hz] (default: the scene's [sweep] list), about the stationary
    state with the end at the circle's centre: a
    :class:`~rawehelix.studies.response.ResponseResult` with ``f1_Hz``,
    ``lateral_mid_amplitude_m`` (semi-major axis of the midpoint's lateral
    ellipse), ``tension_amplitude_N`` (at s = 0), ``peaks`` (``peaks_Hz``) with
    the nearest natural mode, ``natural`` (the modes of the same
    linearisation) and ``summary``.  One f1's complex response vector:
    :class:`rawehelix.solvers.response.HarmonicResponse`.

    Args:
        scene: the validated scene (:func:`load_scene`).
        f1_Hz: the forcing frequencies [Hz] (default: the scene's ``[sweep]`` list).
        comm: the MPI communicator (default ``MPI.COMM_WORLD``)."""
    comm = _world(comm)
    scene = _ready(scene, "response", comm, f1_Hz)
    from rawehelix.studies import response as study
    return study.compute(scene, f1_Hz, comm=comm)


def simulate(scene: Parameters, until_s: float | None = None, comm=None,
             options: dict | None = None, progress: bool | None = None):
    """The dynamics from the stationary state (Secs. 5.2, 5.3) to ``until_s``
    [s] (default ``time.until_s``): a :class:`~rawehelix.studies.simulate.TimeSeries`
    with ``t_s``, ``spin_rpm`` (n x 3: s = 0, ~L0/2, L0), ``ground_torque_Nm``,
    ``tension_s0_N``, ``tension_s1_N``, ``lateral_mid_m``, ``final_state``,
    ``limits_history`` (t, smallest and largest member force) and ``summary``
    (``summary["limits"]``: the structure's limits over the run; also in a
    failed run's ``SimulationError.partial``).

    Args:
        scene: the validated scene (:func:`load_scene`).
        until_s: the end time [s] (default: the scene's ``time.until_s``).
        comm: the MPI communicator (default ``MPI.COMM_WORLD``).
        options: PETSc options of the integrator without the prefix, e.g.
            ``{"ts_type": "cn"}``.
        progress: print a progress line now and then (default: when stdout is
            a terminal)."""
    comm = _world(comm)
    scene = _ready(scene, "simulate", comm)
    from rawehelix.studies import resources
    resources.check_simulate(scene, until_s, "until_s")
    from rawehelix.studies import simulate as study
    return study.compute(scene, until_s=until_s, comm=comm, options=options,
                         progress=progress)


def sweep(scene: Parameters, f1_Hz=None, comm=None, checkpoint=None):
    """The periodic response of Sec. 5.3 at each forcing frequency f1 [Hz]
    (default: the scene's [sweep] list), continued from one f1 to the next as
    in the paper: a :class:`~rawehelix.studies.sweep.SweepResult` with
    ``points`` (``f1_Hz``, ``tension_max_N``, ``tension_min_N``,
    ``tension_mean_N``, ``periods``, ``periodic``) and ``summary``.
    ``checkpoint``: a directory that keeps finished points, so that the same
    call resumes a stopped sweep.

    Args:
        scene: the validated scene (:func:`load_scene`).
        f1_Hz: the forcing frequencies [Hz], in the order they are swept
            (default: the scene's ``[sweep]`` list).
        comm: the MPI communicator (default ``MPI.COMM_WORLD``).
        checkpoint: a directory that keeps finished points (default: none)."""
    comm = _world(comm)
    scene = _ready(scene, "sweep", comm, f1_Hz)
    from rawehelix.studies import sweep as study
    return study.compute(scene, f1_Hz, comm=comm, checkpoint=checkpoint)


def orbits(scene: Parameters, f1_start_Hz: float, f1_stop_Hz: float, comm=None, progress=None,
           outdir=None, tension_step=None, max_points: int = 400, superharmonics=None,
           method: str = default_for("orbits")):
    """The branch of periodic orbits of Sec. 5.3 from f1_start towards f1_stop [Hz]:
    shooting on the period map of the generalised-alpha integrator, Floquet
    multipliers from its tangent, pseudo-arclength continuation through folds,
    the step held so that T max changes by at most ``tension_step`` (relative)
    between points, and closing in on the k:1 superharmonic sites f_n / k of the
    lateral natural frequencies (k in ``superharmonics``, default (2, 3); () for
    none), reported in ``peaks``.  An :class:`~rawehelix.studies.orbits.OrbitsResult` with
    ``branch`` (``f1_Hz``, ``tension_max_N``, ``tension_min_N``, ``stable``,
    ``max_multiplier``, ``newton_iterations``), ``folds``, ``bifurcations``,
    ``peaks`` and ``summary``.  ``progress(orbit)`` is called at every point.
    Each rank of ``comm`` traces one f1 window (joined on rank 0); with
    ``outdir`` every point is stored as found and a rerun resumes after the last.
    ``method``: "shooting" (above), "hb" (harmonic balance, Hill's method for the
    multipliers, H chosen by accuracy and reported per point) or "auto" (the rule
    of :func:`rawehelix.studies.orbit_method.choose`).

    Args:
        scene: the validated scene (:func:`load_scene`).
        f1_start_Hz: the forcing frequency [Hz] the branch starts from.
        f1_stop_Hz: the forcing frequency [Hz] it is continued towards.
        comm: the MPI communicator (default ``MPI.COMM_WORLD``).
        progress: a callable called with each orbit as it is found (default: none).
        outdir: a directory that keeps every point, so that a rerun resumes.
        tension_step: the largest relative change of T max between two points
            (default: the method's own).
        max_points: the most points the branch may have.
        superharmonics: the orders k of the k:1 superharmonic sites to close in
            on (default (2, 3); () for none).
        method: "shooting", "hb" or "auto"."""
    comm = _world(comm)
    scene = _ready(scene, "orbits", comm)
    from rawehelix.studies import orbits as study, resources
    resources.check_branches(scene, comm.size, f1_start_Hz, f1_stop_Hz, method,
                             key="--f1", max_points=max_points)
    return study.compute(scene, f1_start_Hz, f1_stop_Hz, comm=comm, progress=progress,
                         outdir=outdir, tension_step=tension_step, max_points=max_points,
                         superharmonics=superharmonics, method=method)


def envelope(scene: Parameters, vary, f1_lo_Hz: float, f1_hi_Hz: float, comm=None,
             outdir=None, method: str = default_for("envelope"), progress=None,
             f1_step_Hz: float | None = None):
    """The operating envelope of Sec. 5.3's forced helix in (f1, KEY): ``vary`` is
    "KEY=LO:HI[:COUNT]" (a dotted scene key, COUNT values, default 5); at each value the
    branch over [f1_lo, f1_hi] (``method``: "hb", "shooting" or "auto"), the f1 where the
    first limit of the structure is reached, the folds continued in KEY (the band of
    two coexisting stable responses) and the period doublings and Neimark-Sackers
    continued in KEY (the unstable bands).  An
    :class:`~rawehelix.studies.envelope.EnvelopeResult` (``summary``, ``write(outdir)``:
    summary.json and envelope.png).  The values are dealt to the ranks of ``comm``; with
    ``outdir`` each value's branch is stored and a rerun resumes; ``f1_step_Hz``: the
    most a branch steps in f1 (stability is judged at its points).

    Args:
        scene: the validated scene (:func:`load_scene`).
        vary: the scene key varied and its values, "KEY=LO:HI[:COUNT]" (or a
            :class:`~rawehelix.studies.sampling.Variable`).
        f1_lo_Hz: the lowest forcing frequency [Hz] of each branch.
        f1_hi_Hz: the highest forcing frequency [Hz] of each branch.
        comm: the MPI communicator (default ``MPI.COMM_WORLD``).
        outdir: a directory that keeps each value's branch, so that a rerun resumes.
        method: how each branch is traced: "hb", "shooting" or "auto".
        progress: a callable called as the branches are traced (default: none).
        f1_step_Hz: the most a branch steps in f1 [Hz] (default: the method's own)."""
    from rawehelix.studies import envelope as study
    from rawehelix.studies.sampling import Variable, parse_vary
    from rawehelix.studies import resources
    comm = _world(comm)
    scene = _ready(scene, "envelope", comm)
    vary = vary if isinstance(vary, Variable) else parse_vary(vary)
    resources.check_branches(scene, vary.count or study.DEFAULT_VALUES, f1_lo_Hz, f1_hi_Hz,
                             method)
    return study.compute(scene, vary, f1_lo_Hz, f1_hi_Hz, comm=comm, outdir=outdir,
                         method=method, progress=progress, f1_step_Hz=f1_step_Hz)


def labtest(test: str, scene: Parameters | None = None, tensions_N=None, loads=None,
            fit: bool = False, rod_EI_Nm2: float | None = None, elements: int | None = None,
            degree: int | None = None, gravity: bool = True, comm=None):
    """The paper's lab test ``test`` ("axial", "bending" or "torsion", Sec. 4,
    Fig. 2 a-c) run on a 6.76 m segment of ``scene``'s helix (default the
    Table 2 helix) clamped at a wall, with the tension T_e [N] (``tensions_N``)
    a dead load along its axis; ``loads`` are F_N [N] (bending) or M_t [Nm]
    (torsion).  A :class:`~rawehelix.studies.labtest.LabTest` whose ``summary``
    has the apparent EA, EI or GJ that Eqs. (62), (63), (65) infer.
    ``fit`` (bending): the intrinsic law EI = a T + b whose simulated test
    reproduces Eq. (64) (``summary["law"]``); ``rod_EI_Nm2``: the rod's constant
    EI (default Eq. (64) at each T_e).

    Args:
        test: "axial", "bending" or "torsion".
        scene: the scene whose helix is tested (default ``stationary_table2``).
        tensions_N: the tensions T_e [N] of the test (default: the paper's).
        loads: the loads F_N [N] (bending) or M_t [Nm] (torsion) at each tension
            (default: the paper's).
        fit: fit the intrinsic law EI = a T + b (bending only).
        rod_EI_Nm2: the rod's constant EI [N m^2] (default: Eq. (64) at each T_e
            in the bending test, the scene's EI in the others).
        elements: the segment's number of elements (default: the lab test's own).
        degree: the polynomial degree p (default: the scene's).
        gravity: whether the segment's weight acts.
        comm: the MPI communicator (default ``MPI.COMM_WORLD``)."""
    from rawehelix.studies import labtest as study, resources
    scene = scene if scene is not None else load_scene("stationary_table2")
    resources.check(study.lab_parameters(scene, elements, degree), "labtest")
    resources.check_count("--tension/--loads", len(tensions_N or ()) * max(len(loads or ()), 1))
    return study.compute(scene, test, tensions_N=tensions_N, loads=loads, fit=fit,
                         rod_EI_Nm2=rod_EI_Nm2, elements=elements, degree=degree,
                         gravity=gravity, comm=_world(comm))


def torsion_loop(law: dict, period_s: float = 20.0, cycles: int = 4, steps_per_cycle: int = 200,
                 elements: int = 2, comm=None):
    """The hysteretic torsion test of Sec. 4 (Fig. 2c, Fig. 5) in time: the lab
    segment of the Table 2 helix, T_e = 200 N, its end twisted from 0 to 50
    degrees and back ``cycles`` times in ``period_s`` [s] each, with the Bouc-Wen
    law ``law`` (the scene's ``[torsion_hysteresis]`` keys).  A dict of arrays:
    ``t_s``, ``theta_rad``, ``moment_Nm`` (the FE rod's end moment) and
    ``reference_moment_Nm`` (the Bouc-Wen ODE of the same twist history, scipy).

    Args:
        law: the Bouc-Wen law's keys and values, as in a scene's
            ``[torsion_hysteresis]`` section.
        period_s: the period [s] of one twist cycle.
        cycles: the number of cycles.
        steps_per_cycle: the time steps of one cycle.
        elements: the segment's number of elements.
        comm: the MPI communicator (default ``MPI.COMM_WORLD``)."""
    from rawehelix.parameters import TorsionHysteresis
    from rawehelix.studies import torsion_loop as study
    law = TorsionHysteresis(**law)
    t, theta, moment = study.run(study.segment(law, elements), period_s, cycles,
                                 steps_per_cycle, comm=_world(comm))
    return {"t_s": t, "theta_rad": theta, "moment_Nm": moment,
            "reference_moment_Nm": study.reference(law, t, period_s)}
