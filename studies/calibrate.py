"""`rawehelix calibrate`: scene keys fitted to target quantities by least squares.

    rawehelix calibrate SCENE --fit KEY[,KEY...] --target Q=VALUE[,...]
                        [--bounds KEY=LO:HI] [--uncertainty REL] [-o DIR]

``scipy.optimize.least_squares`` (trust region reflective) on the relative
residuals r_j = Q_j(p) / target_j - 1 of the scaled unknowns x_i = p_i / p0_i
(p0: the scene's values).  The Jacobian is forward differences in x with the
step ``fd_step`` (default 1e-3; backwards at an upper bound); its columns are
independent scenes, evaluated together on the ranks
(:mod:`rawehelix.studies.pool`: dynamic, resumable: every evaluation is
stored in ``DIR/points`` under a hash of its keys, so a rerun, with other
target values too, recomputes none).  Without ``--bounds`` a key stays in
[p0 / 1000, 1000 p0].

The report: ``fitted`` (key -> value), the residuals, the condition number of
the scaled Jacobian E_ji = d ln Q_j / d ln p_i at the fit (large: the targets
do not identify the keys), and the linearised standard uncertainty of the
fitted keys for a relative standard uncertainty u of the targets:
Cov(ln p) = u^2 (E^T E)^-1 (Gauss-Newton, targets independent).

Success is every target met: |r_j| <= ``tolerance`` (default TOLERANCE =
1e-3, relative; ``--tolerance``).  The summary's ``status`` is "targets met"
or "targets missed", ``missed`` names each missed target with its residual,
and ``active_bounds`` the fitted keys that ended on a bound.  Exit status:
0 targets met; 3 (``EXIT_UNMET``, "ran, but did not meet its targets"; the
summary is written); 2 bad input, before any evaluation (an unknown key, a
bound outside the key's allowed range, which the scene loader checks at
both ends of each bound, a negative target of a quantity that cannot be
negative, fewer targets than fitted keys); 1 a scene of the fit failed to solve.
A fit whose scaled Jacobian at the end has a rank below the number of keys (a key
no target sees, or two the targets see alike: :mod:`rawehelix.fits`) is not a
result, whatever its residuals: status "keys not determined", ``undetermined``
says why, exit 3.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rawehelix import fits
from rawehelix.errors import SceneError, SolverError
from rawehelix.studies import pool, quantities
from rawehelix.studies.store import writers
from rawehelix.studies.study import EXIT_UNMET, Source, key_type

FD_STEP = 1e-3  # forward-difference step of the Jacobian, relative to the scene's value
RANGE = 1e3  # default bounds: [p0 / RANGE, RANGE p0], within the key's allowed range
TOLERANCE = 1e-3  # a target is met when |Q / target - 1| <= TOLERANCE
#: units of the quantities that are >= 0 by definition (frequencies, lengths, times)
NON_NEGATIVE_UNITS = {"Hz": "a frequency", "m": "a length", "s": "a time"}


def parse_fit(text: str) -> list[str]:
    keys = [k.strip() for k in str(text).split(",") if k.strip()]
    if not keys or len(set(keys)) != len(keys):
        raise SceneError("--fit", text, "must be KEY[,KEY...], each key once, e.g. helix.EI_Nm2")
    return keys


def parse_targets(text: str) -> dict:
    targets = {}
    for item in str(text).split(","):
        name, sep, value = item.strip().partition("=")
        try:
            v = float(value)
        except ValueError:
            v = math.nan
        if not sep or not math.isfinite(v) or v == 0:
            raise SceneError("--target", item, "must be Q=VALUE with a finite VALUE != 0, e.g. "
                             "lateral_frequency_Hz=5")
        quantity, _ = quantities.parse(name.strip(), "--target")
        if v < 0 and quantity.unit in NON_NEGATIVE_UNITS:
            raise SceneError("--target", item, f"{name.strip()} is "
                             f"{NON_NEGATIVE_UNITS[quantity.unit]} [{quantity.unit}]: "
                             f"its target must be > 0")
        targets[name.strip()] = v
    return targets


def parse_bounds(items: list[str], fit: list[str]) -> dict:
    bounds = {}
    for item in items:
        key, sep, spec = item.partition("=")
        try:
            lo, hi = (float(v) for v in spec.split(":"))
        except ValueError:
            raise SceneError("--bounds", item, "must be KEY=LO:HI") from None
        if key not in fit:
            raise SceneError("--bounds", item, f"{key} is not one of --fit {','.join(fit)}")
        if not lo < hi:
            raise SceneError("--bounds", item, "needs LO < HI")
        bounds[key] = (lo, hi)
    return bounds


@dataclass
class CalibrationResult:
    scene: str
    summary: dict

    @property
    def exit_status(self) -> int:
        """0: every target met by determined keys; EXIT_UNMET: ran, but missed a target
        or could not determine the keys."""
        return 0 if self.summary["success"] else EXIT_UNMET

    def write(self, outdir) -> Path:
        outdir = Path(outdir)
        writers.write_json(outdir / "summary.json", self.summary)
        return outdir


class _Evaluator:
    """Residuals of batches of x, the batch's scenes evaluated together on the ranks."""

    def __init__(self, source, fit, p0, targets, store, comm, log):
        self.source, self.fit, self.p0, self.targets = source, fit, p0, targets
        self.store, self.comm, self.log = store, comm, log
        self.wanted = list(targets)
        self.seen: dict = {}  # id -> record
        self.evaluations = 0

    def overrides(self, x) -> dict:
        return {k: float(p * xi) for k, p, xi in zip(self.fit, self.p0, x)}

    @staticmethod
    def task_id(over: dict) -> str:
        return "e" + writers.digest({k: repr(v) for k, v in over.items()})

    def batch(self, xs) -> list[np.ndarray]:
        tasks = []
        for x in xs:
            over = self.overrides(x)
            self.source.load(over)  # a bad value: the scene loader's message
            tasks.append(pool.Task(self.task_id(over), over, "calibrate"))
        new = list({t.id: t for t in tasks if t.id not in self.seen}.values())
        if new:
            out = pool.run(new, self.source.load, self.wanted, self.store, self.comm, self.log)
            self.seen.update(out["records"])
            self.evaluations += out["computed"]
        rows = []
        for t in tasks:
            r = self.seen[t.id]
            if r["status"] != "ok":
                raise SolverError(f"calibrate: the scene at {t.overrides} failed: "
                                  + "; ".join(r["errors"].values()))
            rows.append(np.array([r["values"][q] / self.targets[q] - 1 for q in self.wanted]))
        return rows

    def fun(self, x):
        return self.batch([x])[0]

    def jac(self, x, lower, upper, step):
        """Forward differences in x (backwards where a step would leave the bounds)."""
        h = np.where(x + step <= upper, step, -step)
        cols = [x + h[i] * np.eye(len(x))[i] for i in range(len(x))]
        r0, *rs = self.batch([x, *cols])
        return np.column_stack([(r - r0) / h[i] for i, r in enumerate(rs)])


