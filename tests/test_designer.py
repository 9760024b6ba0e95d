"""Issue 41, the designer's part: a scene from what a designer knows (section.rings,
helix.stiffness = "from_section", `rawehelix section`) and the fit/calibrate faults
(a fit its data cannot determine, optional keys refused by calibrate, integer keys
rounded by study), each tried on several inputs."""

import json
import subprocess
import sys

import numpy as np
import pytest

from rawehelix import fits

RAWEHELIX = [sys.executable, "-m", "rawehelix.cli.main"]


def _run(tmp_path, *argv, timeout=300):
    return subprocess.run([*RAWEHELIX, *argv], cwd=tmp_path, capture_output=True, text=True,
                          timeout=timeout)


def _refused(tmp_path, argv, message):
    """Exit 2, one line naming ``message``, nothing written."""
    run = _run(tmp_path, *argv, "-o", str(tmp_path / "OUT"))
    lines = run.stderr.splitlines()
    assert run.returncode == 2, run.stderr
    assert len(lines) == 1 and "Traceback" not in run.stderr, run.stderr
    assert message in lines[0], lines[0]
    assert list(tmp_path.iterdir()) == []
    return lines[0]


# -- a fit its data cannot determine -------------------------------------------------

@pytest.mark.parametrize("design,parameters,why", [
    (fits.polynomial([100.0], 1), 2, "1 distinct point for 2 parameters"),
    (fits.polynomial([100.0, 100.0, 100.0], 1), 2, "1 distinct point for 2 parameters"),
    (fits.polynomial([1.0, 2.0], 2), 3, "2 distinct points for 3 parameters"),
    (np.zeros((0, 2)), 2, "0 distinct points"),
    (np.array([[1.0, 2.0], [2.0, 4.0], [3.0, 6.0]]), 2, "rank 1 for 2"),  # columns alike
    (np.array([[1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]), 2, "rank 1 for 2"),  # one unseen
    (np.array([[1e9, 1e-9], [2e9, 2e-9 * (1 + 1e-3)]]), 2, "rank 1 for 2"),  # under rtol
    (np.array([[1.0, np.nan], [2.0, 1.0]]), 2, "non-finite"),
])
def test_undetermined_names_each_degenerate_design(design, parameters, why):
    rtol = 1e-2 if design.size and np.isfinite(design).all() and design[0, 0] == 1e9 else None
    assert why in fits.undetermined(design, parameters, rtol=rtol)


@pytest.mark.parametrize("design,parameters", [
    (fits.polynomial([90.0, 181.0, 259.0], 1), 2),
    (fits.polynomial([90.0, 181.0], 1), 2),
    (fits.polynomial([0.0, 1.0, 2.0], 2), 3),
    (np.array([[1e9, 1e-9], [2e9, 3e-9]]), 2),  # units do not matter: unit columns
])
def test_a_determined_design_passes(design, parameters):
    assert fits.undetermined(design, parameters) is None


@pytest.mark.parametrize("tensions", ["100", "100,100", "181,181.0,181"])
def test_labtest_bending_fit_refuses_tensions_that_cannot_determine_its_law(tmp_path, tensions):
    _refused(tmp_path, ["labtest", "bending", "--fit", "--tension", tensions],
             "labtest --tension: ")
    assert "1 distinct point for 2 parameters" in _run(
        tmp_path, "labtest", "bending", "--fit", "--tension", tensions).stderr


class _FakeSolver:
    """A rod whose bending reading sees only the law's a (or only a + b): the
    Gauss-Newton Jacobian of the lab law's fit is rank-deficient after the work."""

    def __init__(self, reading):
        self.law, self.reading = (0.0, 0.0), reading

    def set_bending_law(self, a, b):
        self.law = (a, b)


@pytest.mark.parametrize("reading", [
    lambda a, b, T: a * T + 3000.0,  # b unseen
    lambda a, b, T: 2290.0 * np.exp(T * (a / 1e4 + b / 1e6))])  # a and b seen alike
def test_the_lab_laws_gauss_newton_says_when_its_jacobian_cannot_determine_a_b(reading):
    from rawehelix.studies.analysis import labfit
    solver = _FakeSolver(reading)

    def test(solver, T, loads):
        return {"apparent_EI_Nm2": reading(*solver.law, T)}
    tensions = (90.0, 181.0, 259.0)
    targets = 52.4 * np.array(tensions) + 2290.0
    *_, why = labfit._refine_law(solver, tensions, targets, (0.1,), (60.0, 2000.0), test)
    assert why is not None and "rank 1 for 2" in why


def test_calibrate_refuses_fewer_targets_than_keys(tmp_path):
    _refused(tmp_path, ["calibrate", "stationary_table2", "--fit",
                        "helix.EI_Nm2,helix.GJ_Nm2", "--target", "sag_m=0.03"],
             "--fit: helix.EI_Nm2,helix.GJ_Nm2: 2 keys cannot be determined by 1 target")


def test_calibrate_with_keys_its_targets_see_alike_exits_3_not_determined(tmp_path):
    """C_D and l_a enter only as their product (nu, Eq. 26): two targets met, the keys
    not determined, exit 3 with the reason in summary.json."""
    run = _run(tmp_path, "calibrate", "stationary_table2", "--elements", "4", "--fit",
               "helix.drag_coefficient,helix.drag_length_m", "--target",
               "sag_m=0.0359,tension_s0_N=202.9", "-o", "C")
    assert run.returncode == 3, run.stderr
    assert "status: keys not determined (exit status 3)" in run.stdout
    s = json.loads((tmp_path / "C" / "summary.json").read_text())
    assert s["status"] == "keys not determined" and not s["success"]
    assert "rank 1 for 2" in s["undetermined"]
    assert not s["missed"]  # the residuals alone would have called it a success


# -- calibrate --fit an optional key the scene sets -------------------------------------

@pytest.mark.parametrize("key,value", [
    ("helix.GA_N", "2000"), ("section.tether_EA_N", "6000"), ("section.radius_m", "0.3"),
    ("section.breaking_force_N", "500"), ("section.ring_spacing_m", "0.5")])
def test_calibrate_fits_an_optional_key_the_scene_sets(tmp_path, key, value):
    """Refused before for its annotation (float | None): now the fit passes the key and
    stops at the next check (a bad bound), before any work."""
    extra = ["--set", 'model.kinematics="shearable"'] if key == "helix.GA_N" else []
    _refused(tmp_path, ["calibrate", "stationary_table2", *extra, "--set", f"{key}={value}",
                        "--fit", key, "--target", "sag_m=0.03", "--bounds", f"{key}=-1:2"],
             f"--bounds: {key}=-1:2: LO is outside the key's allowed range")


@pytest.mark.parametrize("key", ["helix.GA_N", "section.tether_EA_N", "section.radius_m"])
def test_calibrate_names_an_optional_key_the_scene_leaves_absent(tmp_path, key):
    _refused(tmp_path, ["calibrate", "stationary_table2", "--fit", key, "--target", "sag_m=0.03"],
             f"--fit: {key}: is not set by the scene (absent): the fit starts from the scene's "
             f"value, so set one, e.g. --set {key}=VALUE")


# -- integer keys are never rounded ----------------------------------------------------

@pytest.mark.parametrize("vary,given", [
    ("discretisation.elements=2.5:4.5:2", "2.5"), ("discretisation.elements=2:5:3", "3.5"),
    ("discretisation.degree=2:3:3", "2.5"), ("section.tethers=3:8:3", "5.5")])
def test_study_refuses_an_integer_key_given_non_integer_values(tmp_path, vary, given):
    key = vary.split("=")[0]
    line = _refused(tmp_path, ["study", "stationary_table2", "--vary", vary, "--quantity",
                               "sag_m"], f"--vary: {key}: is an integer key")
    if given:
        assert f"gives it {given}:" in line


@pytest.mark.parametrize("sample", ["lhs", "sobol"])
def test_study_refuses_sampling_an_integer_key_with_real_samples(tmp_path, sample):
    _refused(tmp_path, ["study", "stationary_table2", "--vary", "discretisation.elements=2:8",
                        "--sample", sample, "--points", "4", "--quantity", "sag_m"],
             f"--sample: {sample}: discretisation.elements is an integer key")


def test_an_integer_grid_of_integers_is_kept_as_integers():
    from rawehelix.studies import study
    assert [study.cast("discretisation.elements", v) for v in np.linspace(2, 8, 4)] == [2, 4, 6, 8]
    assert isinstance(study.cast("helix.EI_Nm2", 3), float)
    # an optional integer key (int | None) is an integer key too: section.rings = 8,
    # not 8.0 (which the loader would refuse); an optional number is a number
    assert study.cast("section.rings", 8.0) == 8 and isinstance(study.cast("section.rings", 8.0), int)
    assert study.key_type("helix.GA_N") == "float" and study.key_type("helix.EI_law") != "float"


# -- section.rings: the number of rings instead of their spacing -------------------------

@pytest.mark.long  # make test's budget (make test-long runs it)
def test_rings_and_their_spacing_give_identical_limits():
    """section.rings = 9 on the 16.12 m helix is ring_spacing_m = 16.12 / 8: the same
    members, and the same limits block of a solved stationary state."""
    import rawehelix as rh
    L0 = rh.load_scene("stationary_table2").helix.length_m
    by_rings = rh.load_scene("stationary_table2", elements=4, overrides={"section.rings": 9})
    by_spacing = rh.load_scene("stationary_table2", elements=4,
                               overrides={"section.ring_spacing_m": L0 / 8})
    m = by_rings.model.section.members(by_rings.helix)
    assert m == by_spacing.model.section.members(by_spacing.helix)
    assert m.ring_spacing_m == L0 / 8 and np.isfinite(m.critical_twist())
    a, b = rh.stationary(by_rings).summary["limits"], rh.stationary(by_spacing).summary["limits"]
    assert a == b and a["criteria"]["torsional_collapse"] is not None
    off = rh.stationary(rh.load_scene("stationary_table2", elements=4)).summary["limits"]
    assert off["criteria"]["torsional_collapse"] is None  # neither: the check is off


@pytest.mark.parametrize("sets,message", [
    (["section.rings=8", "section.ring_spacing_m=0.5"],
     "section.rings: 8 and section.ring_spacing_m = 0.5 both set the rings' spacing"),
    (["section.rings=1"], "section.rings: 1 must be an integer >= 2"),
    (["section.rings=-3"], "section.rings: -3 must be an integer >= 2"),
    (["section.rings=2.5"], "section.rings: must be an integer, got 2.5"),
])
def test_bad_rings_are_refused_in_one_line(tmp_path, sets, message):
    argv = ["stationary", "stationary_table2"]
    for item in sets:
        argv += ["--set", item]
    _refused(tmp_path, argv, message)


# -- helix.stiffness = "from_section" and `rawehelix section` ---------------------------

OWN = """
[helix]
length_m = 30.0
mass_kg = 3.0
radius_m = 0.5
stiffness = "from_section"
[ends]
elongation = 0.005
elevation_deg = 30.0
[section]
tethers = {n}
tether_EA_N = {k}
lay_angle_deg = {lay}
self_stress_N = {P0}
bar_EA_N = {bars}
rings = 8
"""


def _closed_forms(n, k, R, lay_deg, P0, bars):
    """EA, EI, GJ of n tethers of stiffness k at radius R laid at beta, each carrying
    P0 at zero strain, bars EA_b on the axis, written out here (not members.py): a
    tether's axial share is k cos^3 beta (its strain cos(beta) x the axial strain, its
    force's axial part cos(beta) again, its length 1/cos(beta) per unit rod length ...
    and P0's geometric share P0 cos beta sin^2 beta); the ring's second moment is
    sum cos^2(phi_m) R^2 = n R^2 / 2; the lay's torsion k sin^2 beta cos beta R^2 and
    the tension's P0 cos^3 beta R^2 per tether."""
    b = np.radians(lay_deg)
    axial = n * (k * np.cos(b) ** 3 + P0 * np.cos(b) * np.sin(b) ** 2)
    second_moment = sum(np.cos(2 * np.pi * j / n) ** 2 for j in range(n)) * R**2
    return {"EA_N": axial + bars, "EI_Nm2": axial * second_moment / n,
            "GJ_Nm2": n * np.cos(b) * R**2 * (k * np.sin(b) ** 2 + P0 * np.cos(b) ** 2)}


SECTIONS = [  # n, k [N], lay [deg], P0 [N], bars EA_b [N]
    (6, 20000.0, 0.0, 50.0, 1e4),  # no lay: GJ = n P0 R^2, EA = n k + EA_b, EI = n k R^2 / 2
    (6, 20000.0, 5.0, 0.0, 0.0),
    (3, 1234.5, 30.0, 0.0, 0.0),
    (8, 5e5, 12.0, 100.0, 2e5),
]


@pytest.mark.parametrize("n,k,lay,P0,bars", SECTIONS)
def test_from_section_puts_the_members_closed_forms_in_the_rod(tmp_path, n, k, lay, P0, bars):
    import rawehelix as rh
    path = tmp_path / "own.toml"
    path.write_text(OWN.format(n=n, k=k, lay=lay, P0=P0, bars=bars))
    p = rh.load_scene(path)
    want = _closed_forms(n, k, 0.5, lay, P0, bars)
    if lay == 0:
        assert want["EA_N"] == pytest.approx(n * k + bars, rel=1e-14)
        assert want["EI_Nm2"] == pytest.approx(n * k * 0.25 / 2, rel=1e-14)
        assert want["GJ_Nm2"] == pytest.approx(n * P0 * 0.25, rel=1e-14)
    for key, value in want.items():
        assert getattr(p.helix, key) == pytest.approx(value, rel=1e-12), key
    # the scene's other spellings follow: the section changed through replace() ...
    q = p.replace(section={"tether_EA_N": 2 * k})
    assert q.helix.EA_N == pytest.approx(_closed_forms(n, 2 * k, 0.5, lay, P0, bars)["EA_N"])
    # ... and `rawehelix section` prints and stores the same numbers
    run = _run(tmp_path, "section", str(path), "-o", "SEC")
    assert run.returncode == 0, run.stderr
    s = json.loads((tmp_path / "SEC" / "summary.json").read_text())
    for key, value in want.items():
        assert s["taut_moduli"][key] == pytest.approx(value, rel=1e-12)
        assert s["helix"][key] == pytest.approx(value, rel=1e-12)
    assert s["members"]["ring_spacing_m"] == pytest.approx(30.0 / 7)
    assert f"= {want['EA_N']:.6g} N" in run.stdout and f"= {want['GJ_Nm2']:.6g} N m^2" in run.stdout
    # under the chord's tension T, the tethers' share T_t (the bars carry the rest)
    # adds T_t R^2 to GJ without a lay (to the strain's order)
    T = s["at_tension"]["tension_N"]
    assert T == pytest.approx(want["EA_N"] * 0.005)
    T_t = T * (want["EA_N"] - bars) / want["EA_N"]
    if lay == 0:
        assert s["at_tension"]["GJ_Nm2"] - want["GJ_Nm2"] == pytest.approx(T_t * 0.25, rel=0.01)
    else:  # a lay takes the tension's share down (the tester's D6: the remark said T_t R^2)
        assert 0 < s["at_tension"]["GJ_Nm2"] - want["GJ_Nm2"] < T_t * 0.25
    # the printed remark is the section's: the share it adds, and the lay named only if laid
    share = s["at_tension"]["GJ_Nm2"] - want["GJ_Nm2"]
    assert f"adds {share:.4g} to GJ; T_t R^2 = {T_t * 0.25:.4g} without a lay" in run.stdout
    assert ("less at the lay of" in run.stdout) is (lay != 0)


def test_section_prints_the_lab_tests_values_for_a_given_scene(tmp_path):
    """A scene with given stiffness: the section's tether stiffness is derived from
    helix.EA_N, and the lab tests' values (Sec. 4) are the alternative printed."""
    run = _run(tmp_path, "section", "stationary_table2", "-o", "SEC")
    assert run.returncode == 0, run.stderr
    s = json.loads((tmp_path / "SEC" / "summary.json").read_text())
    assert s["helix"]["EA_N"] == 3.64e4 and s["taut_moduli"]["EA_N"] == pytest.approx(3.64e4)
    assert s["members"]["tether_EA_from"].startswith("derived")
    lab = s["lab_tests"]
    assert (lab["EA_N"], lab["EI_law"], lab["GJ_Nm2"], lab["GJ_at_tension_N"]) == (
        3.64e4, {"a_Nm2_per_N": 52.4, "b_Nm2": 2290.0}, 140.0, 200.0)
    T = s["at_tension"]["tension_N"]
    assert lab["EI_at_tension_Nm2"] == pytest.approx(52.4 * T + 2290.0)
    assert "EI = 52.4 T + 2290 N m^2 (Eq. 64" in run.stdout


@pytest.mark.parametrize("sets,message", [
    (["helix.EA_N=1e5"], "helix.EA_N: is given, but helix.stiffness = 'from_section' takes"),
    (["helix.GJ_Nm2=100"], "helix.GJ_Nm2: is given, but helix.stiffness = 'from_section'"),
    (["section.tether_EA_N=nan"], "section.tether_EA_N"),
    (["section.lay_angle_deg=0"], "section.lay_angle_deg: 0.0 gives no torsional stiffness"),
    (["helix.stiffness=\"members\""], "helix.stiffness: \"members\" must be one of"),
])
def test_from_section_refuses_too_much_or_too_little(tmp_path, sets, message):
    (tmp_path / "in").mkdir()
    path = tmp_path / "in" / "own.toml"
    path.write_text(OWN.format(n=6, k=2e4, lay=5.0, P0=0.0, bars=0.0))
    argv = ["stationary", str(path)]
    for item in sets:
        argv += ["--set", item]
    run = _run(tmp_path, *argv, "-o", str(tmp_path / "OUT"))
    assert run.returncode == 2 and len(run.stderr.splitlines()) == 1, run.stderr
    assert message in run.stderr and not (tmp_path / "OUT").exists()


def test_from_section_names_a_missing_tether_stiffness_and_given_names_a_missing_EA(tmp_path):
    import rawehelix as rh
    path = tmp_path / "own.toml"
    path.write_text(OWN.format(n=6, k=2e4, lay=5.0, P0=0.0, bars=0.0)
                    .replace("tether_EA_N = 20000.0\n", ""))
    with pytest.raises(rh.SceneError, match="section.tether_EA_N: is required by "
                                            "helix.stiffness = 'from_section'"):
        rh.load_scene(path)
    path.write_text(path.read_text().replace('stiffness = "from_section"', ""))
    with pytest.raises(rh.SceneError, match=r"helix.EA_N: is required \(or set helix.stiffness"):
        rh.load_scene(path)


def test_the_new_keys_at_their_defaults_keep_stored_fingerprints():
    import rawehelix as rh
    for name in ("stationary_table2", "nominal_operation"):
        data = rh.load_scene(name).as_dict()
        assert "stiffness" not in data["helix"]
        assert "rings" not in data["model"].get("section", {})
    tensegrity = rh.load_scene("stationary_table2", overrides={"section.law": "tensegrity",
                                                                "model.kinematics": "extensible"})
    assert "rings" not in tensegrity.as_dict()["model"]["section"]


def test_a_lab_fit_its_data_could_not_determine_exits_3_and_says_so():
    """labtest's result: exit status 3 (EXIT_UNMET) with the reason in its report
    when labfit.fit returned ``undetermined``; 0 otherwise."""
    from rawehelix.studies import labtest, study
    summary = {"test": "bending", "scene": "s", "length_m": 6.76, "elements": 8, "degree": 3,
               "gravity": True, "fit": True, "tension_N": [90.0, 181.0],
               "intrinsic_EI_Nm2": [1.0, 2.0], "apparent_EI_Nm2": [1.0, 2.0],
               "eq64_EI_Nm2": [1.0, 2.0], "relative_error": [0.0, 0.0],
               "law": {"a_Nm2_per_N": 1.0, "b_Nm2": 2.0},
               "undetermined": "the design has rank 1 for 2 parameters"}
    bad = labtest.LabTest(None, "bending", [], summary)
    assert bad.exit_status == study.EXIT_UNMET == 3
    assert "is not determined: the design has rank 1 for 2 parameters" in labtest._report(bad)
    good = labtest.LabTest(None, "bending", [], {**summary, "undetermined": None})
    assert good.exit_status == 0 and "reproduces Eq. (64) within" in labtest._report(good)
