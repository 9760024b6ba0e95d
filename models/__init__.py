"""Rod models: what a solver asks of the rod it solves (:mod:`.base`),
:class:`~rawehelix.models.unshearable.UnshearableRod`, the paper's rod with its
physics components (forms/*: kinematics, Kelvin-Voigt damping, Bouc-Wen
hysteresis, the EI law), and :class:`~rawehelix.models.shearable.ShearableRod`,
the Simo-Reissner rod (forms/shearable.py).  Above forms and parameters, below solvers."""


def rod_model(params):
    """The model of a scene: its kinematics' (models/kinematics.py): the shearable
    rod, or the unshearable one (paper or extensible kinematics)."""
    from rawehelix.models import kinematics
    return kinematics.of(params).rod_model(params)
