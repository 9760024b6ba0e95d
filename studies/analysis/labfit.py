"""The intrinsic bending law EI = a T + b whose simulated lab test reproduces
Eq. (64) at the paper's tensions (``rawehelix labtest bending --fit``,
docs/explanation/labtest.md): per tension a 1-D root find of a constant EI
(secant, from the closed-form inverse of solvers/analytic.py), the line through
the roots, then Gauss-Newton on (a, b) with the law in the rod.  The test itself
(``bending_test``: solver, T_e, loads -> its reading) is the caller's
(:mod:`rawehelix.studies.labtest`).

Below it, the tensegrity's members fitted to the three tests at the section level
(:func:`section_fit`, issue 29, docs/explanation/section.md): k from Eq. (62), the lay
angle or the self-stress from GJ = 140 N m^2 at 200 N, the layout's EI against
Eq. (64), and the fallback cone law (members.py::ConeSection).
"""

from __future__ import annotations

import numpy as np

from rawehelix import fits
from rawehelix.solvers import analytic
from rawehelix.errors import SceneError

FIT_TOLERANCE = 1e-4  # relative: the per-tension root find of the intrinsic EI
FIT_TARGET = 0.01  # the law's simulated test reproduces Eq. (64) within 1 %


def intrinsic_EI(solver, tension_N: float, target_Nm2: float, loads_N, bending_test,
                 rtol: float = FIT_TOLERANCE, max_iterations: int = 12):
    """The constant EI of the rod whose simulated bending test at T_e reads
    ``target_Nm2`` by Eq. (63): secant on log EI from the closed-form inverse."""
    L0 = solver.q.L0

    def misfit(EI):
        solver.set_bending_stiffness(EI)
        return np.log(bending_test(solver, tension_N, loads_N)["apparent_EI_Nm2"] / target_Nm2)

    guess = analytic.cantilever_intrinsic_EI(target_Nm2, tension_N, L0)
    if guess is None:
        raise SceneError("labtest --fit", f"T_e = {tension_N:g} N",
                         f"Eq. (64)'s EI = {target_Nm2:.4g} N m^2 is below the string's "
                         f"T L0^2 / 3 = {tension_N * L0**2 / 3:.4g} N m^2: no intrinsic EI")
    x0, x1 = np.log(guess), np.log(guess) + 0.01
    f0, f1 = misfit(np.exp(x0)), misfit(np.exp(x1))
    for _ in range(max_iterations):
        x0, x1, f0 = x1, x1 - f1 * (x1 - x0) / (f1 - f0), f1
        f1 = misfit(np.exp(x1))
        if abs(f1) < rtol:
            return float(np.exp(x1))
    raise SceneError("labtest --fit", f"T_e = {tension_N:g} N",
                     f"the root find of the intrinsic EI did not converge (misfit {f1:.2e})")


def fit(solver, tensions, targets, loads, bending_test):
    """The intrinsic law EI = a T + b (see the module doc) whose simulated test reads
    ``targets`` (Eq. 64) at the tensions: the roots of a constant EI per tension,
    the line through them, then (a, b) refined by Gauss-Newton on the law's own
    simulated tests (the law in the rod at the local tension).  (rows, summary)."""
    targets = np.asarray(targets, dtype=float)
    why = fits.undetermined(fits.polynomial(tensions, 1), 2)
    if why:  # labtest._check refuses it first (exit 2): here for the API's callers
        raise SceneError("labtest --tension", list(tensions),
                         f"cannot determine the law EI = a T + b: {why}")
    roots = [intrinsic_EI(solver, T, t, loads, bending_test) for T, t in zip(tensions, targets)]
    line = np.polyfit(tensions, roots, 1)
    law, rows, misfit, iterations, why = _refine_law(solver, tensions, targets, loads, line,
                                                     bending_test)
    a, b = law
    apparent = np.array([r["apparent_EI_Nm2"] for r in rows])
    error = apparent / targets - 1
    intrinsic = a * np.asarray(tensions) + b
    return rows, {
        "fit": True, "tension_N": list(tensions), "load_N": list(loads),
        "law": {"a_Nm2_per_N": float(a), "b_Nm2": float(b)},
        "law_applied_as": "helix.EI_law in the rod: EI = a T + b at the local tension T = EA eps",
        "gauss_newton_iterations": iterations,
        "intrinsic_EI_Nm2": intrinsic.tolist(),
        "constant_EI_roots_Nm2": roots,
        "line_through_roots": {"a_Nm2_per_N": float(line[0]), "b_Nm2": float(line[1])},
        "apparent_EI_Nm2": apparent.tolist(), "eq64_EI_Nm2": targets.tolist(),
        "relative_error": error.tolist(),
        "within_1_percent": bool(not why and np.all(np.abs(error) <= FIT_TARGET)),
        "undetermined": why,  # None, or why the tests could not determine (a, b): fits.py
        "eq64_over_intrinsic": (targets / intrinsic).tolist(),
    }


