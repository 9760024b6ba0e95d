"""The components' registry (parameters/components.py): each section module declares
where it lives, its dataclass, its normalised groups and its checks, and the scene
loader, Model and Normalised take them from there."""

import dataclasses

import pytest

from rawehelix.parameters import Model, Normalised, components, fingerprint
from rawehelix.studies import scene


def test_each_table_is_a_scene_section_held_by_its_holder():
    tables = {s.KEY: s for s in components.SECTIONS if s.SECTION is not None}
    assert tables  # damping, torsion_hysteresis
    for key, s in tables.items():
        assert scene.SECTIONS[key] is s.SECTION
        assert scene.NESTED[key] == s.HOLDER
        holder = {f.name: f for f in dataclasses.fields(scene.SECTIONS[s.HOLDER])}
        assert holder[key].default_factory is s.SECTION
        # what Model.describe and the fingerprints ask of a section
        assert s.SECTION().active is False and isinstance(s.SECTION().describe(), str)
    assert set(scene.NESTED) == set(tables)


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
