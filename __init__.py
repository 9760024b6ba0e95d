"""rawehelix: dynamics of the tensegrity helix of a rotary airborne wind energy machine.

The helix is a Cosserat rod (Sanchez-Arriaga et al., Eqs. 30-40): centre line r(s, t)
and twist angle alpha(s, t), either the paper's unshearable rod or the shearable
Simo-Reissner rod (``model.kinematics``), with the section's law of its members
(``section.law``).  The public API (:mod:`rawehelix.api`)::

    import rawehelix as rh
    scene = rh.load_scene("stationary_table2", elements=16)
    st = rh.stationary(scene)      # SI arrays and .summary; st.write(outdir)
    table = rh.modes(scene)        # the modes of Table 3
    fr = rh.response(rh.load_scene("mobile_end", elements=8))  # linear response to the circle
    ts = rh.simulate(rh.load_scene("nominal_operation"), until_s=10.0)
    sw = rh.sweep(rh.load_scene("mobile_end", elements=8), f1_Hz=[9.0, 10.0])

Subpackages and top-level modules, from the top of the imports down (.importlinter;
docs/explanation/architecture.md):

- ``rawehelix.cli``: the ``rawehelix`` command line, its command registry and the demo
- ``rawehelix.api``: the public functions, one per command
- ``rawehelix.studies``: the command drivers and registries (schemes, orbit methods,
  quantities, needs), over ``present/`` (figures, reports), ``analysis/`` (post-processing)
  and ``store/`` (outputs, stores, locks); ``converge/`` and ``extremes/`` are two drivers
- ``rawehelix.solvers``: SNES, TS and SLEPc on the FE rod, and ``harmonic_balance/``
- ``rawehelix.references``: the paper's shooting and spline-Galerkin schemes and the
  ring-and-tether network (no FE code)
- ``rawehelix.models``: the rod models (unshearable, shearable) and the kinematics registry
- ``rawehelix.periodic_orbits``: the periodic-orbit problem, Floquet, continuation (numpy)
- ``rawehelix.meshes``: uniform and graded interval meshes
- ``rawehelix.forms``: the weak forms (UFL), one physics component a module
- ``rawehelix.parameters``: the scene parameters (SI), their checks and normalisation
- ``rawehelix.section_laws``: the section-law registry (UFL and numpy from one definition)
- ``rawehelix.members``, ``fits``, ``families``, ``compat``, ``errors``: the members'
  numpy laws and limits, when a fit's data determine it, the mode families, the calls
  that differ between DOLFINx versions, the errors
- ``rawehelix.operation``: the machine's numpy laws (rotor Cp/CT, generator, wind
  profile and wind in time, the rigid-shaft torque balance)
- ``rawehelix.section_math``, ``registry``: the section laws' algebra, the one registry class
"""

__version__ = "0.2.0"

from rawehelix.api import (Parameters, SceneError, SolverError, campbell, envelope,  # noqa: E402
                           labtest, load_scene, modes, operate, orbits, response, section,
                           simulate, stationary, sweep, torsion_loop)

__all__ = ["load_scene", "section", "stationary", "modes", "response", "simulate", "sweep", "orbits",
           "envelope", "operate", "campbell", "labtest", "torsion_loop", "SceneError", "SolverError",
           "Parameters", "__version__"]