def _refine_law(solver, tensions, targets, loads, start, bending_test,
                max_iterations: int = 8):
    """Gauss-Newton on (a, b) for log(apparent EI / Eq. 64) at the tensions, the law
    in the rod; from ``start``, finite-difference Jacobian.  (law, rows, misfit, its,
    why): ``why`` is None, or why a Jacobian could not determine (a, b) (fits.py),
    where the iteration stops."""
    def run(law):
        solver.set_bending_law(*law)
        rows = [bending_test(solver, T, loads) for T in tensions]
        return rows, np.log(np.array([r["apparent_EI_Nm2"] for r in rows]) / targets)

    law = np.asarray(start, dtype=float)
    rows, misfit = run(law)
    for iteration in range(max_iterations):
        if np.abs(misfit).max() < FIT_TOLERANCE:
            return law, rows, misfit, iteration, None
        steps = 1e-3 * np.abs(law)
        J = np.column_stack([(run(law + h * np.eye(2)[k])[1] - misfit) / h
                             for k, h in enumerate(steps)])
        why = fits.undetermined(J, 2, rtol=fits.DIFFERENCES_RTOL)
        if why:
            solver.set_bending_law(*law)
            return law, rows, misfit, iteration, why
        step = np.linalg.lstsq(J, -misfit, rcond=None)[0]
        law = law + step
        rows, misfit = run(law)
        if np.all(np.abs(step) <= 1e-6 * np.abs(law)):  # the least-squares floor
            return law, rows, misfit, iteration + 1, None
    return law, rows, misfit, max_iterations, None


# -- the members' fits at the section level (members.py's closed forms) -----------------
#
# The lab's three readings taken off the section law itself, without the rod: the axial
# test's strain eps at N = T_e, Q = 0 (Eq. 62 regressed through the origin); the torsion
# test's twist alpha / L0 = tau - tau_0 at N = T_e, Q = M_t (Eq. 65); the bending test's
# EI = dM/d kappa at N = T_e, through the tensioned cantilever's closed form (Eq. 63,
# solvers/analytic.py, no gravity) that the rod-level fit above solves in the rod.

SECTION_LEVEL = ("section: members.py's law at one section, the lab segment's Eq. (63) "
                 "through the tensioned cantilever's closed form (no gravity); the fitted "
                 "members then run in the rod, the FE section law in the simulated tests "
                 "(labtest.py::rod_check, the block's \"rod\")")
GJ_TARGET = (140.0, 200.0)  # GJ [N m^2] at T_e [N]: Sec. 4, Fig. 5
TWIST_RAD = np.radians(50.0)  # the torsion test's largest angle, about 50 deg (Sec. 4)


