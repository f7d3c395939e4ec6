"""Atomic file output: write to a temporary file in the same folder, then rename, so that
a reader (or a crash) never sees a half-written file; a failed write raises
:class:`~hmatddm.errors.OutputError` naming the file, its folder and the reason.
"""
import contextlib
import os
import secrets
from pathlib import Path

from ..errors import HmatddmError, OutputError


def _new_temporary(path):
    """Create an empty, uniquely named hidden file next to ``path``.

    Unlike ``tempfile.mkstemp`` (mode 0600) the file gets the ordinary permissions
    (0666 less the umask), which the final file inherits after the rename.
    """
    while True:
        temporary = path.with_name(f".{path.name}.{secrets.token_hex(6)}.tmp")
        try:
            os.close(os.open(temporary, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666))
        except FileExistsError:
            continue
        return temporary


@contextlib.contextmanager
def atomic_output(path):
    """Context manager yielding a temporary :class:`~pathlib.Path` in the folder of
    ``path``; on a clean exit the temporary file replaces ``path`` (``os.replace``,
    atomic on POSIX and Windows), on an exception it is removed and ``path`` is left
    untouched. The folder is created if missing.

    An ``OSError`` while creating the folder, writing or renaming (``ENOSPC``: the disk
    is full; ``EACCES``: not writable) is raised as :class:`~hmatddm.errors.OutputError`
    (itself an ``OSError``) whose message names ``path``, its folder and the reason.

    Example::

        with atomic_output("out/summary.json") as temporary:
            temporary.write_text(text)
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        temporary = _new_temporary(path)
    except OSError as error:
        raise OutputError.from_os_error(error, path) from error
    try:
        yield temporary
        os.replace(temporary, path)
    except BaseException as error:
        try:
            temporary.unlink(missing_ok=True)
        except OSError:
            pass
        if isinstance(error, OSError) and not isinstance(error, HmatddmError):
            raise OutputError.from_os_error(error, path) from error
        raise


__all__ = ["atomic_output"]
