"""Natural modes of the stationary state (Sec. 5.1, Table 3): the public API.

:func:`compute` solves the stationary state, linearises about it and returns
a :class:`ModesResult` for either scheme:

* ``fe``: SLEPc on the linearised Eqs. (30)-(31) (:mod:`rawehelix.solvers.modal`),
  with the mode shapes;
* ``spline``: the paper's spline-Galerkin reference (eigenvalues of the
  Jacobian of Eq. 61, :mod:`rawehelix.references.spline_galerkin.spectrum`),
  without mode shapes (``s_m``, ``displacement`` and ``alpha_rad`` are None).

Computing never writes files; :meth:`ModesResult.write` does.  ``rawehelix
modes`` is :func:`run`: compute, print the table (:func:`format_table`), write.

Selection: by default the lowest PER_FAMILY oscillating modes of each
family, the rigid rotation (the FE scheme reports it once; the spline
reference every zero eigenvalue, as Table 3 does) and the OVERDAMPED_SHOWN
slowest ``overdamped`` eigenvalues found (real roots of a damped spectrum: a
decay rate, no frequency, no family's mode); with ``count = k`` the k slowest
(|lambda|) modes.  Either way in ascending frequency |Im lambda| (then
|lambda|), the overdamped ones last by decay rate: the order of the table
``rawehelix modes`` prints.  (Table 3 of the paper lists them the other way
round; studies/present/report.py pairs rows by family.)
"""

from __future__ import annotations

import math
import pathlib
import time
from dataclasses import dataclass, field

import numpy as np

from rawehelix.families import FAMILY_LABELS, OVERDAMPED, VIBRATIONS
from rawehelix.parameters import Parameters
from rawehelix.studies import limits, schemes

PER_FAMILY = 3  # modes of each family in the default selection
OVERDAMPED_SHOWN = 2 * PER_FAMILY  # real roots in it: both of PER_FAMILY overdamped pairs
ZERO_TOL = 1e-4  # |Im lambda| (normalised) below which a mode has no period


@dataclass
class ModeResult:
    """One mode (an eigenvalue with Im >= 0 stands for its conjugate pair), in SI.

    The shape is the real part of the eigenvector turned to make its largest
    entry real, scaled so that max(max |displacement| [m], max |alpha| [rad])
    = 1: the ratio of displacement to twist is the physical one."""

    family: str  # one of rawehelix.families.FAMILIES
    eigenvalue: complex  # normalised (1 / t_scale), Eq. (25)
    frequency_Hz: float  # |Im lambda| / (2 pi t_scale)
    decay_per_s: float  # -Re lambda / t_scale (> 0: damped)
    period_s: float | None  # 1 / frequency_Hz; None for the rigid rotation and overdamped
    dominant: list  # dominant components of the eigenvector
    fractions: dict = field(default_factory=dict)  # kinetic-energy fraction per family
    s_m: np.ndarray | None = field(default=None, repr=False)  # arc length of the nodes [m]
    displacement: np.ndarray | None = field(default=None, repr=False)  # (n, 3) [m]
    alpha_rad: np.ndarray | None = field(default=None, repr=False)  # (n,) twist [rad]

    @classmethod
    def of(cls, eigenvalue: complex, family: str, dominant, fractions, q, shape=None):
        """From a normalised eigenvalue; ``shape`` = (s, u (n, 3), alpha) normalised."""
        lam = complex(eigenvalue)
        frequency = abs(lam.imag) / (2 * math.pi * q.t_scale)
        oscillatory = family not in ("rigid", OVERDAMPED) and abs(lam.imag) > ZERO_TOL
        mode = cls(family=family, eigenvalue=lam, frequency_Hz=frequency,
                   decay_per_s=-lam.real / q.t_scale,
                   period_s=1.0 / frequency if oscillatory else None, dominant=list(dominant),
                   fractions={k: float(v) for k, v in fractions.items()})
        if shape is not None:
            s, u, alpha = shape
            u_m = q.length_m(u)
            scale = max(np.linalg.norm(u_m, axis=1).max(), np.abs(alpha).max()) or 1.0
            mode.s_m, mode.displacement, mode.alpha_rad = q.length_m(s), u_m / scale, alpha / scale
        return mode

    @property
    def eigenvalue_per_s(self) -> complex:
        return complex(-self.decay_per_s, math.copysign(2 * math.pi * self.frequency_Hz,
                                                        self.eigenvalue.imag))

    def entry(self) -> dict:
        """The summary.json entry of the mode."""
        lam, lam_s = self.eigenvalue, self.eigenvalue_per_s
        return {"family": self.family, "eigenvalue": [lam.real, lam.imag],
                "eigenvalue_per_s": [lam_s.real, lam_s.imag], "frequency_Hz": self.frequency_Hz,
                "decay_per_s": self.decay_per_s, "period_s": self.period_s,
                "dominant": list(self.dominant)}


