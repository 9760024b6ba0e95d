"""The C0 interior-penalty helpers of the bending forms (the dolfinx biharmonic demo, in 1D):
node jumps and averages of derivatives, the penalty factor and the form B(r, v) of int r''.v''."""

from __future__ import annotations

import ufl

from rawehelix.forms.kinematics import d


def jump(f, n):
    """[[f]] = f(+) n(+) + f(-) n(-): the jump of f at a node."""
    return f("+") * n("+")[0] + f("-") * n("-")[0]


def jump_d(f, n):
    """[[f']] = f'(+) n(+) + f'(-) n(-): the jump of the normal derivative at a node."""
    return d(f)("+") * n("+")[0] + d(f)("-") * n("-")[0]


def avg_d2(f):
    """{{f''}}: the average of the second derivative at a node."""
    return 0.5 * (d(f, 2)("+") + d(f, 2)("-"))


def ip_penalty(degree: int, penalty, dS):
    """The interior-penalty factor eta p^2 / h_avg at a node; eta is
    ``discretisation.penalty``."""
    h = ufl.CellDiameter(dS.ufl_domain())
    return penalty * degree**2 / (0.5 * (h("+") + h("-")))


def bending(r, v, degree: int, penalty, dx, dS):
    """C0 interior-penalty form of int r''.v'' (the dolfinx biharmonic demo, in 1D).

    The penalty eta p^2 / h_avg (:func:`ip_penalty`) scales with the degree
    and the element size.
    """
    n = ufl.FacetNormal(dS.ufl_domain())
    alpha_ip = ip_penalty(degree, penalty, dS)
    return (ufl.inner(d(r, 2), d(v, 2)) * dx
            - ufl.inner(avg_d2(r), jump_d(v, n)) * dS
            - ufl.inner(jump_d(r, n), avg_d2(v)) * dS
            + alpha_ip * ufl.inner(jump_d(r, n), jump_d(v, n)) * dS)
