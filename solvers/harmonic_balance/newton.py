"""Harmonic balance's Newton at fixed f1 and H (:mod:`.problem`): PETSc LU
steps damped by Deuflhard's natural monotonicity, and the rule that a correction at
round-off is convergence only where |G| is near its tolerance (issue 41: at
``ends.elongation = 1e9`` it stopped at |G|/|X| = 0.126 and the branch was reported)."""

from __future__ import annotations

import numpy as np

from rawehelix.periodic_orbits.continuation import FLOOR_FACTOR
from rawehelix.solvers.snes import SolverError
from rawehelix.solvers.harmonic_balance.sparse_lu import LU

BACKTRACK_MIN = 1.0 / 64  # the shortest fraction of a Newton step tried
STEP_TOL = 1e-12  # a Newton correction this small (relative to X): converged at G's floor


class Diverged(SolverError):
    """Newton's correction at round-off with |G| far above its tolerance: the scene
    holds no orbit that double precision resolves, at any H."""


def newton(hb, X, f1_Hz, H, tol, max_it, amplitude=1.0, plain=False):
    """Newton on the harmonic balance ``hb`` at fixed f1 and H, damped by natural
    monotonicity (``plain``: every step whole while G stays finite); raises
    :class:`Diverged` where its correction reaches round-off with |G| above FLOOR_FACTOR
    x ``tol``, SolverError where it finds no descent or does not converge."""
    last = np.inf
    for its in range(1, max_it + 1):
        G, _, J = hb.residual(X, f1_Hz, jacobian=True, resolution=H, amplitude=amplitude)
        res = hb.norm(G, X)
        if res <= tol:
            return X, its, res
        lu = LU(J)
        step = lu.solve(G)
        if np.linalg.norm(step) <= STEP_TOL * max(1.0, np.linalg.norm(X)):
            lu.destroy()  # X is exact to round-off: G is at its floor, if that is small
            if res <= FLOOR_FACTOR * tol:
                return X, its, res
            chord = hb.params.helix.EA_N * hb.params.ends.elongation
            raise Diverged(f"harmonic balance at f1 = {f1_Hz} Hz, H = {H}: Newton's "
                           f"correction is at round-off while |G|/|X| = {res:.3g} > "
                           f"{FLOOR_FACTOR * tol:g}, so no orbit to double precision "
                           f"(the chord's tension EA x ends.elongation is {chord:.3g} N); "
                           f"check the scene's ends.elongation and stiffnesses")
        frac = 1.0
        # Deuflhard's natural monotonicity: the simplified Newton correction at the
        # trial (the same LU) shorter than the step; |G| itself is no merit function
        # here, where the axial rows' scale (sigma) dwarfs the others'
        while frac >= BACKTRACK_MIN:
            trial = X - frac * step
            G_t = hb.residual(trial, f1_Hz, resolution=H, amplitude=amplitude)[0]
            finite = bool(np.all(np.isfinite(G_t)))
            if plain and finite:
                break
            bar = lu.solve(G_t) if finite else np.full_like(step, np.inf)
            if np.linalg.norm(bar) < (1 - frac / 4) * np.linalg.norm(step) \
                    or hb.norm(G_t, trial) <= tol:
                break
            frac /= 2
        else:
            lu.destroy()
            raise SolverError(f"harmonic balance at f1 = {f1_Hz} Hz, H = {H}: no descent "
                              f"along the Newton step (|G|/|X| = {res:.3g}); start the --f1 "
                              f"window where the response is small")
        lu.destroy()
        X, last = trial, res
    raise SolverError(f"harmonic balance did not converge at f1 = {f1_Hz} Hz, H = {H}, in "
                      f"{max_it} iterations (|G|/|X| = {last:.3g} > {tol:g}); start the --f1 "
                      f"window where the response is small, or try --method shooting")
