"""One writer per output folder (issue 27): an exclusive lock on ``OUTDIR/.lock``.

A run takes the lock (:func:`hold`) before it reads any stored state and keeps
it until it has written its last file.  The lock is ``fcntl.flock`` on
``OUTDIR/.lock``, whose text names the holder (pid, host, start); the kernel
releases it when the holder dies, so a run killed with SIGKILL never blocks
the next one (its ``.lock`` file stays, and is taken over).  A second run into
a held folder gets :class:`FolderBusy` at once: bad input, exit status 2,
naming the folder and the holder.  The lock is not reentrant across
processes but is within one: the command line holds it around the whole
command (cli/main.py) and the stores, which also lock for callers of the
Python API, only count up.  Under MPI rank 0 holds it and the other ranks
learn the verdict by a broadcast.

Taking the lock removes the temporary files a killed run left behind
(:func:`rawehelix.studies.store.writers.remove_stale_temps`).  Releasing it
removes ``.lock``, and the folders the lock made (the -o folder, results/<scene>) if they stayed
empty (bad input found after the lock was taken writes nothing).

One command per output folder: the command line names its command when
it takes the lock (:func:`hold`'s ``command``), and a folder whose marker
``OUTDIR/.rawehelix-command`` names another command (or, written before the
marker existed, holds another command's header file: :data:`HEADERS`) is refused
at once (bad input, exit status 2: use another -o), so that no command
overwrites another's summary.json.  The marker is written as the lock is let go,
if the folder then holds anything (a refusal found later writes nothing, and
leaves no marker).

A write that fails for the disk's sake (full, read-only, over quota) is an
:class:`OutputFault`: one line naming the folder, the file and the fault;
the command line exits with status 1 (the input was good: free space and run
the same command again, which resumes and keeps every stored point).
"""

from __future__ import annotations

import errno
import fcntl
import os
import socket
import time
import weakref
from pathlib import Path

from rawehelix.errors import OutputFault, SceneError  # noqa: F401  (OutputFault re-exported)

LOCK = ".lock"
OWNER = ".rawehelix-command"  # the command whose output the folder holds
#: the header file of a resumable command's store, for folders written before OWNER
HEADERS = {"sweep.json": "sweep", "orbits.json": "orbits", "envelope.json": "envelope"}
#: the errors of a disk, not of the program: turned into OutputFault by :func:`hold`
DISK_ERRNOS = (errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EFBIG)
_held: dict[Path, list] = {}  # folder -> [fd, count, the folders made (deepest first), command]


class FolderBusy(SceneError):
    """Another run holds the output folder (exit status 2)."""

    def __init__(self, folder, holder: str):
        self.folder, self.holder = str(folder), holder
        super().__init__("-o", self.folder, f"is in use by another run ({holder}); wait for "
                                            f"it to end or use another -o directory")



def _holder_of(path: Path) -> str:
    """The holder's own words in ``.lock`` (it may not have written them yet)."""
    for _ in range(20):
        try:
            text = path.read_text().strip()
        except OSError:
            text = ""
        if text:
            return text
        time.sleep(0.01)
    return "a process that has not yet written its name into .lock"


def owner(folder: Path) -> str | None:
    """The command whose output ``folder`` holds: its marker's, else (an older folder)
    its store's header file's (:data:`HEADERS`); None if it holds none."""
    try:
        return (folder / OWNER).read_text().strip() or None
    except OSError:
        pass
    return next((command for name, command in HEADERS.items() if (folder / name).exists()),
                None)


def _refuse_another(folder: Path, command: str):
    """SceneError if ``folder`` holds another command's output."""
    other = owner(folder)
    if other is not None and other != command:
        raise SceneError("-o", str(folder),
                         f"holds the output of 'rawehelix {other}' (its summary.json would be "
                         f"overwritten); use another -o directory for '{command}'")