def section_state(members, N: float | None = None, Q: float | None = None,
                  eps: float | None = None, tau: float = 0.0, kappa: float = 0.0):
    """(eps, tau) of the members under the lab's end conditions: the axial force N
    (a dead load) or the stretch eps (the end held), and the torque Q or (Q None) the
    twist tau held.  A laid ring of tethers alone cannot hold its lay at Q = 0 under a
    tension (its torque N R tan(beta) unwinds it to beta = 0: a mechanism), so the
    lab's alpha = 0 is the laid state, held by the end fixtures (the reference)."""
    from scipy.optimize import root
    free = [N is not None, Q is not None]  # which of (eps, tau) are unknowns
    if not any(free):
        return float(eps), float(tau)
    eps0 = N / members.taut_moduli()["EA"] if N is not None else eps
    GJ = members.tangent(eps0, kappa, tau)["GJ"] if Q is not None else 0.0
    Q_here = members.resultants(eps0, kappa, tau)["Q"] if Q is not None else 0.0
    x0 = np.array([eps0, tau + (Q - Q_here) / GJ if free[1] and GJ > 0 else tau])
    targets = np.array([N if free[0] else 0.0, Q if free[1] else 0.0], dtype=float)
    scale = np.maximum(np.abs(targets), 1.0)
    mask = np.array(free)

    def residual(y):
        x = x0.copy()
        x[mask] = y
        r = members.resultants(x[0], kappa, x[1])
        return ((np.array([r["N"], r["Q"]], dtype=float) - targets) / scale)[mask]
    sol = root(residual, x0[mask], method="hybr", options={"xtol": 1e-13})
    if np.abs(residual(sol.x)).max() > 1e-9:  # (hybr calls a round-off floor a failure)
        raise SceneError("labtest --fit", f"N = {N}, Q = {Q}",
                         f"the section's state did not converge ({sol.message})")
    x = x0.copy()
    x[mask] = sol.x
    return float(x[0]), float(x[1])


def section_axial(members, tensions) -> dict:
    """Eq. (62) on the section: eps at N = T_e, the twist held (tau = 0: the belt's
    clamp), the apparent EA through the origin."""
    strain = [section_state(members, N=T)[0] for T in tensions]
    return {"tension_N": list(tensions), "strain": strain,
            "apparent_EA_N": slope(strain, tensions)}


def section_torsion(members, tension_N: float, torques, L0: float) -> dict:
    """Eq. (65) on the section from the laid reference at T_e (tau = 0, its torque Q_ref
    held): alpha / L0 = tau under Q_ref + M_t with the dead load N = T_e (the ballast)
    and with the end held at the reference's length; that hold's tension change under
    the torques and at +-50 deg of twist over L0 (+: the lay's hand)."""
    eps0, _ = section_state(members, N=tension_N)
    Q_ref = float(members.resultants(eps0, 0.0, 0.0)["Q"])
    load = [section_state(members, N=tension_N, Q=Q_ref + M)[1] for M in torques]
    held = [section_state(members, eps=eps0, Q=Q_ref + M)[1] for M in torques]
    held_N = [float(members.resultants(eps0, 0.0, t)["N"]) for t in held]
    rise = {sign: float(members.resultants(eps0, 0.0, sign * TWIST_RAD / L0)["N"] - tension_N)
            for sign in (1, -1)}
    return {"tension_N": tension_N, "torque_Nm": list(torques), "reference_torque_Nm": Q_ref,
            "twist_per_length_dead_load": load, "twist_per_length_held": held,
            "apparent_GJ_dead_load_Nm2": slope(load, torques),
            "apparent_GJ_held_Nm2": slope(held, torques),
            "tension_held_N": held_N,
            "tension_change_at_fixed_length_N": {"+50deg": rise[1], "-50deg": rise[-1]}}


