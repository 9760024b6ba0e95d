"""The paper's spline-Galerkin scheme at N = 8 against the FE modal results,
and the independence of the references from the FE path.

The spline scheme drops the Frenet torsion gamma (as the paper's code does), so
the FE side runs with ``model.gamma = "off"``; both linearise about their own
stationary state and classify the modes in the same frame (the local tangent
of the stationary centre line)."""

import subprocess
import sys

import numpy as np
import pytest
from mpi4py import MPI

from rawehelix.families import VIBRATIONS
from rawehelix.studies import modes, scene


def lowest(result, family, count=2):
    lam = sorted((m.eigenvalue for m in result if m.family == family), key=abs)
    return np.array(lam[:count])


@pytest.fixture(scope="module")
def spectra():
    params = scene.load("stationary_table2").replace(model={"gamma": "off"})
    spline = modes.compute(params.replace(discretisation={"scheme": "spline", "elements": 8}))
    fe = modes.compute(params.replace(discretisation={"elements": 16, "degree": 3}),
                       comm=MPI.COMM_SELF)
    return spline, fe


@pytest.mark.parametrize("family", VIBRATIONS)
def test_spline_n8_matches_fe(spectra, family):
    """First two modes of each family: |lambda| within 1e-3 (2.6e-4 observed)
    and the damping Re lambda within 1e-6 (1e-8 observed; the torsional modes
    are undamped in both: |Re lambda| < 1e-12)."""
    spline, fe = spectra
    a, b = lowest(spline, family), lowest(fe, family)
    assert len(a) == len(b) == 2, (a, b)
    assert np.allclose(np.abs(a), np.abs(b), rtol=1e-3), (family, a, b)
    assert np.allclose(a.real, b.real, rtol=1e-6, atol=1e-10 * np.abs(b).max()), \
        (family, a.real, b.real)


#: the FE path: what the references must not import
FE_MODULES = ("dolfinx", "ufl", "basix", "ffcx", "petsc4py", "slepc4py", "rawehelix.forms",
              "rawehelix.compat", "rawehelix.meshes")
REFERENCES = ("rawehelix.references.shooting", "rawehelix.references.spline_galerkin")
# scheme-independent numpy code the references may use: the shooting Newton and
# the Floquet multipliers of a period map, the periodic-orbit problem (no FE module)
SHARED = ("rawehelix.periodic_orbits.floquet", "rawehelix.periodic_orbits.problem",
          # the harmonic-balance room's decisions from the parameters alone (where it runs,
          # the guarded stability step's rules): numpy, read by the orbit-method registry
          # that `import rawehelix` loads; no FE code (they import parameters/ only)
          "rawehelix.solvers.harmonic_balance.scope",
          "rawehelix.solvers.harmonic_balance.stability")
#: packages whose __init__ alone (it imports nothing) the shared modules load
SHARED_PACKAGES = ("rawehelix.solvers.harmonic_balance",)

_PROBE = """
import importlib, pkgutil, sys
for name in {blocked!r}:
    sys.modules[name] = None  # importing it raises ImportError
import rawehelix.references.spline_galerkin as sg
for info in pkgutil.iter_modules(sg.__path__):
    importlib.import_module(sg.__name__ + "." + info.name)
import rawehelix.references.shooting
from rawehelix.references.spline_galerkin import spectrum, stationary
from rawehelix.references.spline_galerkin.system import SplineGalerkin
from rawehelix.studies import scene
nd = scene.load("stationary_table2").normalised()
rawehelix.references.shooting.solve(nd)
system = SplineGalerkin(nd, 2)
assert spectrum.modes(system, stationary.solve(system).x)
print(" ".join(sorted(m for m, v in sys.modules.items() if v is not None)))
"""


def test_references_share_no_code_with_the_fe_path():
    """The shooting and spline references import and run with dolfinx, ufl and
    PETSc blocked, and load no FE module of rawehelix (forms, the FE solvers)."""
    out = subprocess.run([sys.executable, "-c", _PROBE.format(blocked=list(FE_MODULES[:6]))],
                         capture_output=True, text=True, check=True).stdout.split()
    own = [m for m in out if m.startswith("rawehelix.")]
    assert any(m.startswith(REFERENCES[1]) for m in own)
    fe = [m for m in own if m.startswith(FE_MODULES[6:])
          or (m.startswith("rawehelix.solvers.") and not m.startswith(REFERENCES + SHARED)
              and m not in SHARED_PACKAGES)]
    assert fe == [], fe
    assert not [m for m in out if m.split(".")[0] in FE_MODULES[:6]]
