"""cli.argv.split against the real command-line parser: PETSc's
``-option value`` next to our options, positionals and subcommands."""

import argparse

import pytest

from rawehelix.cli import argv, main as cli

S = ["stationary", "stationary_table2"]


@pytest.mark.parametrize("tokens,ours,petsc", [
    # bare PETSc flags
    (S + ["-rawehelix_snes_monitor"], S, ["-rawehelix_snes_monitor"]),
    (S + ["-rawehelix_snes_monitor", "-rawehelix_ksp_view"], S,
     ["-rawehelix_snes_monitor", "-rawehelix_ksp_view"]),
    # PETSc options with a value (the case parse_known_args refused)
    (S + ["-rawehelix_snes_linesearch_type", "bt"], S, ["-rawehelix_snes_linesearch_type", "bt"]),
    (S + ["-rawehelix_snes_monitor", "-rawehelix_snes_max_it", "50"], S,
     ["-rawehelix_snes_monitor", "-rawehelix_snes_max_it", "50"]),
    # negative numbers are values, not options
    (S + ["-rawehelix_snes_rtol", "-1", "-rawehelix_snes_atol", "-1e-3", "-x_shift", "-.5"], S,
     ["-rawehelix_snes_rtol", "-1", "-rawehelix_snes_atol", "-1e-3", "-x_shift", "-.5"]),
    (S + ["-rawehelix_snes_atol", "1e-12"], S, ["-rawehelix_snes_atol", "1e-12"]),
    # our options interleaved with PETSc's, before, between and after
    (S + ["-o", "DIR", "-rawehelix_snes_type", "newtonls", "--elements", "8",
          "-rawehelix_snes_monitor", "--degree", "2"],
     S + ["-o", "DIR", "--elements", "8", "--degree", "2"],
     ["-rawehelix_snes_type", "newtonls", "-rawehelix_snes_monitor"]),
    (["stationary", "-o", "DIR", "stationary_table2", "-rawehelix_snes_monitor"],
     ["stationary", "-o", "DIR", "stationary_table2"], ["-rawehelix_snes_monitor"]),
    (S + ["--output=DIR", "-o=D2", "--elem", "8", "-rawehelix_snes_monitor"],
     S + ["--output=DIR", "-o=D2", "--elem", "8"], ["-rawehelix_snes_monitor"]),
    # -options_file is PETSc's, not -o with the value "ptions_file"
    (S + ["-options_file", "petsc.opts"], S, ["-options_file", "petsc.opts"]),
    # subcommands: each with its own options
    (["sweep", "mobile_end", "--f1", "1:3:1", "--series", "-rawehelix_ts_monitor",
      "-rawehelix_ts_max_snes_failures", "-1"],
     ["sweep", "mobile_end", "--f1", "1:3:1", "--series"],
     ["-rawehelix_ts_monitor", "-rawehelix_ts_max_snes_failures", "-1"]),
    (["simulate", "nominal_operation", "--until", "0.5", "-rawehelix_ts_type", "alpha2"],
     ["simulate", "nominal_operation", "--until", "0.5"], ["-rawehelix_ts_type", "alpha2"]),
    (["modes", "stationary_table2", "--count", "4", "--scheme", "spline"],
     ["modes", "stationary_table2", "--count", "4", "--scheme", "spline"], []),
    (["extremes", "a", "b", "-o", "DIR", "-rawehelix_snes_monitor"],
     ["extremes", "a", "b", "-o", "DIR"], ["-rawehelix_snes_monitor"]),
    # short flags run together are ours (argparse counts them)
    (S + ["-vv", "-rawehelix_snes_monitor"], S + ["-vv"], ["-rawehelix_snes_monitor"]),
    # a single-dash word near one of ours but not it is PETSc's (its check names ours)
    (S + ["-elemnts", "4"], S, ["-elemnts", "4"]),
])
def test_split(tokens, ours, petsc):
    assert argv.split(tokens, cli._parser()) == (ours, petsc)


@pytest.mark.parametrize("tokens,hint", [
    # a double dash is never PETSc's: a typo of ours, or another command's option
    (S + ["--elemnts", "4"], "--elemnts: is not an option of this command; did you mean --elements?"),
    (S + ["--count", "4"], "--count: is not an option of this command; known: --output,"),
    (["sweep", "mobile_end", "--f1", "1:2:1", "--Series"], "did you mean --series?"),
    # one of ours but for case and dashes
    (S + ["-O", "DIR"], "-O: is not an option of this command; did you mean -o?"),
    (S + ["-output", "DIR"], "did you mean --output?"),
    (S + ["-Elements", "4"], "did you mean --elements?"),
    (S + ["-set", "helix.EI_Nm2=1"], "did you mean --set?"),
    (["labtest", "axial", "--no_gravity"], "did you mean --no-gravity?"),
    (["labtest", "axial", "-V"], "did you mean -v?"),
    (["--elements", "4", "stationary"], "the command comes first: stationary, modes,"),
])
def test_mistyped_options_of_ours_refused(tokens, hint):
    with pytest.raises(argv.ArgvError) as err:
        argv.split(tokens, cli._parser())
    assert hint in str(err.value)