def _refusal(source: Source, key: str, value: float) -> str | None:
    """None if the scene loader takes ``value`` for ``key``, else what it allows."""
    try:
        source.load({key: float(value)})
    except SceneError as err:
        return err.allowed
    return None


def check_bounds(source: Source, bounds: dict):
    """Both ends of each bound within the key's allowed range (the scene
    validation of parameters.py, through the loader), before any evaluation."""
    for key, (lo, hi) in bounds.items():
        for end, value in (("LO", lo), ("HI", hi)):
            why = _refusal(source, key, value)
            if why is not None:
                raise SceneError("--bounds", f"{key}={lo:g}:{hi:g}",
                                 f"{end} is outside the key's allowed range ({why})")


def default_bounds(source: Source, key: str, p0: float) -> tuple[float, float]:
    """[p0 / RANGE, RANGE p0] (ordered), each end that the loader refuses moved
    towards p0 (geometric bisection, 50 halvings) to the last value it takes."""
    ends = []
    for end in sorted((p0 / RANGE, p0 * RANGE)):
        if _refusal(source, key, end) is not None:
            good, bad = 0.0, 1.0  # exponents t of p0 (end / p0)^t
            for _ in range(50):
                mid = 0.5 * (good + bad)
                good, bad = (mid, bad) if _refusal(source, key, p0 * (end / p0) ** mid) is None \
                    else (good, mid)
            end = p0 * (end / p0) ** good
        ends.append(float(end))
    return ends[0], ends[1]


