"""The end components' registry (parameters/end_components.py, issue 42): each
condition at the ends registered once, with its scene section and null object."""

from __future__ import annotations

import dataclasses

import pytest

from rawehelix.parameters import ParameterError, Parameters, end_components
from rawehelix.studies import scene

#: each component switched on from a scene whose ends are all off (its null objects)
ON = {"circle": {"ends.circle_radius_m": 0.5, "ends.circle_frequency_Hz": 1.0},
      "torque_ramp": {"torque.top_Nm": 10.0},
      "controller": {"controller.k1": 0.5},
      "rotor": {"rotor.radius_m": 2.0, "rotor.tsr": [1.0, 3.0, 5.0], "rotor.cp": [0.1, 0.3, 0.4],
                "rotor.ct": [0.2, 0.5, 0.7]},
      "generator": {"generator.law": "mppt", "generator.mppt_gain_Nms2": 0.15},
      "lifter": {"lifter.top": "lifted", "lifter.force_N": 300.0, "lifter.elevation_deg": 60.0}}
OFF = {"ends.circle_radius_m": 0.0, "torque.top_Nm": 0.0, "controller.k1": 0.0,
       "controller.k2": 0.0}


def test_the_registry_holds_todays_ends():
    assert tuple(end_components.REGISTRY) == ("fixed", "circle", "torque_ramp", "controller",
                                              "rotor", "generator", "lifter")
    fields = {f.name: f.type for f in dataclasses.fields(Parameters)}
    for c in end_components.END_COMPONENTS:
        assert c.KEY in fields and fields[c.KEY] == c.SECTION.__name__, c.name


@pytest.mark.parametrize("name", ["circle", "torque_ramp", "controller", "rotor", "generator",
                                  "lifter"])
def test_each_component_is_off_at_its_null_object_and_on_when_switched(name):
    off = scene.load("nominal_operation", elements=2, overrides=OFF)
    assert [c.name for c in end_components.active(off)] == ["fixed"]
    on = scene.load("nominal_operation", elements=2, overrides={**OFF, **ON[name]})
    assert [c.name for c in end_components.active(on)] == ["fixed", name]
    assert (end_components.torques(on) != ()) == (end_components.get(name).load == "torque")


def test_an_unknown_name_is_refused_once_with_the_names():
    with pytest.raises(ParameterError) as err:
        end_components.get("propeller")
    text = str(err.value)
    assert "'propeller'" in text and all(n in text for n in end_components.REGISTRY)


@pytest.mark.parametrize("name", ["torque_ramp", "controller", "rotor", "generator"])
def test_a_torque_component_refuses_the_twist_free_rod(name):
    """model.twist = false needs every torque component off: the message lists each
    one's null object (the registry's, so a new torque component is named too)."""
    with pytest.raises(scene.SceneError) as err:
        scene.load("nominal_operation", elements=2,
                   overrides={**OFF, **ON[name], "model.twist": False})
    assert ("torque.top_Nm = 0, controller off, no rotor.table, generator.law = 'paper'"
            in str(err.value))
    scene.load("nominal_operation", elements=2, overrides={**OFF, "model.twist": False})
