"""What the command line prints, made plain: no reST markup, no negative zero.

The help reuses the modules' docstrings, written for Sphinx (``:mod:`x```,
````x````); a terminal shows their contents only.  A number that rounds to
zero prints without a sign (``0.0000``, not ``-0.0000``), whichever format
made it: every result line passes :func:`printable` (``base.say``).
"""

from __future__ import annotations

import re

#: a reST role or literal: :mod:`x`, :py:func:`~a.b`, :ref:`text <target>`, ``x``
_REST = re.compile(r"(?::[a-z]+)?:[a-z]+:`~?([^`<]*?)(?: <[^`]*>)?`|``([^`]+)``")
#: a minus before a number whose digits are all 0 (-0, -0.0000, -0.00e+00), not
#: inside a word, a number or an option (1e-0, 2-0, --0)
_NEGATIVE_ZERO = re.compile(r"(?<![\w.\-])-(0(?:\.0*)?(?:[eE][+-]?\d+)?)(?![\w.])")


def plain(text: str) -> str:
    """Help text without reST markup: the roles' and literals' contents only."""
    return _REST.sub(lambda m: m.group(1) if m.group(1) is not None else m.group(2), text)


def printable(text: str) -> str:
    """``text`` with every negative zero printed as zero; in a padded column
    (two spaces before it) the sign's place is kept, so the column stays aligned."""
    def unsigned(m: re.Match) -> str:
        padded = m.start() >= 2 and text[m.start() - 2:m.start()] == "  "
        return (" " if padded else "") + m.group(1)
    return _NEGATIVE_ZERO.sub(unsigned, text)
