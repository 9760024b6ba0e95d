"""The energy balance of a run with a rotor and a generator, step by step:

    work in (the rotor's, int (mN + Q) Omega(L0) dt)
        = generator work (int tau Omega(0) dt) + dissipation + change in stored energy,

the dissipation being the structural damping's int 2 D dt, the drag's loss
-int F_A . r_t ds dt (Eq. 14) and the non-variational terms' -int P_nv dt
(forms/energy.py), the stored energy K + U + 1/2 J Omega(L0)^2 (the rotor's spin)
and, with a lifted top, 1/2 m_top |r_t(L0)|^2 - F . r(L0) (its mass and the lifter's and
weight's constant force; the thrust's power is in the work in).
Each power is the trapezoidal integral over the accepted steps (normalised, then SI:
energies by M g L0)."""

from __future__ import annotations

import numpy as np

#: the powers integrated in time, by their name in DynamicsSolver.energy()
POWERS = ("power_in", "power_generator", "dissipation", "power_drag", "power_nv")


class EnergyAccount:
    """Call it with the solver at the start and after every accepted step
    (``advance(on_step=account)``, and once before); :meth:`summary` in SI."""

    def __init__(self):
        self.t0 = None
        self.work = dict.fromkeys(POWERS, 0.0)
        self._last = None  # (t, powers) of the last call
        self.stored0 = self.stored = None

    def __call__(self, solver):
        t = solver.t
        solver.form.set_time(t)  # the step's own time: alpha2 leaves t_{n + alpha_f} set
        e = solver.energy()  # collective
        powers = {k: e[k] for k in POWERS}
        # the lifted top's 1/2 m |r_t(1)|^2 - F . r(1) (solvers/lifted_top.py) with it
        stored = e["kinetic"] + e["potential"] + e["rotor_kinetic"] + e.get("top_energy", 0.0)
        if self._last is None:
            self.t0, self.stored0 = t, stored
        elif t > self._last[0]:
            dt = t - self._last[0]
            for k in POWERS:
                self.work[k] += 0.5 * dt * (powers[k] + self._last[1][k])
        self._last, self.stored = (t, powers), stored

    def balance(self) -> float:
        """work in - generator work - dissipation - change in stored energy (normalised)."""
        w = self.work
        return (w["power_in"] - w["power_generator"] - w["dissipation"] + w["power_drag"]
                + w["power_nv"] - (self.stored - self.stored0))

    def summary(self, q) -> dict:
        """The energy block of summary.json [J]; ``balance_of_work_in`` relative."""
        scale = q.force_scale * q.L0  # M g L0 [J]
        w = self.work
        out = {"work_in_J": w["power_in"], "generator_work_J": w["power_generator"],
               "damping_dissipated_J": w["dissipation"], "drag_dissipated_J": -w["power_drag"],
               "non_variational_dissipated_J": -w["power_nv"],
               "stored_change_J": (self.stored - self.stored0) if self.stored is not None else 0.0,
               "balance_J": self.balance() if self.stored is not None else 0.0}
        out = {k: float(v * scale) for k, v in out.items()}
        work_in = out["work_in_J"]
        out["balance_of_work_in"] = (abs(out["balance_J"]) / abs(work_in) if work_in
                                     else float(np.nan))
        return out

    @staticmethod
    def line(block: dict | None) -> str:
        """The summary's energy line ('' without a machine)."""
        if not block:
            return ""
        return (f"\n  energy: work in {block['work_in_J']:.6g} J = generator "
                f"{block['generator_work_J']:.6g} J + dissipated "
                f"{block['damping_dissipated_J'] + block['drag_dissipated_J'] + block['non_variational_dissipated_J']:.4g} J "
                f"+ stored {block['stored_change_J']:.4g} J; balance "
                f"{block['balance_of_work_in']:.2e} of the work in")


__all__ = ["EnergyAccount", "POWERS"]
