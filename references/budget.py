"""A wall-time budget for the references' integrations (the shooting of Sys. (67)
where it serves as a check or a first guess): inside :func:`budget`, every right
side that :func:`watched` wraps stops with :class:`OverBudget` once the time is
spent, so a stiff scene whose steps shrink without end stops too."""

from __future__ import annotations

import contextlib
import time

__all__ = ["OverBudget", "budget", "watched"]


class OverBudget(Exception):
    """A shooting solve ran past the wall time of :func:`budget` (not a RuntimeError:
    the solvers' own "did not converge" handling lets it through)."""


_DEADLINE = [None]  # perf_counter() past which an integration stops: set by budget()


@contextlib.contextmanager
def budget(seconds: float):
    """Every shooting solve inside the block stops with :class:`OverBudget` once
    ``seconds`` of wall time have passed (checked at each evaluation of the right
    side, so a stiff scene whose steps shrink without end stops too)."""
    outer = _DEADLINE[0]
    _DEADLINE[0] = time.perf_counter() + seconds
    try:
        yield
    finally:
        _DEADLINE[0] = outer


def watched(f):
    """``f`` stopped at the budget in force (``f`` itself outside any budget)."""
    deadline = _DEADLINE[0]
    if deadline is None:
        return f

    def g(s, y):
        if time.perf_counter() > deadline:
            raise OverBudget("stopped at its time budget")
        return f(s, y)
    return g