def _take(folder: Path, command: str | None = None):
    """Lock ``folder`` on this process (reentrant), refusing another ``command``'s
    folder: raises FolderBusy, SceneError or OutputFault."""
    if folder in _held:
        _held[folder][1] += 1
        if command is not None:
            _held[folder][3] = command
        return
    made = _missing(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise SceneError("-o", str(folder), "is a file, not a directory") from None
    except OSError as err:
        raise OutputFault.of(err, folder) from err
    path = folder / LOCK
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as err:
            raise OutputFault.of(err, path) from err
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise FolderBusy(folder, _holder_of(path)) from None
        # the last holder unlinks .lock as it lets go: the file just locked may be gone
        try:
            same = os.stat(path).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    if command is not None:
        try:
            _refuse_another(folder, command)
        except SceneError:
            try:
                os.unlink(path)  # while still held, as _let_go: the folder as it was
            except OSError:
                pass
            os.close(fd)
            raise
    try:
        os.ftruncate(fd, 0)
        os.write(fd, f"pid {os.getpid()} on host {socket.gethostname()}, since "
                     f"{time.strftime('%Y-%m-%d %H:%M:%S %Z')}\n".encode())
        from rawehelix.studies.store import writers
        writers.remove_stale_temps(folder)
    except OSError as err:
        os.close(fd)
        raise OutputFault.of(err, path) from err
    _held[folder] = [fd, 1, made, command]


def _let_go(folder: Path):
    entry = _held.get(folder)
    if entry is None:
        return
    entry[1] -= 1
    if entry[1] > 0:
        return
    fd, _, made, command = _held.pop(folder)
    if command is not None and not (folder / OWNER).exists():
        try:
            if any(p.name != LOCK for p in folder.iterdir()):  # the command wrote something
                (folder / OWNER).write_text(command + "\n")
        except OSError:
            pass  # a full disk: the run's own fault is the one reported
    try:
        os.unlink(folder / LOCK)  # while still held: see _take
    except OSError:
        pass
    os.close(fd)
    for made_dir in made:  # -o's folder, then the parents it needed (results/<scene>)
        try:
            made_dir.rmdir()  # only if empty: nothing was written
        except OSError:
            break


def _missing(folder: Path) -> list[Path]:
    """The folders that making ``folder`` creates, deepest first."""
    missing = []
    while not folder.exists() and folder != folder.parent:
        missing.append(folder)
        folder = folder.parent
    return missing


class Holding:
    """The lock of one folder as long as this object lives (or until
    :meth:`release`); a context manager that also turns a disk's OSError
    raised inside it into an :class:`OutputFault`."""

    def __init__(self, folder: Path, locked: bool):
        self.folder = folder
        self._release = weakref.finalize(self, _let_go, folder) if locked else None

    def release(self):
        if self._release is not None:
            self._release()

    def __enter__(self):
        return self

    def __exit__(self, kind, err, tb):
        self.release()
        if isinstance(err, OSError) and not isinstance(err, OutputFault) \
                and err.errno in DISK_ERRNOS:
            raise OutputFault.of(err, err.filename or self.folder) from err
        return False


def hold(folder, comm=None, command: str | None = None) -> Holding:
    """Take the lock of the output folder ``folder`` (collective on ``comm``:
    rank 0 takes it, every rank gets its verdict) for ``command`` (the command line's:
    a folder holding another command's output is refused; None: the stores' own,
    reentrant holds).  Raises :class:`FolderBusy` (another run holds it),
    :class:`OutputFault` or SceneError (it cannot be made, or holds another
    command's output) on every rank."""
    folder = Path(os.path.abspath(folder))
    rank = 0 if comm is None else comm.rank
    verdict = None
    if rank == 0:
        try:
            _take(folder, command)
        except FolderBusy as err:
            verdict = ("busy", err.folder, err.holder)
        except OutputFault as err:
            verdict = ("fault", err.errno, err.strerror, err.filename)
        except SceneError as err:
            verdict = ("bad", err.path, err.key, err.allowed)
    if comm is not None and comm.size > 1:
        verdict = comm.bcast(verdict, root=0)
    if verdict is None:
        return Holding(folder, locked=rank == 0)
    kind, *args = verdict
    raise {"busy": FolderBusy, "fault": OutputFault, "bad": SceneError}[kind](*args)
