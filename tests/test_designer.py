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
    from rawehelix.studies import labfit
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
