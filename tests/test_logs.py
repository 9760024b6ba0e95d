"""studies.logs: one handler on stderr, and no JIT-compiler chatter on a cold
form cache unless -vv.  Each test runs a fresh interpreter with its own empty
XDG_CACHE_HOME (the form cache of FFCx), so the forms really compile."""

import os
import subprocess
import sys
import textwrap

import pytest

# A small form compiled on the cold cache, and one message at each level.
SMALL_FORM = """
import sys
from rawehelix.studies import logs
logs.configure(int(sys.argv[1]))
import logging
import ufl
from mpi4py import MPI
from dolfinx import fem, mesh
from rawehelix import compat
log = logging.getLogger("rawehelix.test")
log.info("an info message")
log.debug("a debug message")
log.warning("a warning")
domain = mesh.create_unit_interval(MPI.COMM_SELF, 2)
V = compat.scalar_space(domain, "Lagrange", 1)
u = fem.Function(V)
fem.form(u * u * ufl.dx)
"""


def _run(code, tmp_path, *args):
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache")}
    result = subprocess.run([sys.executable, "-c", textwrap.dedent(code), *args], env=env,
                            capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "cache" / "fenics").is_dir()  # the forms compiled there
    return result.stderr.splitlines()


@pytest.mark.parametrize("verbosity,expected", [
    (0, ["rawehelix: an info message", "rawehelix: a warning"]),  # our progress, by default
    (1, ["rawehelix: an info message", "rawehelix: a debug message", "rawehelix: a warning"]),
])
def test_levels_without_jit_chatter(tmp_path, verbosity, expected):
    assert _run(SMALL_FORM, tmp_path, str(verbosity)) == expected


def test_vv_shows_the_compiler(tmp_path):
    err = _run(SMALL_FORM, tmp_path, "2")
    assert err[:3] == ["rawehelix: an info message", "rawehelix: a debug message",
                       "rawehelix: a warning"]
    assert all(line.startswith("rawehelix: ") for line in err)
    from rawehelix import compat
    if not compat.NEW:  # DOLFINx 0.5's FFCx logs the C compiler's command lines (0.9's does not)
        assert any("gcc" in line for line in err)


@pytest.mark.long  # make test's budget (make test-long runs it)
def test_stationary_on_a_cold_cache_prints_nothing_on_stderr(tmp_path):
    """The whole `stationary` command (every form of the rod) on a cold cache:
    the summary on stdout, nothing on stderr."""
    code = f"""
    import sys
    from rawehelix.cli import main as cli
    from rawehelix.studies import logs
    logs.configure(0)
    sys.exit(cli.main(["stationary", "stationary_table2", "--elements", "4",
                       "-o", {str(tmp_path / "out")!r}]))
    """
    assert _run(code, tmp_path) == []
    assert (tmp_path / "out" / "summary.json").is_file()


def test_a_killed_compilation_does_not_hold_up_the_next_run():
    """FFCx's lock of a compilation (the exclusive C file) left by a process killed
    while it compiled is set aside once it is older than compat.JIT_STALE_S, so
    that the next run (a study resumed after SIGKILL) compiles instead of waiting
    for it and failing; a fresh lock, or one with its result, is left alone."""
    import os
    import time
    from pathlib import Path

    from rawehelix import compat

    cache = Path(compat.jit_options()["cache_dir"])
    cache.mkdir(parents=True, exist_ok=True)
    tag = f"libffcx_forms_test{os.getpid()}"
    dead, live, done = (cache / f"{tag}{k}.c" for k in ("dead", "live", "done"))
    for path in (dead, live, done):
        path.write_text("")
    done.with_suffix(".c.cached").write_text("")
    old = time.time() - 2 * compat.JIT_STALE_S
    for path in (dead, done):
        os.utime(path, (old, old))
    try:
        cleared = compat.clear_stale_jit_locks()
        assert dead in cleared and live not in cleared and done not in cleared
        assert dead.with_suffix(".c.stale").exists() and live.exists() and done.exists()
    finally:
        for path in cache.glob(f"{tag}*"):
            path.unlink()
