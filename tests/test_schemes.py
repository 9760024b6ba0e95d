"""The scheme registry owns every decision made by the scheme's name (issue 42): its
core below the solvers (parameters/schemes.py) and the studies' registry that extends
it (studies/schemes.py) agree, and each decision the solvers and studies used to make
by testing the name gives what it gave."""

from __future__ import annotations

import pytest

from rawehelix.parameters import SCHEMES, ParameterError
from rawehelix.parameters import schemes as cores
from rawehelix.solvers import stepsize
from rawehelix.studies import limits, resources, response, scene, schemes, stationary

N = 6


def load(scheme, **kw):
    return scene.load("mobile_end", scheme=scheme, elements=kw.pop("elements", N), **kw)


def test_each_scheme_extends_its_core():
    assert tuple(schemes.SCHEME_REGISTRY) == tuple(cores.CORES) == SCHEMES
    for name, scheme in schemes.SCHEME_REGISTRY.items():
        core = cores.CORES[name]
        assert isinstance(scheme, type(core)) and isinstance(scheme, schemes.Scheme)
        for attr in ("name", "has_degree", "fixed_time_step", "fe_assembled", "integrator",
                     "harmonic_balance_refusal"):
            assert getattr(scheme, attr) == getattr(core, attr), (name, attr)


@pytest.mark.parametrize("get", [cores.get, schemes.get])
def test_an_unknown_scheme_is_refused_once_with_the_names(get):
    with pytest.raises(ParameterError) as err:
        get("no_such_scheme")
    assert "'no_such_scheme'" in str(err.value) and str(SCHEMES) in str(err.value)


def test_the_memory_estimate_is_the_schemes():
    """The FE: the heaviest step's bytes per unknown; the spline: its dense N^2 (the
    formulas resources.py had by name)."""
    fe, spline = load("fe"), load("spline")
    n = 4 * (fe.discretisation.degree * N + 1)  # (r, alpha), ip bending, no hysteresis
    assert resources.unknowns(fe) == n
    assert resources.estimate_bytes(fe, "modes") == resources.BASE_BYTES + 22e3 * n
    assert resources.estimate_bytes(fe, "sweep") == resources.BASE_BYTES + 1.5e3 * n
    assert resources.estimate_bytes(spline, "modes") == resources.BASE_BYTES + 4.5e3 * N**2
    assert "dense matrices" in schemes.of(spline).memory_bytes(spline, "modes")[1]
    assert f"{n} unknowns" in schemes.of(fe).memory_bytes(fe, "modes")[1]


def test_the_orbit_size_is_the_schemes():
    from rawehelix.solvers.harmonic_balance.scope import H_START
    fe, spline = load("fe"), load("spline")
    n = resources.unknowns(fe)
    assert resources.orbit_size(fe, "shooting") == 3 * n
    assert resources.orbit_size(fe, "hb") == (2 * H_START + 1) * n
    for method in ("shooting", "hb"):  # the spline reference shoots, whatever is asked
        assert resources.orbit_size(spline, method) == 8 * N


def test_harmonic_balance_refuses_the_spline_scheme_by_its_reason():
    from rawehelix.solvers.harmonic_balance import scope
    assert scope.cannot(load("spline")) == cores.SplineCore.harmonic_balance_refusal
    assert scope.cannot(load("fe")) != cores.SplineCore.harmonic_balance_refusal


def test_the_step_size_rule_is_the_fixed_step_schemes():
    """A dt far too long is refused for the FE (fixed steps) and not checked for the
    spline (Radau's adaptive steps)."""
    long = {"time.dt_s": 0.5}
    with pytest.raises(scene.SceneError, match="time.dt_s"):
        stepsize.check(load("fe", overrides=long))
    assert stepsize.check(load("spline", overrides=long)) is None


def test_the_ip_limit_is_the_fe_assembled_schemes():
    """Past the IP form's limit the FE scheme is refused, the spline (no IP form) not."""
    far = {"discretisation.bending": "ip"}
    fe = load("fe", elements=5000, overrides=far)
    with pytest.raises(scene.SceneError, match="discretisation.elements"):
        limits.check_bending_resolution(fe, "modes")
    limits.check_bending_resolution(load("spline", elements=5000, overrides=far), "modes")


@pytest.mark.parametrize("check", [stationary.compute, response.check])
def test_the_fe_only_commands_refuse_the_spline_scheme(check):
    with pytest.raises(scene.SceneError, match="discretisation.scheme"):
        check(load("spline"))


def test_the_fe_solvers_refuse_a_scheme_they_do_not_assemble():
    from rawehelix.solvers.discrete import RodDiscretisation
    with pytest.raises(ValueError, match="this solver is the FE scheme"):
        RodDiscretisation(load("spline"))
