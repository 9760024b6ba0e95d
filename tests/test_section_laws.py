"""The section laws' registry (section_laws.py, issue 42): one object per law owns every
decision made by the law's name, and the law's maths is written once (section_math.py)
for the FE rod's UFL and the numpy of the limits.

* nothing in the product outside parameters/ chooses a section law by its name
  (a survivor carries the comment :data:`JUSTIFIED`, which says why);
* the registry refuses an unknown name once, with the list the scene's check gives;
* the solid is a complete null object: it answers every question the product asks of
  a scene's section component;
* the law written once (section_math.py) is members.py's docstring's in numpy.
(The UFL halves against numpy: tests/test_section_law.py.)
"""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import numpy as np
import pytest

from rawehelix import section_laws
from rawehelix.parameters import ParameterError
from rawehelix.parameters.section import LAWS, Section
from rawehelix.section_math import ramp_energy

ROOT = Path(__file__).resolve().parents[1]
#: the folders where a law's name may be tested: the scene's checks and what is not product
ALLOWED = {"parameters", "tests", "docs", "scripts", "benchmarks", "build"}
#: the comment that justifies a name test on its line (say why after it)
JUSTIFIED = "# section law by name:"
NAMES = "|".join(section_laws.NAMES)
#: a section law chosen by its name: compared with a law's name, or a law compared
BY_NAME = re.compile(
    rf"""(==|!=|\bin)\s*[(\[{{]?\s*["']({NAMES})["']"""  # x == "solid", x in ("solid", ...)
    rf"""|["']({NAMES})["']\s*(==|!=)"""  # "solid" == x
    r"""|\bsection\.name\b|\bsection_law\s*(==|!=)|\blaw\s*(==|!=)"""  # whatever it is compared with
)


def _product_files():
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT)
        top = rel.parts[0]
        if len(rel.parts) > 1 and (top in ALLOWED or top.startswith(".") or "egg-info" in top):
            continue
        yield rel, path.read_text()


def by_name(text: str) -> list[tuple[int, str]]:
    """The lines of ``text`` that choose a section law by its name, unjustified."""
    return [(i, line.strip()) for i, line in enumerate(text.splitlines(), 1)
            if BY_NAME.search(line.split("#")[0]) and JUSTIFIED not in line]


def test_the_grep_sees_every_form_of_a_name_test():
    """The pattern catches the name tests the product had before issue 42 (so the
    next test cannot pass by seeing nothing), and takes the justified line."""
    caught = ['if c.section.name == "solid":', 'if c.section.name != "solid":',
              'if self.law == "tensegrity":', 'if section.law == "saturating":',
              'if q.section_law == "tensegrity":', "if law in ('solid', 'saturating'):",
              'if "tensegrity" == kind:', 'members = model.section.law == "tensegrity"']
    for line in caught:
        assert by_name(line), line
    assert not by_name('if c.section.name == "solid":  ' + JUSTIFIED + " the file format says so")
    assert not by_name("law = section_laws.get(section.law)")
    assert not by_name('x = 1  # a comment may say law == "solid"')


def test_no_section_law_is_chosen_by_its_name():
    """Outside parameters/ (the scene's checks), tests/, docs/, scripts/ and
    benchmarks/, no product file tests a section law's name: each decision is the
    registry's object's (section_laws.py).  A survivor needs JUSTIFIED on its line."""
    found = {str(rel): hits for rel, text in _product_files() if (hits := by_name(text))}
    assert not found, f"choose by section_laws.get(name)'s attributes, not the name: {found}"


def test_the_registry_refuses_an_unknown_name_with_the_scenes_list():
    assert LAWS == section_laws.NAMES == ("solid", "tensegrity", "saturating")
    assert section_laws.refusal("solid") is None
    with pytest.raises(ValueError, match=r"section.law = 'steel': must be one of \['solid', "
                                         r"'tensegrity', 'saturating'\]"):
        section_laws.get("steel")
    with pytest.raises(ParameterError) as err:
        Section(law="steel")
    assert section_laws.refusal("steel") in str(err.value)
    for law in section_laws.SECTION_LAWS.values():
        assert section_laws.get(law.name) is law
        assert Section(law=law.name).active == law.nonlinear


def test_each_law_says_what_is_decided_by_it():
    solid, tensegrity, saturating = (section_laws.get(n) for n in section_laws.NAMES)
    assert not solid.nonlinear and solid.smooth and solid.normalised(None) is None
    assert tensegrity.nonlinear and not tensegrity.smooth
    assert saturating.nonlinear and not saturating.smooth
    # the members' own resultants: a phase, the twist, GA (the scene's checks read it)
    assert [x.members for x in (solid, tensegrity, saturating)] == [False, True, False]
    for law in (solid, saturating):
        for key, value in (("ring", "turning"), ("torsion", "members")):
            with pytest.raises(ParameterError, match=f"section.{key}"):
                Section(law=law.name, **{key: value})
    assert Section(law="tensegrity", ring="turning", torsion="members").ring == "turning"


