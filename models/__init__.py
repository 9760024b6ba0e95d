"""Rod models: what a solver asks of the rod it solves (:mod:`.base`),
:class:`~rawehelix.models.unshearable.UnshearableRod`, the paper's rod with its
physics components (forms/*: kinematics, Kelvin-Voigt damping, Bouc-Wen
hysteresis, the EI law), and :class:`~rawehelix.models.shearable.ShearableRod`,
the Simo-Reissner rod (forms/shearable.py).  Above forms and parameters, below solvers."""


def rod_model(params):
    """The model of a scene: ``model.kinematics = "shearable"`` the shearable rod,
    otherwise the unshearable one (paper or extensible kinematics)."""
    from rawehelix.models.shearable import ShearableRod
    from rawehelix.models.unshearable import UnshearableRod
    if params.model.kinematics == "shearable":
        return ShearableRod(params)
    return UnshearableRod(params)
