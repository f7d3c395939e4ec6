"""Error types of hmatddm.

Every error a user can trigger derives from :class:`HmatddmError`, so scripts can catch
one type; the subclasses also derive from the matching built-in (``ValueError``,
``RuntimeError``) so ordinary ``except ValueError`` keeps working.
"""


class HmatddmError(Exception):
    """Base class of every error raised on purpose by hmatddm."""


class InputError(HmatddmError, ValueError):
    """Invalid user input; the message names the field and its allowed range."""


class SizeLimitError(InputError):
    """A growing simulation would pass its element limit (``max_elements`` of
    :class:`hmatddm.Simulation`, ``numerics.max_elements`` of a scene). Raised before the
    step is accepted: the state (and the newest checkpoint) is the last finished step, so a
    run can continue with a higher limit. ``elements`` is the count the step reached,
    ``limit`` the limit."""

    def __init__(self, message, elements=0, limit=0):
        super().__init__(message)
        self.elements = elements
        self.limit = limit


class ConvergenceError(HmatddmError, RuntimeError):
    """An iterative solver did not reach its tolerance.

    Attributes
    ----------
    residual : float
        Relative residual reached when the solver stopped.
    iterations : int
        Iterations performed.
    """

    def __init__(self, message, residual=float("nan"), iterations=0):
        super().__init__(message)
        self.residual = residual
        self.iterations = iterations


class OutputError(HmatddmError, OSError):
    """An output file could not be written: the disk is full, the folder is not
    writable, the file system is read-only. The message names the file and its folder.

    Derives from ``OSError`` too, so ``except OSError`` keeps working.

    Attributes
    ----------
    path : str or None
        The file that could not be written.
    errno : int or None
        The system's error number (``errno.ENOSPC`` for a full disk).
    """

    def __init__(self, message, path=None, errno=None):
        super().__init__(message)
        self.path = None if path is None else str(path)
        self.errno = errno

    @property
    def disk_full(self):
        """Whether the disk (or the user's quota on it) is full."""
        import errno

        return self.errno in (errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC))

    @staticmethod
    def describe(error, folder):
        """Why ``error`` (an OSError) stopped a write into ``folder``, in words."""
        import errno as codes

        folder = str(folder)
        code = getattr(error, "errno", None)
        if code == codes.ENOSPC:
            return f"no space left on the disk holding {folder!r} (the disk is full)"
        if code == getattr(codes, "EDQUOT", None):
            return f"the disk quota for {folder!r} is exhausted (the disk is full for this user)"
        if code in (codes.EACCES, codes.EPERM):
            return f"{folder!r} is not writable (permission denied)"
        if code == codes.EROFS:
            return f"{folder!r} is on a read-only file system"
        return error.strerror or str(error)

    @classmethod
    def from_os_error(cls, error, path, what=None):
        """The OutputError for ``error`` (an OSError) raised while writing ``path``;
        ``what`` names the file in the message (default: its path)."""
        from pathlib import Path

        path = Path(path)
        reason = cls.describe(error, path.parent)
        return cls(f"could not write {what or str(path)}: {reason}", path=path,
                   errno=getattr(error, "errno", None))


class MeshQualityWarning(UserWarning):
    """The mesh is valid but too coarse for its geometry: the constant-DD solution can
    be wrong there (e.g. two fractures closer than their elements resolve, see
    :func:`hmatddm.mesh.close_parallel_pairs`). The message names the elements and the
    element size that fixes it. Turn it into an error with
    ``warnings.simplefilter("error", hd.errors.MeshQualityWarning)``."""


class NoInjectionWarning(UserWarning):
    """Every cluster injects at rate 0: nothing drives the fractures, which only relax
    from their initial pressure (a scene without a [reference] would otherwise start
    such a run silently)."""
