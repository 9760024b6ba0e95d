"""The one registry class (registry.py) behind the five registries of choices made
by name: each refuses an unknown name once, with the list, in its own exception."""

from dataclasses import dataclass

import pytest

from rawehelix.parameters import ParameterError
from rawehelix.registry import Registry


@dataclass(frozen=True)
class Thing:
    name: str


def test_get_iteration_and_names_keep_the_order_of_registration():
    reg = Registry("thing.kind", [Thing("b"), Thing("a")])
    assert reg.names() == ("b", "a") == tuple(reg) and len(reg) == 2
    assert reg.get("a") == Thing("a") == reg["a"] and "a" in reg and "c" not in reg
    assert [t.name for t in reg.values()] == ["b", "a"]


@pytest.mark.parametrize("name", ["c", None, ["a"]])  # unknown, not a string, unhashable
def test_an_unknown_name_is_refused_once_with_the_list(name):
    reg = Registry("thing.kind", [Thing("b"), Thing("a")], error=ParameterError)
    with pytest.raises(ParameterError) as err:
        reg.get(name)
    assert str(err.value) == f"thing.kind = {name!r}: must be one of ('b', 'a')"
    assert reg.refusal(name) == "must be one of ('b', 'a')" and reg.refusal("a") is None


def test_a_name_registered_twice_is_refused():
    with pytest.raises(ValueError, match="'a' is registered twice"):
        Registry("thing.kind", [Thing("a"), Thing("a")])


def test_the_five_registries_are_registries():
    from rawehelix import section_laws
    from rawehelix.models import kinematics
    from rawehelix.parameters import end_components, schemes as cores
    from rawehelix.studies import orbit_method, schemes
    for reg in (section_laws.SECTION_LAWS, kinematics.KINEMATICS_REGISTRY, cores.CORES,
                schemes.SCHEME_REGISTRY, orbit_method.ORBIT_METHODS, end_components.REGISTRY):
        assert isinstance(reg, Registry) and reg.names()
    with pytest.raises(ValueError, match=r"section.law = 'steel': must be one of \['solid', "):
        section_laws.get("steel")
