"""The kinematics as one registered object and the rod-model interface as what the
solvers call (issue 42; models/kinematics.py, models/base.py).

* the registry names the kinematics of ``parameters.KINEMATICS`` and refuses any
  other name once, as a scene's ``model.kinematics`` is refused;
* each decision made by the kinematics' name is the object's: its rod model, the
  planar reduction, the modal damping estimate, the cantilever's transverse
  equation, its independent reference;
* no product module chooses a kinematics by name (outside parameters/' validation),
  unless the line says why (``# kinematics by name: ...``);
* every method the solvers (and the studies, the API) call on a rod model is
  declared by ``RodModel``, and no module outside models/ imports a concrete model.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest

from rawehelix.forms.coefficients import KINEMATICS as COMPONENTS
from rawehelix.models import kinematics
from rawehelix.models.base import RodModel
from rawehelix.parameters import KINEMATICS, ParameterError
from rawehelix.studies import scene

ROOT = Path(__file__).resolve().parents[1]
#: the folders that hold no product code (parameters/ validates the names)
NOT_PRODUCT = {"tests", "docs", "scripts", "benchmarks", ".venv", ".ci"}


def of_kinematics(name: str, **changes):
    """Table 2's scene with the kinematics ``name`` (the shearable rod with a GA)."""
    helix = {"GA_N": 1e7} if name == "shearable" else {}
    return scene.load("stationary_table2").replace(model={"kinematics": name}, helix=helix,
                                                   **changes)


def product_files(skip=()):
    for path in sorted(ROOT.rglob("*.py")):
        parts = path.relative_to(ROOT).parts
        if parts[0] not in NOT_PRODUCT | set(skip) and not parts[0].startswith("."):
            yield path


# -- the registry ------------------------------------------------------------------
def test_the_registry_names_the_scenes_kinematics():
    assert tuple(kinematics.KINEMATICS_REGISTRY) == KINEMATICS
    assert tuple(COMPONENTS) == KINEMATICS  # the UFL half (forms/coefficients.py)
    for name in KINEMATICS:
        assert kinematics.get(name).name == name == COMPONENTS[name].name


def test_an_unknown_name_is_refused_as_a_scenes_is():
    with pytest.raises(ParameterError) as by_registry:
        kinematics.get("timoshenko")
    with pytest.raises(ParameterError) as by_scene:
        scene.load("stationary_table2").replace(model={"kinematics": "timoshenko"})
    assert str(by_registry.value) == str(by_scene.value)
    assert "model.kinematics" in str(by_registry.value)
    assert all(name in str(by_registry.value) for name in KINEMATICS)


def test_a_kinematics_that_leaves_a_decision_is_refused_when_defined():
    with pytest.raises(TypeError, match="does not decide .*'planar_reduction'"):
        class Undecided(kinematics.Kinematics):  # noqa: F841
            name, reference = "undecided", "shooting"
            rod_model = staticmethod(kinematics.unshearable_rod)
            bending_in_axial_damping = False
            cantilever_transverse = staticmethod(kinematics.paper_transverse)
    for kin in kinematics.KINEMATICS_REGISTRY.values():
        assert all(getattr(kin, k) is not None for k in kin.DECISIONS)


def test_each_kinematics_has_its_rod_model():
    from rawehelix.models import rod_model
    for name in KINEMATICS:
        model = rod_model(of_kinematics(name))
        assert isinstance(model, RodModel)
        assert model.has("director") == (name == "shearable")


def test_the_planar_reduction_is_the_kinematics_decision():
    from rawehelix.solvers.planar import planar_allowed
    allowed = {name: planar_allowed(of_kinematics(name)) for name in KINEMATICS}
    assert allowed == {name: kinematics.get(name).planar_reduction for name in KINEMATICS}
    assert {name: allowed[name] for name in ("paper", "extensible", "shearable")} == {
        "paper": True, "extensible": True, "shearable": False}


def test_the_modal_estimate_holds_the_bending_share_where_the_kinematics_has_it():
    from rawehelix.solvers.modal_window import estimates
    q = scene.load("stationary_table2").replace(
        damping={"axial_s": 0.0, "bending_s": 0.1, "torsion_s": 0.0}).normalised()
    longitudinal = {name: estimates(q, 1.0, 3, kinematics=name)["longitudinal"]
                    for name in KINEMATICS}
    assert not np.allclose(longitudinal["paper"], longitudinal["extensible"])
    np.testing.assert_allclose(longitudinal["extensible"], longitudinal["shearable"])


def test_the_cantilever_transverse_equation_is_the_kinematics():
    from rawehelix.solvers import analytic
    T_e, EI, EA = np.array([0.0, 100.0, 250.0]), 7000.0, 1e4
    T, EI_t = analytic.cantilever_transverse(T_e, EI, EA, "extensible")
    np.testing.assert_allclose(T, T_e / (1 + T_e / EA))
    np.testing.assert_allclose(EI_t, EI / (1 + T_e / EA) ** 2)
    T, EI_t = analytic.cantilever_transverse(T_e, EI, EA)  # the paper's
    eps = analytic.paper_axial_strain(T_e, EA)
    np.testing.assert_allclose(EA * eps * (1 + eps), T_e)
    np.testing.assert_allclose(T, T_e / (1 + eps))
    assert np.all(EI_t == EI)
    with pytest.raises(ParameterError):
        analytic.cantilever_transverse(T_e, EI, EA, "timoshenko")


