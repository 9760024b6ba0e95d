"""rawehelix: dynamics of the tensegrity helix of a rotary airborne wind energy machine.

The helix is an unshearable Cosserat rod (Sanchez-Arriaga et al., Eqs. 30-40):
centre line r(s, t) and twist angle alpha(s, t).  The public API
(:mod:`rawehelix.api`)::

    import rawehelix as rh
    scene = rh.load_scene("stationary_table2", elements=16)
    st = rh.stationary(scene)      # SI arrays and .summary; st.write(outdir)
    table = rh.modes(scene)        # the modes of Table 3
    fr = rh.response(rh.load_scene("mobile_end", elements=8))  # linear response to the circle
    ts = rh.simulate(rh.load_scene("nominal_operation"), until_s=10.0)
    sw = rh.sweep(rh.load_scene("mobile_end", elements=8), f1_Hz=[9.0, 10.0])

Subpackages:

- ``rawehelix.parameters``: the scene parameters (SI) and their normalisation (numpy only)
- ``rawehelix.forms``: the weak forms (UFL)
- ``rawehelix.meshes``: uniform and graded interval meshes
- ``rawehelix.solvers``: SNES, TS, SLEPc, and the independent references
- ``rawehelix.studies``: scenes, drivers, writers and the command line
"""

__version__ = "0.2.0"

from rawehelix.api import (Parameters, SceneError, SolverError, campbell, envelope,  # noqa: E402
                           labtest, load_scene, modes, operate, orbits, response, section,
                           simulate, stationary, sweep, torsion_loop)

__all__ = ["load_scene", "section", "stationary", "modes", "response", "simulate", "sweep", "orbits",
           "envelope", "operate", "campbell", "labtest", "torsion_loop", "SceneError", "SolverError",
           "Parameters", "__version__"]
