"""What :class:`~rawehelix.solvers.dynamics.DynamicsSolver` reports of its current
state: the fields along s, the end moment (the model's moment observable) and the
energies.  Collective where they assemble; the fields on rank 0."""

from __future__ import annotations

import ufl
from mpi4py import MPI

import dolfinx.fem


#: the energy account's entries of a run with a rotor or a generator (None without)
MACHINE_ENERGY = ("rotor_kinetic", "power_in", "power_generator", "power_drag", "top_energy")


class DynamicsOutputs:
    """The output methods of :class:`DynamicsSolver` (a mixin: it uses the
    solver's ``rod``, ``form``, ``probes``, ``comm``, ``t`` and ``_good``)."""

    def state_arrays(self) -> dict | None:
        """The current state along s (normalised), on rank 0 (None elsewhere)."""
        f = self.probes.fields()
        if f is None:
            return None
        return {"t": self.t if self._good is None else self._good[0],
                "s": f["s"], "r": f["r"], "alpha": f["alpha"], "r_t": f["r_t"],
                "alpha_t": f["alpha_t"]}

    def end_moment(self) -> float:
        """The torsional moment at s = 1 / (GJ / L0) (normalised like the end torques,
        Eq. 39): the model's moment, tau(1) (34) or the hysteretic moment
        rho tau + (1 - rho) z of forms/hysteresis.py; collective.  The form is
        compiled at the first call."""
        if getattr(self, "_end_moment", None) is None:
            by_role, _ = self.form.fields.roles()
            m = self.rod.model.moment(by_role, self.rod.c)
            mesh = self.rod.mesh
            s = ufl.SpatialCoordinate(mesh)[0]
            self._end_moment = dolfinx.fem.form(m * s * ufl.ds(domain=mesh))
        return self.comm.allreduce(dolfinx.fem.assemble_scalar(self._end_moment), op=MPI.SUM)

    # -- energy (normalised) ----------------------------------------------------------
    def energy(self) -> dict:
        """Kinetic, potential, non-variational power and the power dissipated by the
        structural damping, 2 D (0 without it), of the current state (collective);
        with a rotor or a generator (solvers/end_torques.py) also the rotor's kinetic
        energy, the power in at the top, the generator's power out and the drag's
        power (ts_forms._Formulation._machine_forms)."""
        out = {"dissipation": 0.0}
        for name in ("kinetic", "potential", "power_nv", "dissipation") + MACHINE_ENERGY:
            form = getattr(self.form, name)
            if form is not None:
                out[name] = self.comm.allreduce(dolfinx.fem.assemble_scalar(form), op=MPI.SUM)
        return out
