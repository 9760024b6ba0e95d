"""Where a discretisation stops being trusted: checked before a run, so that no
command returns a wrong number without saying so."""

from __future__ import annotations

from rawehelix.errors import SceneError
from rawehelix.parameters import Parameters, schemes


def check_bending_resolution(params: Parameters, command: str):
    """Refuse the IP bending form past :meth:`Discretisation.ip_limit` for the
    commands whose numbers it spoils there (modes, dynamics: the lateral
    eigenvalues lose more than 1e-3, docs/explanation/large_n.md).  The stationary state
    is not refused: its summary reports its own distance to the shooting
    reference, and Newton fails loudly where it cannot converge."""
    disc = params.discretisation
    if schemes.of(params).fe_assembled and disc.bending == "ip" and disc.elements > disc.ip_limit():
        raise SceneError(params.name, "discretisation.elements",
                         f"{disc.elements} is past the limit N <= {disc.ip_limit()} of "
                         f"discretisation.bending = 'ip' at degree {disc.degree} for '{command}' "
                         f"(the round-off of its fourth-order operator, entries ~ mu p^4 N^3, "
                         f"spoils the lateral eigenvalues by more than 1e-3; docs/explanation/large_n.md): "
                         f"use discretisation.bending = 'mixed' (--set "
                         f"discretisation.bending=mixed), or fewer elements")