def test_ours_parse_strictly():
    """Our part parses with parse_args: no leftovers, the values in place."""
    parser = cli._parser()
    ours, petsc = argv.split(
        ["sweep", "mobile_end", "-rawehelix_snes_linesearch_type", "bt", "-o", "/tmp/x",
         "--elements", "8", "-rawehelix_snes_rtol", "-1e-3", "--f1", "1:2:1"], parser)
    args = parser.parse_args(ours)
    assert (args.command, args.scene, str(args.output), args.elements, args.f1) == \
        ("sweep", "mobile_end", "/tmp/x", 8, "1:2:1")
    assert petsc == ["-rawehelix_snes_linesearch_type", "bt", "-rawehelix_snes_rtol", "-1e-3"]


def test_missing_value_left_to_argparse():
    """Our option followed by an option takes no value: argparse then says so."""
    parser = cli._parser()
    ours, petsc = argv.split(S + ["--elements", "-rawehelix_snes_monitor"], parser)
    assert (ours, petsc) == (S + ["--elements"], ["-rawehelix_snes_monitor"])
    with pytest.raises(SystemExit):
        parser.parse_args(ours)


def test_positional_after_petsc_option_is_its_value():
    """The documented limit: positionals come before the PETSc options."""
    ours, petsc = argv.split(["stationary", "-rawehelix_snes_monitor", "stationary_table2"],
                             cli._parser())
    assert (ours, petsc) == (["stationary"], ["-rawehelix_snes_monitor", "stationary_table2"])


def test_ambiguous_prefix_and_double_dash():
    parser = argparse.ArgumentParser()
    parser.add_argument("--alpha", type=int)
    parser.add_argument("--alps", action="store_true")
    parser.add_argument("names", nargs="*")
    assert argv.split(["--alp", "3"], parser) == (["--alp", "3"], [])
    with pytest.raises(SystemExit):
        parser.parse_args(["--alp", "3"])  # "ambiguous option"
    assert argv.split(["--alph", "3", "n", "--", "-x"], parser) == (["--alph", "3", "n", "--", "-x"], [])


# -- the PETSc options' check (solvers/petsc_options.py), in this process's database

@pytest.fixture
def petsc_options():
    """PETSc's options database with some options set, restored afterwards."""
    from petsc4py import PETSc
    opts, added = PETSc.Options(), []

    def put(name, value=""):
        assert not opts.hasName(name)
        opts[name] = value
        added.append(name)

    yield put
    for name in added:
        opts.delValue(name)


def test_used_flag_is_petscs(petsc_options):
    """compat.petsc_option_used reads PETSc's own flag: False until something asks."""
    from petsc4py import PETSc

    from rawehelix import compat
    petsc_options("rawehelix_test_flag", "3")
    assert not compat.petsc_option_used("rawehelix_test_flag")
    assert PETSc.Options().getInt("rawehelix_test_flag") == 3
    assert compat.petsc_option_used("rawehelix_test_flag")


def test_check_refuses_unused_with_what_it_meant(petsc_options):
    from rawehelix.errors import SceneError
    from rawehelix.solvers import petsc_options as po
    petsc_options("rawehelix_snes_maxit", "5")  # a typo of -rawehelix_snes_max_it
    petsc_options("rawehelix_ts_snes_max_it", "7")  # the dynamics' Newton solver reads it
    with pytest.raises(SceneError) as err:
        po.check("error", ("--elements",))
    text = str(err.value)
    assert "-rawehelix_snes_maxit (did you mean -rawehelix_snes_max_it" in text
    assert "rawehelix_ts_snes_max_it" not in text.split("(did you mean")[0]
    assert "--petsc-unused warn" in text


def test_check_warn_only(petsc_options, caplog):
    from rawehelix.solvers import petsc_options as po
    petsc_options("rawehelix_elemnts", "4")
    po.check("warn")
    assert "-rawehelix_elemnts" in caplog.text and "no solver of rawehelix reads" in caplog.text


@pytest.mark.parametrize("name,value,reason", [
    ("rawehelix_snes_type", "nonexistent", "Unable to find requested SNES type nonexistent"),
    ("rawehelix_ksp_rtol", "abc", "Input string abc has no numeric value"),
    ("rawehelix_pep_type", "nonexistent", "nonexistent"),
])
def test_check_refuses_bad_values_with_petscs_reason(petsc_options, name, value, reason):
    from rawehelix.errors import SceneError
    from rawehelix.solvers import petsc_options as po
    petsc_options(name, value)
    with pytest.raises(SceneError) as err:
        po.check()
    assert f"-{name} {value}: " in str(err.value) and reason in str(err.value)
    assert "\n" not in str(err.value)


def test_viewers_are_left_to_the_end_of_the_run(petsc_options):
    """-..._converged_reason is read by a solve, not a set-up: passed by the check,
    listed by left_after_run until a solver reads it."""
    from petsc4py import PETSc

    from rawehelix import compat
    from rawehelix.solvers import petsc_options as po
    petsc_options("rawehelix_ts_snes_converged_reason")
    petsc_options("rawehelix_snes_maxit", "5")  # warned before the work, not again
    po.check("warn")
    # PETSc 3.18 reads it in the solve; later ones (3.22, Debian 13) already in the set-up
    read_at_setup = compat.petsc_option_used("rawehelix_ts_snes_converged_reason")
    assert po.left_after_run() == ([] if read_at_setup else ["rawehelix_ts_snes_converged_reason"])
    PETSc.Options().hasName("rawehelix_ts_snes_converged_reason")  # as TSSolve's SNES does
    assert "rawehelix_ts_snes_converged_reason" not in po.left_after_run()