class ModesResult(list):
    """The selected :class:`ModeResult` objects in ascending frequency, with what
    describes the run (``info``) and the stationary centre line ``x0_m`` (n, 3)
    [m, FE only] about which they were computed."""

    def __init__(self, modes, info: dict, x0_m=None, radius_m: float = 0.0):
        super().__init__(modes)
        self.info, self.x0_m, self.radius_m = info, x0_m, radius_m
        self.rank = 0  # write() writes on rank 0 only

    @property
    def summary(self) -> dict:
        """Exactly what :meth:`write` puts into summary.json."""
        return {**self.info, "modes": [m.entry() for m in self],
                # per mode (same order); the twist with beta/delta (Eq. 27)
                "kinetic_energy_fractions": [dict(m.fractions) for m in self]}

    def firsts(self) -> dict:
        """The slowest selected mode of each vibrating family that has a shape."""
        out = {}
        for m in sorted(self, key=lambda m: abs(m.eigenvalue)):
            if m.family != "rigid" and m.displacement is not None:
                out.setdefault(m.family, m)
        return {f: out[f] for f in VIBRATIONS if f in out}

    def write(self, outdir) -> list[pathlib.Path]:
        """summary.json (atomic), and with mode shapes modes.png, modes.xdmf
        and, where pyvista works, one animated GIF per family's first mode.
        Returns the paths written."""
        from rawehelix.studies.store import writers
        outdir = pathlib.Path(outdir)
        if self.rank != 0:
            return []
        outdir.mkdir(parents=True, exist_ok=True)
        paths = [writers.write_json(outdir / "summary.json", self.summary)]
        firsts = self.firsts()
        if firsts:
            paths += self._write_shapes(outdir, firsts)
        return paths

    def _write_shapes(self, outdir: pathlib.Path, firsts: dict) -> list[pathlib.Path]:
        from rawehelix.studies.store import writers
        x0 = self.x0_m
        L0 = float(np.max(next(iter(firsts.values())).s_m))
        chord = x0[-1] / np.linalg.norm(x0[-1])
        normal = np.cross([0.0, 1.0, 0.0], chord)
        panels, point_data = {}, {"s_m": next(iter(firsts.values())).s_m}
        for f, m in firsts.items():
            u, alpha = m.displacement, m.alpha_rad
            u_max = np.linalg.norm(u, axis=1).max() or 1.0
            a_max = np.abs(alpha).max() or 1.0
            # a part below 1e-4 of the other one (normalised units: u / L0) is
            # round-off or a weak slaved response: drawn as zero, not blown up to 1
            u_scale = u_max if u_max / L0 >= 1e-4 * a_max else math.inf
            a_scale = a_max if a_max >= 1e-4 * u_max / L0 else math.inf
            label = (f"{FAMILY_LABELS[f]}: {m.frequency_Hz:.2f} Hz, decay "
                     f"{m.decay_per_s:.2f} 1/s\nmax|alpha| / max|displacement| = "
                     f"{a_max / u_max:.2g} rad/m")
            panels[label] = (u @ chord / u_scale, u @ normal / u_scale, u[:, 1] / u_scale,
                             alpha / a_scale)
            point_data[f"{f}_displacement"] = u
            point_data[f"{f}_alpha"] = alpha
        info = self.info
        paths = [
            writers.mode_shapes_png(outdir / "modes.png", point_data["s_m"], panels,
                                    f"First modes of each family, FE N = {info['elements']}, "
                                    f"p = {info['degree']} (displacement and twist each "
                                    f"scaled to 1)"),
            writers.centre_line_xdmf(outdir / "modes.xdmf", x0, point_data)]
        from rawehelix.studies.present import render
        if render.available():
            for f, m in firsts.items():
                path = render.mode_animation(
                    outdir / f"mode_{f}.gif", m.s_m, x0, m.displacement, m.alpha_rad,
                    self.radius_m, f"{FAMILY_LABELS[f]}, {m.frequency_Hz:.2f} Hz")
                if path is not None:
                    paths.append(pathlib.Path(path))
        return paths


def ascending(modes: list) -> list:
    """Ascending frequency |Im lambda|, then |lambda| (the rigid rotation
    first); the overdamped ones (no frequency) last, by decay rate."""
    return sorted(modes, key=lambda m: (m.family == OVERDAMPED, abs(m.eigenvalue.imag),
                                        abs(m.eigenvalue)))


def select(modes: list, count: int | None) -> list:
    """The lowest PER_FAMILY oscillating modes of each family, the rigid ones
    and the OVERDAMPED_SHOWN slowest overdamped ones (count None), or the
    ``count`` slowest (|lambda|); in :func:`ascending` order."""
    if count is None:
        keep = [m for m in modes if m.family == "rigid"]
        for f in VIBRATIONS:
            keep += ascending(m for m in modes if m.family == f)[:PER_FAMILY]
        keep += ascending(m for m in modes if m.family == OVERDAMPED)[:OVERDAMPED_SHOWN]
    else:
        keep = sorted(modes, key=lambda m: abs(m.eigenvalue))[:count]
    return ascending(keep)