def test_each_kinematics_names_a_reference_the_check_holds():
    from rawehelix.references import shooting, shooting_shear
    from rawehelix.studies import reference_check
    solvers = {name: reference_check.references()[kinematics.get(name).reference].solve
               for name in KINEMATICS}
    assert {name: solvers[name] for name in ("paper", "extensible", "shearable")} == {
        "paper": shooting.solve, "extensible": shooting.solve_extensible,
        "shearable": shooting_shear.solve_shearable}


def test_a_shearable_scene_without_GA_is_not_applicable():
    from rawehelix.studies import reference_check
    params = of_kinematics("shearable")
    assert reference_check.reference_of(params).not_applicable(params) is None
    members = scene.load("stationary_table2").replace(model={"kinematics": "shearable"},
                                           section={"law": "tensegrity", "lay_angle_deg": 10.0})
    assert "constant GA" in reference_check.reference_of(members).not_applicable(members)


# -- no kinematics chosen by name ----------------------------------------------------
#: a test of the kinematics' name: ==, !=, in (...), not in (...), or a lookup by it
BY_NAME = re.compile(r"kinematics(\.name)?\s*(==|!=|(not\s+)?in\s*[(\[{])"
                     r"|\[[^\]\n]*\bkinematics\s*\]")
#: the comment that justifies a survivor
JUSTIFIED = re.compile(r"#.*kinematics by name: \S")


def chosen_by_name(text: str) -> list[str]:
    return [line.strip() for line in text.splitlines()
            if BY_NAME.search(line.split("#")[0]) and not JUSTIFIED.search(line)]


def test_the_search_finds_a_choice_by_name():
    assert chosen_by_name('    if params.model.kinematics == "shearable":')
    assert chosen_by_name('    if c.kinematics.name != "extensible":')
    assert chosen_by_name('    return x if model.kinematics in ("paper", "extensible") else y')
    assert chosen_by_name('    f = {"paper": a, "shearable": b}[params.model.kinematics]')
    assert not chosen_by_name('    return kinematics.of(params).planar_reduction')
    assert not chosen_by_name('    x = K[model.kinematics]()  # kinematics by name: the UFL half')
    assert not chosen_by_name('    # if params.model.kinematics == "shearable": a comment')


def test_no_product_module_chooses_a_kinematics_by_name():
    found = {str(path.relative_to(ROOT)): hits for path in product_files(skip={"parameters"})
             if (hits := chosen_by_name(path.read_text()))}
    assert found == {}, ("ask models/kinematics.py's registry "
                         "(or say why: # kinematics by name: ...)")


# -- the rod-model interface -----------------------------------------------------------
#: a rod model as the solvers hold it: ``model``, ``self.model``, ``rod.model``, ...
#: (``params.model`` is the scene's [model] table, not a rod model)
SCENE_TABLES = {"params", "p", "scene", "base"}


def _is_rod_model(node: ast.expr) -> bool:
    if isinstance(node, ast.Name):
        return node.id == "model"
    if isinstance(node, ast.Attribute) and node.attr == "model":
        owner = node.value  # params.model, self.params.model: the scene's table
        return not (isinstance(owner, ast.Name) and owner.id in SCENE_TABLES
                    or isinstance(owner, ast.Attribute) and owner.attr in SCENE_TABLES)
    return False


def called_on_models(source: str) -> set[str]:
    """The names of the methods called on a rod model in ``source``."""
    return {node.func.attr for node in ast.walk(ast.parse(source))
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and _is_rod_model(node.func.value)}


def test_the_walk_finds_the_methods_called():
    source = ("f = model.split(w)\nT = self.rod.model.tension(f, c)\n"
              "x = rod.model.conservative(c)\ny = params.model.replace(twist=False)\n"
              "z = self.params.model.describe()\n")
    assert called_on_models(source) == {"split", "tension", "conservative"}


def test_every_method_called_on_a_model_is_declared_by_the_interface():
    """The solvers' calls (and the studies' and the API's: the rooms that hold a rod
    model; gmsh.model in meshes/ and the scene's [model] in parameters/ are not one)."""
    called = set()
    for path in product_files(skip={"models", "meshes", "parameters"}):
        called |= called_on_models(path.read_text())
    assert {"moment", "conservative", "pair_element", "split_pair"} <= called  # the walk sees them
    assert sorted(name for name in called if not hasattr(RodModel, name)) == []


def test_a_model_without_a_first_order_form_says_so():
    from rawehelix.models.shearable import ShearableRod
    model = ShearableRod(of_kinematics("shearable"))
    assert model.refusals("first_order")
    with pytest.raises(NotImplementedError, match="no first-order form"):
        model.pair_element(None, 2)


#: an import of a concrete model (models/unshearable.py, models/shearable.py)
CONCRETE = re.compile(r"^\s*(from\s+rawehelix\.models\.(unshearable|shearable)\s+import"
                      r"|import\s+rawehelix\.models\.(unshearable|shearable)"
                      r"|from\s+rawehelix\.models\s+import\s+.*\b(unshearable|shearable)\b)", re.M)


def test_the_import_search_finds_a_concrete_model():
    assert CONCRETE.search("from rawehelix.models.unshearable import PAIR_ROLES")
    assert CONCRETE.search("    from rawehelix.models import shearable")
    assert not CONCRETE.search("from rawehelix.models.base import PAIR_ROLES")


def test_no_module_outside_models_imports_a_concrete_model():
    found = [str(path.relative_to(ROOT)) for path in product_files(skip={"models"})
             if CONCRETE.search(path.read_text())]
    assert found == [], "ask models/base.py (the interface) or models/kinematics.py"