def slope(x, y) -> float:
    """The least-squares line through the origin, y = slope x (the lab's formulas have
    no intercept)."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    return float(x @ y / (x @ x))


def section_bending(members, tensions, targets, L0: float) -> dict:
    """The members' EI = dM/d kappa at N = T_e (kappa = 0+), Eq. (63)'s reading of it
    (the tensioned cantilever, extensible kinematics) against Eq. (64), and the radius
    R' = sqrt(2 EI_int / K) at which the same tethers (K = EA - EA_b) would give the
    intrinsic EI that Eq. (64) needs at each T_e."""
    EI, apparent, intrinsic = [], [], []
    K = members.taut_moduli()["EA"] - members.EA_b
    targets = np.asarray(targets, dtype=float)
    for T, target in zip(tensions, targets):
        eps, tau = section_state(members, N=T)
        EI.append(members.tangent(eps, 0.0, tau)["EI"])
        apparent.append(_apparent(EI[-1], T, K + members.EA_b, L0))
        intrinsic.append(_intrinsic(target, T, K + members.EA_b, L0))
    return {"tension_N": list(tensions), "members_EI_Nm2": EI, "apparent_EI_Nm2": apparent,
            "eq64_EI_Nm2": targets.tolist(), "intrinsic_EI_Nm2": intrinsic,
            "relative_error": (np.array(apparent) / targets - 1).tolist(),
            "radius_needed_m": [float(np.sqrt(2 * e / K)) for e in intrinsic]}


def _apparent(EI, T_e, EA, L0):
    T, EI_t = analytic.cantilever_transverse(T_e, EI, EA, "extensible")
    return float(analytic.cantilever_apparent_EI(EI_t, T, L0))


def _intrinsic(apparent, T_e, EA, L0):
    """The intrinsic EI whose extensible tensioned cantilever reads ``apparent``."""
    from scipy.optimize import brentq
    return float(brentq(lambda e: _apparent(e, T_e, EA, L0) - apparent,
                        1e-6 * apparent, 10 * apparent, xtol=1e-12 * apparent))


def fit_tether_EA(members, tensions, EA_target: float):
    """k (one tether's EA) whose section reads EA_target by Eq. (62): a root find from
    the closed form (taut_moduli: EA = n k cos^3 beta + ... + EA_b)."""
    from dataclasses import replace
    from scipy.optimize import brentq

    def misfit(k):
        return section_axial(replace(members, k=k), tensions)["apparent_EA_N"] / EA_target - 1
    k = brentq(misfit, 0.5 * members.k, 2.0 * members.k, xtol=1e-12 * members.k)
    return replace(members, k=float(k))


def fit_lay_angle(members, tensions, EA_target: float, L0: float, torques, hold: str = "held"):
    """beta whose section, with k refitted to Eq. (62) at each beta, reads GJ = 140 N m^2
    at 200 N (Eq. 65; ``hold``: "held" or "dead_load", section_torsion's two end
    conditions): a root find in (0, 45 deg).  None if GJ never reaches it there."""
    from dataclasses import replace
    from scipy.optimize import brentq
    GJ, T = GJ_TARGET

    def fitted(beta):
        m = replace(members, beta=beta)
        k0 = (EA_target - m.EA_b) / m.n / np.cos(beta) ** 3  # the closed form's start
        return fit_tether_EA(replace(m, k=k0), tensions, EA_target)

    def misfit(beta):
        return section_torsion(fitted(beta), T, torques, L0)[f"apparent_GJ_{hold}_Nm2"] / GJ - 1
    lo, hi = 1e-4, np.radians(45.0)
    if misfit(lo) > 0 or misfit(hi) < 0:
        return None
    return fitted(brentq(misfit, lo, hi, xtol=1e-12))


def fit_self_stress(members, tensions, EA_target: float, L0: float, torques,
                    hold: str = "dead_load"):
    """P0 (at the members' beta, bars EA_b > 0) whose section, k refitted to Eq. (62),
    reads GJ = 140 N m^2 at 200 N (``hold`` as :func:`fit_lay_angle`): the tethers'
    tension's geometric part N_t R^2."""
    from dataclasses import replace
    from scipy.optimize import brentq
    GJ, T = GJ_TARGET

    def fitted(P0):
        m = replace(members, P0=P0)
        k0 = ((EA_target - m.EA_b) / m.n - P0 * np.cos(m.beta) * np.sin(m.beta) ** 2) \
            / np.cos(m.beta) ** 3
        return fit_tether_EA(replace(m, k=k0), tensions, EA_target)

    def misfit(P0):
        return section_torsion(fitted(P0), T, torques, L0)[f"apparent_GJ_{hold}_Nm2"] / GJ - 1
    if misfit(0.0) > 0:
        return None
    hi = GJ / members.R**2  # N_t R^2 = GJ with all of it in P0: an upper bound per tether x n
    return fitted(brentq(misfit, 0.0, hi, xtol=1e-10 * hi))


def cone_fit(EA: float, R: float, c: float, tensions, targets, L0: float, loads,
             width: float = 0.0):
    """The fallback (members.py::ConeSection): per T_e the intrinsic EI that Eq. (64)
    needs, its slope dM/d kappa measured on the law at N = T_e (not the input restated:
    it is the law's, at the lab's curvatures), Eq. (63)'s reading of it, the smallest
    Hessian eigenvalue over the lab's states (convexity) and the end load F_N at which
    the wall moment F tanh(lambda L0) / lambda reaches c T_e R (the cone's edge)."""
    from rawehelix.members import ConeSection
    rows = []
    for T, target in zip(tensions, targets):
        EI = _intrinsic(target, T, EA, L0)
        law = ConeSection(EA=EA, EI=EI, R=R, c=c, width=width)
        eps = T / EA
        T_t, EI_t = analytic.cantilever_transverse(T, EI, EA, "extensible")
        lam = np.sqrt(T_t / EI_t)
        arm = np.tanh(lam * L0) / lam  # M(0) = F tanh(lambda L) / lambda
        kappa = max(loads) * arm / EI  # the largest wall curvature of the fit's loads
        slope = float(law.resultants(eps, kappa)["M"] / kappa)
        rows.append({"tension_N": T, "EI_Nm2": EI, "measured_EI_Nm2": slope,
                     "apparent_EI_Nm2": _apparent(slope, T, EA, L0), "eq64_EI_Nm2": float(target),
                     "min_hessian_eigenvalue": _min_hessian(law, eps, kappa),
                     "saturation_load_N": float(c * T * R / arm)})
    error = [r["apparent_EI_Nm2"] / r["eq64_EI_Nm2"] - 1 for r in rows]
    return {"EA_N": EA, "R_m": R, "c": c, "rows": rows, "relative_error": error,
            "within_1_percent": bool(np.all(np.abs(error) <= FIT_TARGET)),
            "convex": bool(all(r["min_hessian_eigenvalue"] >= -1e-9 for r in rows))}


def _min_hessian(law, eps, kappa, points: int = 15) -> float:
    """The smallest eigenvalue of the law's Hessian (central differences of its
    resultants, scaled by diag(1/sqrt(EA), 1/sqrt(EI))) over eps in [-eps, 3 eps],
    kappa in [-3 kappa, 3 kappa] and out to the cone's edge and past it."""
    edge = law.c * law.R * law.EA * eps / law.EI  # EI kappa = c R EA eps
    he, hk = 1e-6 * max(eps, 1e-6), 1e-6 * max(edge, 1e-6)
    scale = np.diag([law.EA ** -0.5, law.EI ** -0.5])
    worst = np.inf
    for e in np.linspace(-eps, 3 * eps, points):
        for k in np.linspace(-3 * max(kappa, edge), 3 * max(kappa, edge), points):
            r = [np.array([law.resultants(*x)[key] for key in "NM"], dtype=float)
                 for x in ((e + he, k), (e - he, k), (e, k + hk), (e, k - hk))]
            H = np.column_stack([(r[0] - r[1]) / (2 * he), (r[2] - r[3]) / (2 * hk)])
            worst = min(worst, np.linalg.eigvalsh(scale @ (H + H.T) / 2 @ scale).min())
    return float(worst)


def section_fit(test: str, members, EA_target: float, L0: float, lab: dict) -> dict:
    """``labtest <test> --fit``'s members block (the module doc's section level):
    axial: k from Eq. (62); torsion: k and beta (and, at the scene's beta, P0 with bars)
    from Eq. (62) and GJ = 140 N m^2 at 200 N; bending: that layout's EI against
    Eq. (64), the radius it would need, the verdict and the fallback cone law.
    ``lab``: the tests' inputs, {"axial": tensions, "torsion": torques, "bending":
    tensions, "bending_loads": F_N, "eq64": Eq. (64) at the bending tensions}."""
    from dataclasses import replace
    axial_T, torques = lab["axial"], lab["torsion"]
    base = fit_tether_EA(members, axial_T, EA_target)
    out = {"level": SECTION_LEVEL, "tethers": members.n, "radius_m": members.R,
           "EA_target_N": EA_target, "axial_tensions_N": list(axial_T),
           "layout": _layout(base)}
    ax = section_axial(base, axial_T)
    out["axial"] = {"tether_EA_N": base.k, "closed_form_EA_N": base.taut_moduli()["EA"],
                    "apparent_EA_N": ax["apparent_EA_N"],
                    "relative_error": ax["apparent_EA_N"] / EA_target - 1}
    if test == "axial":
        return out
    GJ, T = GJ_TARGET
    out["torsion_at_scene_layout"] = section_torsion(base, T, torques, L0)
    lay = fit_lay_angle(base, axial_T, EA_target, L0, torques, "held")
    fits = {"lay_angle_fit_held": lay,
            "lay_angle_fit_dead_load": fit_lay_angle(base, axial_T, EA_target, L0, torques,
                                                     "dead_load"),
            "self_stress_fit_dead_load": fit_self_stress(
                base if base.EA_b > 0 else replace(base, EA_b=EA_target / 2),
                axial_T, EA_target, L0, torques, "dead_load")}
    for key, m in fits.items():
        if m is None:
            out[key] = None
            continue
        tor = section_torsion(m, T, torques, L0)
        hold = key.split("_fit_")[1]
        out[key] = {"layout": _layout(m), **tor,
                    "relative_error": tor[f"apparent_GJ_{hold}_Nm2"] / GJ - 1,
                    "taut_moduli": m.taut_moduli()}
    if test == "torsion":
        return out
    layout = lay or base
    bend = section_bending(layout, lab["bending"], lab["eq64"], L0)
    cone = cone_fit(EA_target, layout.R, layout.saturation, lab["bending"], lab["eq64"], L0,
                    lab["bending_loads"])
    worst = max(abs(e) for e in bend["relative_error"])
    out.update(bending=bend, cone=cone, consistent=bool(worst <= FIT_TARGET),
               verdict=_verdict(layout, bend, worst))
    return out


def _layout(m) -> dict:
    return {"tethers": m.n, "radius_m": m.R, "lay_angle_deg": float(np.degrees(m.beta)),
            "tether_EA_N": m.k, "self_stress_N": m.P0, "bar_EA_N": m.EA_b}


def _verdict(layout, bend, worst) -> str:
    if worst <= FIT_TARGET:
        return "one member layout fits Eq. (62), GJ at 200 N and Eq. (64) within 1 %"
    R_need = bend["radius_needed_m"]
    EA_R2 = layout.taut_moduli()["EA"] * layout.R**2 / 2
    return (f"no member layout fits all three: the tethers' taut EI = K R^2 / 2 <= EA R^2 / 2 "
            f"= {EA_R2:.0f} N m^2 (any n, beta, P0, bars on the axis; "
            f"{max(bend['members_EI_Nm2']):.0f} under the tension) reads {min(bend['relative_error']) * 100:+.0f} % against Eq. (64); it would "
            f"need R = {R_need[0]:.2f}-{R_need[-1]:.2f} m ({R_need[0] / layout.R:.1f}-"
            f"{R_need[-1] / layout.R:.1f} x {layout.R:g} m) and an EI rising with T_e, which "
            f"the members' taut EI does not: the assumption that fails is that the bending "
            f"stiffness is the tethers' axial stiffness at the helix radius")