def _calls_on_the_section():
    """The method names the product calls on a scene's section component (``c.section.x``)."""
    names = set()
    for rel, text in _product_files():
        if rel.parts[0] == "parameters":
            continue
        names |= set(re.findall(r"\bc\.section\.(\w+)\s*\(", text))
    return names


def test_the_solid_is_a_complete_null_object():
    """Every method the product calls on ``c.section`` is declared by the component's
    Protocol, and the solid (the null object) and the member laws' class both give
    each with the Protocol's parameters (forms/section_law.py)."""
    sl = pytest.importorskip("rawehelix.forms.section_law")
    called = _calls_on_the_section()
    assert {"energy", "twist_moment", "wall_moment", "sheared_density"} <= called
    declared = {n for n, x in vars(sl.SectionComponent).items()
                if inspect.isfunction(x) and not n.startswith("_")}
    assert called <= declared, f"declare them in SectionComponent: {called - declared}"
    for name in declared:
        want = list(inspect.signature(getattr(sl.SectionComponent, name)).parameters)
        for cls in (sl.SolidSection, sl.NonlinearSection):
            assert list(inspect.signature(getattr(cls, name)).parameters) == want, (cls, name)
    for cls in (sl.SolidSection, sl.NonlinearSection):
        assert all(hasattr(cls, a) for a in sl.SectionComponent.__annotations__), cls


@pytest.mark.parametrize("lay, P0, EA_b", [(0.0, 0.0, 0.0), (20.0, 150.0, 2e4)])
def test_the_written_once_law_is_members_docstring(lay, P0, EA_b):
    """Members (numpy, through section_math.py::TetherRing, the FE rod's law too) gives
    the members' strains of members.py's docstring at every phase, and W = sum_m
    (k / cos beta) Phi_w(e_m) + EA_b / 2 (eps + e_b0)^2 + Q_b0 tau, taut and slack."""
    m = Section(law="tensegrity", lay_angle_deg=lay, self_stress_N=P0, bar_EA_N=EA_b,
                tether_EA_N=6000.0, radius_m=0.5, slack_width=1e-4).members(_Helix())
    cb, tb = np.cos(m.beta), np.tan(m.beta)
    psi = np.array([0.0, 0.3])
    seen_slack = 0
    for eps in (-2e-3, 0.0, 1e-3, 5.5e-3):
        for kappa in (0.0, 0.005, 0.05, 0.3):
            for tau in (0.0, 0.02):
                phi = m.phi + psi[:, None]
                e = cb * np.sqrt((1 + eps - m.R * kappa * np.cos(phi))**2 + (m.R * tau + tb)**2) \
                    - 1 + m.e0
                assert np.allclose(m.strains(eps, kappa, tau, psi), e, rtol=1e-13, atol=1e-15)
                W = (m.k / cb * ramp_energy(e, m.width).sum(axis=-1)
                     + 0.5 * m.EA_b * (eps + m.e_b0)**2 + m.Q_b0 * tau)
                assert np.allclose(m.energy(eps, kappa, tau, psi), W, rtol=1e-13, atol=1e-12)
                seen_slack += bool((e <= 0).any())
    assert seen_slack >= 3


class _Helix:
    """The helix keys Section.members reads."""

    EA_N, radius_m, length_m = 36400.0, 0.5, 10.0


def test_the_limits_law_of_each_name():
    """The numpy law the limits read: the cone for the saturating law, none otherwise
    (the members' own or the solid's resultants)."""
    from rawehelix.members import ConeSection

    class Helix(_Helix):
        EI_Nm2 = 4381.0
    section = Section(law="saturating")
    members = section.members(Helix())
    cone = section_laws.get("saturating").limits_law(section, Helix(), members)
    assert isinstance(cone, ConeSection) and cone.c == members.saturation
    assert section_laws.get("solid").limits_law(section, Helix(), members) is None
    N, M = section_laws.get("saturating").resultants(members, cone, 1.0, 2.0, 1e-3, 0.1, 0.0)
    assert (N, M) == (cone.resultants(1e-3, 0.1)["N"], abs(cone.resultants(1e-3, 0.1)["M"]))
    assert section_laws.get("solid").resultants(members, None, 1.0, 2.0, 1e-3, 0.1, 0.0) == (1.0, 2.0)
    assert np.all(section_laws.get("tensegrity").member_forces(members, 0, 0, 0, 1e-3, 0.1, 0.0)[0]
                  == members.forces(1e-3, 0.1, 0.0))
