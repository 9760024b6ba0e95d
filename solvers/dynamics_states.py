"""The states of :class:`~rawehelix.solvers.dynamics.DynamicsSolver`: setting one,
reading the last accepted one, and keeping the last good one across a failed step.

The second-order form (TSALPHA2) holds the state in the model's space W (u, v);
the first-order form in its own pair space (the fields and their rates,
models/base.py::RodModel.pair_element): a state moves between the two field by
field, by role (the model's ``index`` and ``pair_index``).
"""

from __future__ import annotations

import dolfinx.fem

from rawehelix import compat
from rawehelix.models.base import PAIR_ROLES
from rawehelix.solvers.state import RodState


class DynamicsStates:
    """The state methods of :class:`DynamicsSolver` (a mixin: it uses the
    solver's ``rod``, ``form``, ``ts``, ``probes``, ``convergence`` and ``_velocity``)."""

    def set_state(self, state: RodState):
        """Start from ``state``: its time, configuration and velocity (at rest if
        it has none) and its controller constant C of Eq. (40) (if it has none,
        C makes the ground torque of the state zero: the stationary state
        carries no torque)."""
        form, rod = self.form, self.rod
        if form.second_order:
            rod.set_state(state, w=form.u, w_t=form.v)
        else:
            rod.set_state(state, w=rod.w, w_t=self._velocity)
            self._to_pair(rod.w, self._velocity)
        for f in self._state_functions():
            f.x.scatter_forward()
        self.ts.setTime(state.t)
        form.set_time(state.t)
        self.convergence.stale = True  # a new start: a fresh Jacobian (if reused)
        self._push()
        if state.offset is None:
            form.offset.value = 0.0
            form.offset.value = -self.probes.value("m0")  # m0 = 0 in this state
        else:
            form.offset.value = state.offset
        self._remember(state.t)
        self._fresh = self._has_state = True

    def state(self) -> RodState:
        """The last accepted state (a copy), with the controller constant C."""
        if not self._has_state:
            raise RuntimeError("DynamicsSolver: no state yet; call set_state or use from_stationary")
        form, rod = self.form, self.rod
        t = self.t if self._good is None else self._good[0]
        if form.second_order:
            w, w_t = form.u, form.v
        else:
            w, w_t = dolfinx.fem.Function(rod.W), self._velocity
            self._from_pair(w, w_t)
            w.x.scatter_forward()
            w_t.x.scatter_forward()
        state = rod.get_state(w, w_t, t)
        state.offset = float(form.offset.value)
        return state

    def _to_pair(self, w, w_t):
        """The first-order form's X <- (the fields of ``w``, their rates ``w_t``)."""
        model, x = self.rod.model, self.form.x
        for role in PAIR_ROLES:
            x.sub(model.pair_index(role)).interpolate(w.sub(model.index(role)))
            x.sub(model.pair_index(role, True)).interpolate(w_t.sub(model.index(role)))

    def _from_pair(self, w, w_t):
        """(``w``, ``w_t``) <- the fields and rates of the first-order form's X."""
        model, x = self.rod.model, self.form.x
        for role in PAIR_ROLES:
            w.sub(model.index(role)).interpolate(x.sub(model.pair_index(role)))
            w_t.sub(model.index(role)).interpolate(x.sub(model.pair_index(role, True)))

    def _push(self):
        """The TS solution <- the formulation's functions."""
        form = self.form
        if form.second_order:  # into the TS's own vectors: no new Vec (see _remember)
            U, V = self.ts.getSolution2()
            compat.petsc_vec(form.u).copy(U)
            compat.petsc_vec(form.v).copy(V)
            self.ts.setSolution2(U, V)
        else:
            X = self.ts.getSolution()
            compat.petsc_vec(form.x).copy(X)
            self.ts.setSolution(X)

    def _remember(self, t: float):
        """The current state is the last good one (restored after a failure).

        Called after every step: it copies into vectors made once.  (A petsc4py
        3.18 Vec dropped without destroy() goes to PETSc's garbage list and is
        only freed by PETSc.garbage_cleanup: a new copy per step leaked 9 kB a
        step, 24 GB in an N = 16 sweep.)"""
        functions = self._state_functions()
        if self._good_vecs is None:
            self._good_vecs = [compat.petsc_vec(f).duplicate() for f in functions]
        for f, v in zip(functions, self._good_vecs):
            compat.petsc_vec(f).copy(v)
        self._good = (t, self._good_vecs)

    def _state_functions(self):
        return (self.form.u, self.form.v) if self.form.second_order else (self.form.x,)

    def _restore_good(self):
        """Functions <- the last accepted state (after a failure PETSc may leave a bad one)."""
        if self._good is None:
            return
        t, vecs = self._good
        for f, v in zip(self._state_functions(), vecs):
            v.copy(compat.petsc_vec(f))
            f.x.scatter_forward()
        self.form.set_time(t)
        self.good_time = t
