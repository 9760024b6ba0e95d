"""studies.argv.split against the real command-line parser: PETSc's
``-option value`` next to our options, positionals and subcommands."""

import argparse

import pytest

from rawehelix.studies import argv, cli

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
    # --count is modes' own: for stationary it is PETSc's (and PETSc reports it unused)
    (S + ["--count", "4"], S, ["--count", "4"]),
])
def test_split(tokens, ours, petsc):
    assert argv.split(tokens, cli._parser()) == (ours, petsc)


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
