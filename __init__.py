"""rawehelix: dynamics of the tensegrity helix of a rotary airborne wind energy machine.

The helix is an unshearable Cosserat rod (Sanchez-Arriaga et al., Eqs. 30-40):
centre line r(s, t) and twist angle alpha(s, t).  Subpackages:

- ``rawehelix.parameters``: the scene parameters (SI) and their normalisation (numpy only)
- ``rawehelix.forms``: the weak forms (UFL)
- ``rawehelix.meshes``: uniform and graded interval meshes
- ``rawehelix.solvers``: SNES, TS, SLEPc, and the independent references
- ``rawehelix.studies``: scenes, drivers and writers behind the command line
"""

__version__ = "0.1.0"
