"""Moved to :mod:`rawehelix.studies.analysis.branch_limits`.  This alias stays only while branch
i42-runs edits studies/sweep.py and studies/orbits.py, which import this path; once it
is merged they import the new path and this file goes (issue 42)."""

import sys

from rawehelix.studies.analysis import branch_limits as _moved

sys.modules[__name__] = _moved
