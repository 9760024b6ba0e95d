"""The two errors a user of rawehelix meets (no heavy imports: importable anywhere)."""


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
