"""Split a command line into our arguments and PETSc's options.

PETSc's own syntax is ``-option value`` (or a bare ``-flag``), which argparse
cannot tell from a stray positional: ``parse_known_args`` leaves the value
``bt`` of ``-rawehelix_snes_linesearch_type bt`` as an unexpected argument.
:func:`split` walks the tokens with the parser's own tables instead:

- an option our parser knows (exactly, ``--long=value``, or an unambiguous
  prefix of a ``--long`` option, as argparse allows) is ours, with as many
  values as its action takes;
- a subcommand name switches to that subcommand's options;
- short flags run together (``-vv``) are ours;
- any other ``--word`` is refused (:class:`ArgvError`): PETSc's options have
  one dash, so a double dash is always meant for us (``--elemnts`` a typo);
- a single-dash token that is one of our options but for case and dashes
  (``-O``, ``-output``, ``-Elements``) is refused too, naming ours;
- any other token that starts with ``-`` (and is not a number) starts a
  PETSc option; the token after it is its value when it does not start with
  ``-`` or is a number (``-1``, ``-1e-3``).  Whether PETSc uses it is
  checked later (:mod:`rawehelix.solvers.petsc_options`);
- an ambiguous prefix of our ``--long`` options is ours (argparse reports it);
- any other token is one of our positionals.

So our positionals must come before the PETSc options: in
``stationary -rawehelix_snes_monitor SCENE`` the scene is taken as the
monitor's value.  Our options may go anywhere.  Single-dash options are
matched exactly, never as ``-oDIR``, so that ``-options_file`` stays PETSc's.
"""

from __future__ import annotations

import argparse
import difflib

from rawehelix.errors import SceneError


class ArgvError(SceneError):
    """An option of ours mistyped: ``command: token: did you mean ...``."""


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _is_option(token: str) -> bool:
    return token.startswith("-") and token != "-" and not _is_number(token)


def _lookup(parser: argparse.ArgumentParser, token: str) -> list[argparse.Action]:
    """The actions that our option ``token`` (without any ``=value``) may
    name: one, none, or several for an ambiguous prefix."""
    options = {s: a for a in parser._actions for s in a.option_strings}
    if token in options:
        return [options[token]]
    if token.startswith("--") and parser.allow_abbrev:
        return list({a: None for s, a in options.items() if s.startswith(token)})
    return []


def _normal(token: str) -> str:
    """An option as a user may mean it: no dashes, any case, '-' and '_' alike."""
    return token.lstrip("-").lower().replace("_", "-")


def _short_flags(parser: argparse.ArgumentParser, token: str) -> bool:
    """``-vv``: short options without a value, run together (argparse takes them)."""
    flags = {s for a in parser._actions if a.nargs == 0 for s in a.option_strings
             if len(s) == 2 and s[0] == "-" and s[1] != "-"}
    return (len(token) > 2 and token[0] == "-" and token[1] != "-"
            and all("-" + c in flags for c in token[1:]))


def _refuse(parser: argparse.ArgumentParser, name: str):
    """Raise ArgvError for ``name``, a mistyped option of ours, or return when
    it is none (a PETSc option)."""
    ours = option_strings(parser)
    by_normal = {}
    for s in ours:  # the long spelling of each option first
        by_normal.setdefault(_normal(s), s)
    meant = by_normal.get(_normal(name))
    if meant is None and not name.startswith("--"):
        return  # a PETSc option (checked when the solvers are set up)
    if meant is None:
        close = difflib.get_close_matches(_normal(name), list(by_normal), n=3, cutoff=0.6)
        meant = " or ".join(by_normal[c] for c in close)
    commands = _subcommands(parser)
    hint = (f"did you mean {meant}?" if meant
            else f"the command comes first: {', '.join(commands)}" if commands
            else "known: " + ", ".join(s for s in ours if s.startswith("--")))
    raise ArgvError(parser.prog.split()[-1], name, f"is not an option of this command; {hint} "
                    "(PETSc options have one dash: -rawehelix_snes_monitor)")


def option_strings(parser: argparse.ArgumentParser, command: str | None = None) -> list[str]:
    """The options of ``parser`` (of its subcommand ``command`` if given), for "did you mean"."""
    parser = _subcommands(parser).get(command, parser)
    return [s for a in parser._actions for s in a.option_strings if s not in ("-h", "--help")]


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _values_taken(action: argparse.Action, rest: list[str]) -> int:
    """How many of the tokens ``rest`` after our option are its values: as
    argparse, never one that looks like an option (it then reports the
    missing value itself)."""
    if action.nargs in (None, "?"):
        most = 1
    elif isinstance(action.nargs, int):
        most = action.nargs
    else:  # '*', '+', ...
        most = len(rest)
    n = 0
    while n < min(most, len(rest)) and not _is_option(rest[n]):
        n += 1
    return n


def split(argv: list[str], parser: argparse.ArgumentParser) -> tuple[list[str], list[str]]:
    """``(ours, petsc)``: the tokens of ``argv`` that ``parser`` knows (its
    options with their values, its subcommands and positionals, in order) and
    the PETSc options with their values (in order).  Positionals must come
    before the PETSc options (see the module docstring).

    ``parser.parse_args(ours)`` then parses our part strictly, and ``petsc``
    goes to ``petsc4py.init``.  Raises :class:`ArgvError` for an option of
    ours mistyped (see the module docstring).
    """
    ours: list[str] = []
    petsc: list[str] = []
    current = parser
    i = 0
    while i < len(argv):
        token = argv[i]
        if token == "--":  # argparse: everything after it is positional
            ours += argv[i:]
            break
        if _is_option(token):
            name, has_value, _ = token.partition("=")
            actions = _lookup(current, name)
            if actions:  # several: an ambiguous prefix, which argparse reports
                n = 0 if has_value or len(actions) > 1 else _values_taken(actions[0], argv[i + 1:])
                ours += argv[i:i + 1 + n]
                i += 1 + n
                continue
            if _short_flags(current, name):
                ours.append(token)
                i += 1
                continue
            _refuse(current, name)
            petsc.append(token)
            if i + 1 < len(argv) and not _is_option(argv[i + 1]):
                petsc.append(argv[i + 1])
                i += 1
            i += 1
            continue
        ours.append(token)
        current = _subcommands(current).get(token, current)
        i += 1
    return ours, petsc
