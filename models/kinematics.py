"""The kinematics, chosen by name (``model.kinematics``): the one registry that the
models, solvers and studies ask instead of testing the name.

* ``paper``: the forces of Eqs. (30)-(33) (forms/paper.py) on the (r, alpha) rod;
* ``extensible``: stretch and bending from the stored energy 1/2 EA eps^2 +
  1/2 EI |t'|^2, t = r'/|r'| (forms/extensible.py), on the (r, alpha) rod;
* ``shearable``: the Simo-Reissner rod (r, alpha, n) (forms/shearable.py).

A :class:`Kinematics` gives every decision made by the kinematics' name: the rod
model that carries it, whether the planar (x, z) reduction applies, its share of the
modal damping estimates, the transverse equation of the tensioned cantilever and the
name of its independent stationary reference (references/, resolved by
studies/reference_check.py: the references share no code with this one).  Its UFL
half is the component of forms/coefficients.py (:data:`rawehelix.forms.coefficients.KINEMATICS`).
The names are :data:`rawehelix.parameters.KINEMATICS`, where a scene's kinematics is
checked; :func:`get` refuses any other name with the same message.

A new kinematics: its name in parameters/sections.py::KINEMATICS, its forms component
(forms/, registered in forms/coefficients.py::KINEMATICS), a subclass of
:class:`Kinematics` here that decides each of :data:`Kinematics.DECISIONS` (one left
undecided is refused when the class is defined), registered in
:data:`KINEMATICS_REGISTRY`; a new reference (references/) is named in
studies/reference_check.py::references.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from rawehelix.parameters import KINEMATICS, Parameters
from rawehelix.parameters.checks import ParameterError
from rawehelix.registry import Registry


def paper_axial_strain(tension, EA):
    """eps with EA eps (1 + eps) = T_e: the end strain of the paper's kinematics."""
    return (np.sqrt(1 + 4 * np.asarray(tension, dtype=float) / EA) - 1) / 2


def unshearable_rod(params: Parameters):
    """The (r, alpha) rod (models/unshearable.py)."""
    from rawehelix.models.unshearable import UnshearableRod
    return UnshearableRod(params)


def shearable_rod(params: Parameters):
    """The (r, alpha, n) rod (models/shearable.py)."""
    from rawehelix.models.shearable import ShearableRod
    return ShearableRod(params)


class Kinematics:
    """What the models, solvers and studies need of a kinematics (one instance per
    name).  A subclass decides each of :data:`DECISIONS`; one it leaves to this class
    is refused when the subclass is defined (no silent fall-back)."""

    #: the scene's name of it (model.kinematics)
    name: str
    #: the rod model (models/base.py::RodModel) of a scene of this kinematics
    rod_model: Callable[[Parameters], object]
    #: the planar (x, z) rod of solvers/planar.py reduces this kinematics' fields
    planar_reduction: bool
    #: the Kelvin-Voigt estimate of the longitudinal modes holds the bending share
    #: tau_b mu k^4 (bending acts on the whole r, solvers/modal_window.py)
    bending_in_axial_damping: bool
    #: (T, EI) of the transverse equation of the tensioned cantilever under the end
    #: tension T_e, from (T_e, EI, EA) (solvers/analytic.py::cantilever_transverse)
    cantilever_transverse: Callable
    #: the name of its independent stationary reference
    #: (studies/reference_check.py::references)
    reference: str

    DECISIONS = ("name", "rod_model", "planar_reduction", "bending_in_axial_damping",
                 "cantilever_transverse", "reference")

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        # dispatch-ok: a subclass is checked for the decisions its definition must make
        undecided = [k for k in cls.DECISIONS if not hasattr(cls, k)]
        if undecided:
            raise TypeError(f"the kinematics {cls.__name__} does not decide {undecided} "
                            "(models/kinematics.py::Kinematics)")


def paper_transverse(tension, EI, EA):
    """T r' with |r'| = 1 + eps: the transverse tension is T_e / (1 + eps), EI stays."""
    return tension / (1 + paper_axial_strain(tension, EA)), EI


def extensible_transverse(tension, EI, EA):
    """T t with the bending energy on the unit tangent per unstretched length:
    T_e / (1 + eps) and EI / (1 + eps)^2, eps = T_e / EA."""
    stretch = 1 + np.asarray(tension, dtype=float) / EA
    return tension / stretch, EI / stretch**2


class Paper(Kinematics):
    name, reference = "paper", "shooting"
    rod_model = staticmethod(unshearable_rod)
    planar_reduction, bending_in_axial_damping = True, True
    cantilever_transverse = staticmethod(paper_transverse)


class Extensible(Kinematics):
    name, reference = "extensible", "extensible_elastica"
    rod_model = staticmethod(unshearable_rod)
    planar_reduction, bending_in_axial_damping = True, False
    cantilever_transverse = staticmethod(extensible_transverse)


class Shearable(Kinematics):
    name, reference = "shearable", "shearable_elastica"
    rod_model = staticmethod(shearable_rod)
    planar_reduction = False  # its director is not reduced
    bending_in_axial_damping = False
    # the paper's closed form, as before the registry (shear adds its own compliance,
    # which only the clamped rod of solvers/shearable_cantilever.py resolves)
    cantilever_transverse = staticmethod(paper_transverse)


#: every kinematics by name
KINEMATICS_REGISTRY: Registry[Kinematics] = Registry(
    "model.kinematics", (Paper(), Extensible(), Shearable()), error=ParameterError)
assert KINEMATICS_REGISTRY.names() == KINEMATICS, \
    "the registry names the kinematics of parameters.KINEMATICS"
#: the kinematics of a name; any other name is refused as a scene's is
get = KINEMATICS_REGISTRY.get


def of(params: Parameters) -> Kinematics:
    """The kinematics of a scene (``model.kinematics``)."""
    return get(params.model.kinematics)


__all__ = ["Extensible", "KINEMATICS_REGISTRY", "Kinematics", "Paper", "Shearable",
           "extensible_transverse", "get", "of", "paper_axial_strain", "paper_transverse",
           "shearable_rod", "unshearable_rod"]
