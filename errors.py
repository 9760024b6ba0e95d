"""The errors a user of rawehelix meets: bad input, a failed solve, an output file
not written (no heavy imports: importable anywhere)."""


class SceneError(ValueError):
    """Bad input: ``file (or command): key: what is allowed``.  The command
    line prints it and exits with status 2 before anything is written."""

    def __init__(self, path, key: str, allowed: str):
        self.path, self.key, self.allowed = str(path), key, allowed
        # a key as typed may hold a newline or another control character (a quoted
        # TOML key, --set): shown escaped, so that the message stays one line
        shown = key if str(key).isprintable() else repr(key)
        super().__init__(f"{self.path}: {shown}: {allowed}")


class SolverError(RuntimeError):
    """A solve failed; the message says what, where and what to try."""


class OutputFault(OSError):
    """A file of the output folder could not be written (exit status 1)."""

    @classmethod
    def of(cls, err: OSError, path) -> "OutputFault":
        """``err`` (raised writing ``path``) as an OutputFault; one already is one."""
        if isinstance(err, OutputFault):
            return err
        return cls(err.errno, err.strerror or str(err), str(err.filename or path))

    def __str__(self):
        return (f"{self.filename}: not written: {self.strerror} (errno {self.errno}); "
                f"free space or use another -o directory, then run the same command again "
                f"(every point stored so far is kept)")


# -- Ctrl-C ------------------------------------------------------------------------------
# petsc4py >= 3.19 turns a KeyboardInterrupt raised inside a Python callback of a PETSc
# solve (the residual, a monitor) into a PETSc error (code -1), which a solver would
# report as a failed solve.  The command line's SIGINT handler records the interrupt
# here, so that a solver that catches a PETSc error raises the interrupt instead.
_interrupted = False


def on_sigint(signum, frame):
    """SIGINT handler: record the interrupt, then interrupt as Python does."""
    global _interrupted
    _interrupted = True
    raise KeyboardInterrupt


def reraise_if_interrupted():
    """Raise KeyboardInterrupt if Ctrl-C came (on_sigint): a PETSc error after it is
    the interrupt, not a failed solve."""
    if _interrupted:
        raise KeyboardInterrupt
