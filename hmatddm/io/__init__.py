"""File output that other programs read: VTK XML for ParaView, written atomically.

* :func:`write_vtu`: one mesh with per-element fields (``.vtu``, unstructured grid).
* :func:`write_pvd`: a time collection of ``.vtu`` files (``.pvd``), for ParaView's
  time slider.
* :func:`read_vtu`, :func:`read_pvd`: read them back (for tests and post-processing).
* :func:`atomic_output`: the write-to-a-temporary-then-rename helper every writer uses,
  so that a reader (or a crash) never sees a half-written file, and a failed write (a
  full disk, a folder that is not writable) raises :class:`~hmatddm.errors.OutputError`
  naming the file, its folder and the reason, with the previous file left intact.
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


from .vtk import read_pvd, read_vtu, write_pvd, write_vtu  # noqa: E402  (vtk uses atomic_output)

__all__ = ["write_vtu", "write_pvd", "read_vtu", "read_pvd", "atomic_output", "OutputError"]
