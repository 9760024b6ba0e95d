"""The command line's text: plain help, a --version, no negative zero, and the
modes table's eigenvalue column says its scale."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from rawehelix.cli import main as cli_main
from rawehelix.cli.text import plain, printable


def _helps():
    """The --help of rawehelix and of each of its commands, as printed."""
    parser = cli_main._parser()
    yield "rawehelix", parser.format_help()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    for name, p in sub.choices.items():
        yield name, p.format_help()


MARKUP = re.compile(r":(mod|func|class|meth|attr|data|ref|doc|py):|``|:[a-z]+:`")


def test_no_help_shows_rest_markup():
    helps = dict(_helps())
    assert len(helps) > 10  # rawehelix and each command
    for name, text in helps.items():
        assert not MARKUP.search(text), (name, MARKUP.search(text).group(0))
    assert "rawehelix.api" in helps["rawehelix"]  # the role's content stays


@pytest.mark.parametrize("marked,shown", [
    (":mod:`rawehelix.api`", "rawehelix.api"),
    (":func:`~rawehelix.api.sweep`", "rawehelix.api.sweep"),
    (":py:class:`Parameters`", "Parameters"),
    (":ref:`the how-to <resume>`", "the how-to"),
    ("``stationary_table2``", "stationary_table2"),
])
def test_plain_strips_each_role(marked, shown):
    assert plain(f"see {marked}.") == f"see {shown}."


@pytest.mark.parametrize("printed,shown", [
    ("decay -0.0000 1/s", "decay 0.0000 1/s"),
    ("alpha = -0.00, -0", "alpha = 0.00, 0"),
    ("x -0.000e+00 m", "x 0.000e+00 m"),
    ("|-0.0|", "|0.0|"),
    ("-0.0001 -0.10 -1.0 1e-05 2-0 --0 -0.0.1 v-0", "-0.0001 -0.10 -1.0 1e-05 2-0 --0 -0.0.1 v-0"),
])
def test_no_negative_zero_is_printed(printed, shown):
    assert printable(printed) == shown
    for fmt in (".4f", ".2f", ".3e", ".1f", "g"):  # every format of -0.0 and of a tiny
        for value in (-0.0, -1e-12 if "f" in fmt else -0.0):  # negative that rounds to it
            assert printable(f"x {value:{fmt}} y") == f"x {0.0:{fmt}} y"
            assert printable(f"|{value:>12{fmt}}|") == f"|{0.0:>12{fmt}}|"  # a column stays aligned


def test_the_command_lines_results_pass_printable(capsys):
    from rawehelix.cli.commands.base import say

    class Rank0:
        rank = 0
    say(Rank0(), "decay -0.0000 1/s, twist -0.000 rad")
    assert capsys.readouterr().out == "decay 0.0000 1/s, twist 0.000 rad\n"


def test_version_names_rawehelix_dolfinx_and_petsc():
    proc = subprocess.run([sys.executable, "-m", "rawehelix.cli", "--version"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    import rawehelix
    assert re.fullmatch(rf"rawehelix {re.escape(rawehelix.__version__)} \(DOLFINx \d+\.\d+\.\d+, "
                        r"PETSc \d+\.\d+\.\d+, .*\)\n", proc.stdout), proc.stdout
    assert proc.stderr == ""


def test_the_modes_table_says_its_eigenvalue_scale():
    from rawehelix.studies import modes
    head = modes.format_table([]).splitlines()[0]
    assert "Eigenvalue x sqrt(L0/g)" in head