def active_bounds(x, lower, upper, fit) -> dict:
    """The fitted keys that ended on a bound (within 1e-6 of the scaled range)."""
    out = {}
    for k, xi, lo, hi in zip(fit, x, lower, upper):
        gap = 1e-6 * (hi - lo)
        if xi <= lo + gap:
            out[k] = "lower"
        elif xi >= hi - gap:
            out[k] = "upper"
    return out


def compute(source: Source, fit: list[str], targets: dict, outdir, bounds: dict | None = None,
            uncertainty: float = 0.01, fd_step: float | None = None, comm=MPI.COMM_WORLD,
            log=None, tolerance: float | None = None) -> CalibrationResult:
    """Fit ``fit`` to ``targets`` (collective; the result on every rank);
    ``fd_step`` None is FD_STEP, ``tolerance`` None is TOLERANCE.  Bad input
    (SceneError) is refused before any evaluation."""
    from scipy.optimize import least_squares

    from rawehelix.studies import resources

    start = time.perf_counter()
    fd_step = FD_STEP if fd_step is None else fd_step
    tolerance = TOLERANCE if tolerance is None else tolerance
    bounds = bounds or {}
    if not 0 < fd_step < 0.5:
        raise SceneError("--fd-step", fd_step, "must be in (0, 0.5)")
    if not uncertainty > 0:
        raise SceneError("--uncertainty", uncertainty, "must be > 0")
    if not (0 < tolerance < 1 and math.isfinite(tolerance)):
        raise SceneError("--tolerance", tolerance, "must be a relative tolerance in (0, 1)")
    if len(targets) < len(fit):  # each target one equation: known before any work
        raise SceneError("--fit", ",".join(fit),
                         f"{len(fit)} keys cannot be determined by {len(targets)} "
                         f"target{'s' * (len(targets) != 1)}: give at least as many --target "
                         "quantities as --fit keys")
    params = source.load()
    resources.check_quantities(params, list(targets), copies=comm.size)
    p0 = []
    for key in fit:
        try:
            value = params.value(key)
        except AttributeError:  # an unknown key: the loader's message
            source.load({key: 1.0})
            raise SceneError("--fit", key, "is not a scene key") from None
        if key_type(key) != "float":
            raise SceneError("--fit", key, "must be a real-valued key (a number); it is "
                             f"{key_type(key)}")
        if value is None:  # an optional key the scene leaves absent
            raise SceneError("--fit", key, "is not set by the scene (absent): the fit starts "
                             f"from the scene's value, so set one, e.g. --set {key}=VALUE")
        if value == 0:
            raise SceneError("--fit", key, "must have a scene value != 0 (the unknowns are "
                             "scaled by it); it is 0")
        p0.append(float(value))
    p0 = np.array(p0)
    check_bounds(source, bounds)
    ranges = [bounds[k] if k in bounds else default_bounds(source, k, p)
              for k, p in zip(fit, p0)]
    lo, hi = np.array([r[0] for r in ranges]), np.array([r[1] for r in ranges])
    lower, upper = np.minimum(lo / p0, hi / p0), np.maximum(lo / p0, hi / p0)
    x0 = np.clip(np.ones(len(fit)), lower + 1e-12, upper - 1e-12)
    disc = params.discretisation
    header = {"scene": params.name, "fingerprint": writers.digest(params.as_dict()),
              "scheme": disc.scheme, "elements": disc.elements, "degree": disc.degree,
              "calibrate": fit, "quantities": sorted(targets)}
    store = pool.Store(outdir, header).open(comm)
    ev = _Evaluator(source, fit, p0, {q: targets[q] for q in sorted(targets)}, store, comm, log)
    res = least_squares(ev.fun, x0, jac=lambda x: ev.jac(x, lower, upper, fd_step),
                        bounds=(lower, upper), method="trf", xtol=1e-10, ftol=1e-10,
                        gtol=1e-10, max_nfev=100)
    r = ev.fun(res.x)
    J = ev.jac(res.x, lower, upper, fd_step)
    E = J * res.x[None, :] / (1 + r)[:, None]  # d ln Q_j / d ln p_i
    sv = np.linalg.svd(E, compute_uv=False)
    undetermined = fits.undetermined(E, len(fit), rtol=fits.DIFFERENCES_RTOL)
    cond = float(sv[0] / sv[-1]) if not undetermined else math.inf
    fitted = {k: float(p * x) for k, p, x in zip(fit, p0, res.x)}
    if math.isfinite(cond):
        cov_ln = uncertainty**2 * np.linalg.inv(E.T @ E)
        rel = np.sqrt(np.diag(cov_ln))
        confidence = {k: {"std": float(fitted[k] * s), "relative_std": float(s)}
                      for k, s in zip(fit, rel)}
    else:
        confidence = {k: None for k in fit}
    values = {q: float(targets[q] * (1 + rj)) for q, rj in zip(ev.wanted, r)}
    residuals = {q: {"absolute": values[q] - targets[q], "relative": float(rj)}
                 for q, rj in zip(ev.wanted, r)}
    missed = {q: rr for q, rr in residuals.items() if not abs(rr["relative"]) <= tolerance}
    active = active_bounds(res.x, lower, upper, fit)
    summary = {**header, "targets": targets, "start": dict(zip(fit, p0.tolist())),
               "bounds": {k: [float(a), float(b)] for k, a, b in zip(fit, lo, hi)},
               "fitted": fitted, "values": values, "residuals": residuals,
               "tolerance": tolerance,
               "tolerance_meaning": "a target is met when |Q / target - 1| <= tolerance",
               "status": ("keys not determined" if undetermined else
                          "targets missed" if missed else "targets met"),
               "missed": missed, "active_bounds": active,
               "undetermined": (f"d ln Q / d ln p, {undetermined}" if undetermined
                                else None),
               "scaled_jacobian": E.tolist(),
               "scaled_jacobian_meaning": "d ln Q_j / d ln p_i (rows: quantities, columns: "
                                          "fitted keys), forward differences",
               "condition_number": cond,
               "target_uncertainty": uncertainty, "confidence": confidence,
               "confidence_meaning": "linearised 1-sigma: Cov(ln p) = u^2 (E^T E)^-1",
               "fd_step": fd_step, "success": not missed and not undetermined,
               "optimizer_success": bool(res.success), "message": res.message,
               "nfev": int(res.nfev), "njev": int(res.njev or 0),
               "evaluations_now": ev.evaluations, "ranks": comm.size,
               "wall_s": time.perf_counter() - start}
    return CalibrationResult(params.name, summary)


