"""Rod models: what a solver asks of the rod it solves (:mod:`.base`), and
:class:`~rawehelix.models.unshearable.UnshearableRod`, the paper's rod with its
physics components (forms/*: kinematics, Kelvin-Voigt damping, Bouc-Wen
hysteresis, the EI law).  Above forms and parameters, below solvers."""