def _missing(modes: list, families) -> dict:
    found = {f: sum(m.family == f for m in modes) for f in families}
    return {f: k for f, k in found.items() if k < PER_FAMILY}


def check_count(count):
    from rawehelix.studies.scene import SceneError
    if count is not None and (isinstance(count, bool) or not isinstance(count, (int, np.integer))
                              or count < 1):
        raise SceneError("modes", "count", "must be an integer >= 1")


def compute(params: Parameters, count: int | None = None, comm=None,
            scene: str | None = None) -> ModesResult:
    """Modes of the stationary state for ``params.discretisation.scheme``
    (:mod:`rawehelix.studies.schemes`).

    Parameters
    ----------
    params : the scene (scheme ``fe`` or ``spline``).
    count : the ``count`` slowest modes; None: the lowest 3 of each family
        and the rigid rotation.
    comm : MPI communicator of the FE scheme (COMM_WORLD by default).
    scene : name used in error messages (default: the scene's name).

    Raises SceneError for a bad count, SolverError if a solve fails.
    """
    check_count(count)
    limits.check_bending_resolution(params, "modes")
    start = time.perf_counter()
    q = params.normalised()
    disc = params.discretisation
    nev = None if count is None else 2 * count + 4  # both of each pair, the rigid one
    spectrum = schemes.of(params).spectrum(params, comm, scene or params.name, nev)
    chosen = select(spectrum.modes, count)
    shapes = spectrum.shapes(chosen)  # collective (FE)
    x0 = spectrum.centre_line()  # collective (FE)
    result = None
    if spectrum.comm is None or spectrum.comm.rank == 0:
        missing = _missing(spectrum.modes, VIBRATIONS) if spectrum.missing is None \
            else spectrum.missing
        info = {"scene": params.name, "scheme": disc.scheme, "elements": disc.elements,
                **spectrum.info, "missing_families": missing if count is None else {},
                "wall_s": time.perf_counter() - start}
        result = ModesResult([ModeResult.of(m.eigenvalue, m.family, m.dominant, m.fractions, q,
                                            shape) for m, shape in zip(chosen, shapes)],
                             info, x0_m=None if x0 is None else q.length_m(x0),
                             radius_m=params.helix.radius_m)
    if spectrum.comm is not None:
        result = spectrum.comm.bcast(result, root=0)
        result.rank = spectrum.comm.rank
    return result


#: the eigenvalue column's header: lambda [1/s] times the time scale sqrt(L0/g) of Eq. (25)
EIGENVALUE_HEADER = "Eigenvalue x sqrt(L0/g)"


def format_table(result) -> str:
    """Table 3 layout: eigenvalue (normalised, its header says how), dominant
    components, mode, period and frequency (SI)."""
    head = (f"{EIGENVALUE_HEADER:>24}  {'Dominant components':<34} {'Mode':<15} {'Period (s)':>10} "
            f"{'f (Hz)':>9} {'Decay (1/s)':>11}")
    lines = [head, "-" * len(head)]
    for m in result:
        re, im = (round(v, 2) + 0.0 for v in (m.eigenvalue.real, m.eigenvalue.imag))  # no "-0.00"
        ev = f"{re:.2f} {'±' if im else '+'} {abs(im):.2f}i"
        dom = ", ".join(m.dominant)  # state names as in Table 3: xdot_1, alphadot_0
        if len(dom) > 34:
            dom = dom[:31] + "..."
        period = "N/A" if m.period_s is None else f"{m.period_s:.3f}"
        frequency = "-" if m.family == OVERDAMPED else f"{m.frequency_Hz:.3f}"
        lines.append(f"{ev:>24}  {dom:<34} {FAMILY_LABELS.get(m.family, m.family):<15} "
                     f"{period:>10} {frequency:>9} {round(m.decay_per_s, 3) + 0.0:>11.3f}")
    return "\n".join(lines)


def report(result: ModesResult) -> str:
    """What ``rawehelix modes`` prints: a header, the table, and a note on
    any family with fewer modes than asked for."""
    info = result.info
    scheme = schemes.get(info["scheme"])
    lines = [f"Modes of the stationary state, scheme {info['scheme']}, {scheme.size_label(info)}"
             f"{info['wall_s']:.2f} s), ascending frequency", format_table(result)]
    if any(m.family == OVERDAMPED for m in result):
        lines.append("note: 'Overdamped' rows are real eigenvalues (one root each of an "
                     "overdamped pair): a decay without oscillation, no period, in no family")
    if info["missing_families"]:
        lines.append(f"note: fewer than {PER_FAMILY} oscillating modes found for "
                     f"{info['missing_families']}: try more elements (--elements)"
                     + (" or -rawehelix_pep_nev; a family may have no more oscillating modes "
                        "(overdamped)" if scheme.fe_assembled else ""))  # SLEPc's option
    return "\n".join(lines)


__all__ = ["ModeResult", "ModesResult", "ascending", "compute", "format_table", "report",
           "select"]
