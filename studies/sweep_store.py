"""Moved to :mod:`rawehelix.studies.store.sweep_store`.  This alias stays only while branch
i42-runs edits studies/sweep.py and studies/orbits.py, which import this path; once it
is merged they import the new path and this file goes (issue 42)."""

import sys

from rawehelix.studies.store import sweep_store as _moved

sys.modules[__name__] = _moved