def _fitted_line(key: str, value: float, confidence, uncertainty: float) -> str:
    if not confidence:
        return f"  fitted {key} = {value:.6g} (not identified)"
    return (f"  fitted {key} = {value:.6g} +- {confidence['std']:.4g} "
            f"({100 * confidence['relative_std']:.2g} %, targets +- {100 * uncertainty:g} %)")


def report(result: CalibrationResult) -> str:
    s = result.summary
    head = (f"{s['scene']}: {s['message']} ({s['nfev']} residuals, {s['njev']} Jacobians, "
            f"{s['evaluations_now']} scenes computed now on {s['ranks']} rank(s), "
            f"{s['wall_s']:.1f} s)")
    lines = [head] + [_fitted_line(k, v, s["confidence"][k], s["target_uncertainty"])
                      for k, v in s["fitted"].items()]
    for q, rr in s["residuals"].items():
        lines.append(f"  {q} = {s['values'][q]:.6g} (target {s['targets'][q]:g}, "
                     f"relative residual {rr['relative']:+.2e})")
    lines.append(f"  condition number of the scaled Jacobian: {s['condition_number']:.3g}")
    for q, rr in s["missed"].items():
        lines.append(f"  missed: {q} is {rr['relative']:+.3g} relative ({rr['absolute']:+.4g}) "
                     f"from its target, past the tolerance {s['tolerance']:g}")
    for k, side in s["active_bounds"].items():
        lo, hi = s["bounds"][k]
        lines.append(f"  bound active: {k} = {s['fitted'][k]:.6g} ended on the {side} end of "
                     f"the scaled range, bounds [{lo:g}, {hi:g}]")
    if s.get("undetermined"):
        lines.append(f"  not determined: {s['undetermined']}: the targets cannot fix "
                     f"{', '.join(s['fitted'])}; fit fewer keys or add targets that see them")
    lines.append(f"  status: {s['status']}" + (f" (exit status {EXIT_UNMET})"
                                                if not s["success"]
                                                else f" within {s['tolerance']:g}"))
    return "\n".join(lines)
