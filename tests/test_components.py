"""The components' registry (parameters/components.py): each section module declares
where it lives, its dataclass, its normalised groups and its checks, and the scene
loader, Model and Normalised take them from there."""

import dataclasses

import pytest

from rawehelix.parameters import Model, Normalised, Parameters, components, fingerprint
from rawehelix.studies import scene


def test_each_table_is_a_scene_section_held_by_its_holder():
    tables = {s.KEY: s for s in components.SECTIONS if s.SECTION is not None}
    assert tables  # damping, torsion_hysteresis, wind (held by the scene itself: HOLDER None)
    for key, s in tables.items():
        assert scene.SECTIONS[key] is s.SECTION
        assert scene.NESTED.get(key) == s.HOLDER
        holder = {f.name: f for f in dataclasses.fields(
            Parameters if s.HOLDER is None else scene.SECTIONS[s.HOLDER])}
        assert holder[key].default_factory is s.SECTION
        # what Model.describe and the fingerprints ask of a section
        assert s.SECTION().active is False and isinstance(s.SECTION().describe(), str)
    assert set(scene.NESTED) == {k for k, s in tables.items() if s.HOLDER is not None}


def test_model_keeps_its_fields_in_their_order():
    """The fingerprints hash Model as a dict in this order (tests/test_checkpoints.py);
    a new component's table comes after them.  A switch added since (rotary_inertia,
    the shearable rod's) is dropped from that dict at its default
    (parameters/fingerprint.py::LATER_MODEL_SWITCHES), so the stored fingerprints hold."""
    names = [f.name for f in dataclasses.fields(Model)]
    assert names[:11] == [
        "gravity", "drag", "bending", "twist", "gamma", "reduction", "gamma_eps",
        "kinematics", "rotary_inertia", "damping", "torsion_hysteresis"]
    assert fingerprint.LATER_MODEL_SWITCHES["rotary_inertia"] is True


@pytest.mark.parametrize("section", components.SECTIONS, ids=lambda s: s.KEY)
def test_normalised_groups_are_declared_with_their_off_values(section):
    """normalise gives exactly the NORMALISED fields, and at the section's defaults
    (the component off) their declared values, which are Normalised's defaults."""
    p = scene.load("stationary_table2")
    q = p.normalised()
    got = section.normalise(p, {"L0": p.helix.length_m, "M": p.helix.mass_kg,
                                "g": p.environment.g_m_s2, "t_scale": q.t_scale})
    assert got == section.NORMALISED
    defaults = {f.name: f.default for f in dataclasses.fields(Normalised)}
    for name, value in section.NORMALISED.items():
        assert defaults[name] == value and getattr(q, name) == value


def test_group_of_an_active_section_reaches_normalised():
    p = scene.load("stationary_table2").replace(damping={"axial_s": 0.5})
    q = p.normalised()
    assert q.tau_axial == pytest.approx(0.5 / q.t_scale, rel=1e-15)
    assert p.model.damping.axial_s == 0.5 and p.value("damping.axial_s") == 0.5


def _implementations():
    """Every class of each component of forms/coefficients.py, null objects included."""
    from rawehelix.forms import (coefficients, damping, eilaw, hysteresis, section_law,
                                 spin_drag, wind)
    from rawehelix.forms.components import (BendingLaw, Damping, Hysteresis, Kinematics,
                                            SectionLaw, SpinDragLaw, WindProfile)
    return [(Kinematics, cls) for cls in coefficients.KINEMATICS.values()] + [
        (Damping, damping.KelvinVoigt), (Damping, damping.NoneDamping),
        (BendingLaw, eilaw.TensionDependentBending), (BendingLaw, eilaw.ConstantBending),
        (Hysteresis, hysteresis.BoucWen), (Hysteresis, hysteresis.NoneHysteresis),
        (SectionLaw, section_law.SolidSection), (SectionLaw, section_law.NonlinearSection),
        (SpinDragLaw, spin_drag.SpinDrag), (SpinDragLaw, spin_drag.NoSpinDrag),
        (WindProfile, wind.UniformWind), (WindProfile, wind.ProfileWind)]


@pytest.mark.parametrize("protocol, cls", _implementations(),
                         ids=lambda x: getattr(x, "__name__", str(x)))
def test_each_component_class_gives_its_protocol(protocol, cls):
    """What the forms call on a component is declared (forms/components.py), and each
    implementation, null object included, has it (typing.Protocol's runtime check
    looks for every member)."""
    members = [m for m in vars(protocol) if not m.startswith("_")] + \
        list(getattr(protocol, "__annotations__", {}))
    missing = [m for m in members if not hasattr(cls, m)]
    assert missing == [], (cls.__name__, missing)


@pytest.mark.parametrize("name, overrides", [
    ("nominal_operation", {}),
    ("mobile_end", {"damping.axial_s": 0.01, "torsion_hysteresis.rho": 0.5,
                    "torsion_hysteresis.beta_m_n": 1.0}),
    ("stationary_table2", {"section.law": "tensegrity", "model.kinematics": "extensible"}),
])
def test_the_coefficients_components_are_built_from_the_registry(name, overrides):
    """Coefficients types each component by its protocol and builds them from
    forms/coefficients.py::COMPONENTS (a new component: one entry there)."""
    import typing
    from rawehelix.forms import coefficients
    p = scene.load(name, elements=2, overrides=overrides)
    c = coefficients.Coefficients.from_normalised(p.normalised(), p.model)
    hints = typing.get_type_hints(coefficients.Coefficients)
    for field in [*coefficients.COMPONENTS, "kinematics"]:
        assert getattr(hints[field], "_is_protocol", False), field
        assert isinstance(getattr(c, field), hints[field]), field
    assert type(c.damping).__name__ == ("KelvinVoigt" if p.model.damping.active
                                        else "NoneDamping")
    assert type(c.hysteresis).__name__ == ("BoucWen" if p.model.torsion_hysteresis.active
                                           else "NoneHysteresis")
    from rawehelix import section_laws
    from rawehelix.forms import section_law
    assert isinstance(c.section, section_law.SolidSection) \
        == (not section_laws.get(p.model.section.law).nonlinear)
