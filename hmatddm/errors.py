"""Error types of hmatddm.

Every error a user can trigger derives from :class:`HmatddmError`, so scripts can catch
one type; the subclasses also derive from the matching built-in (``ValueError``,
``RuntimeError``) so ordinary ``except ValueError`` keeps working.
"""


class HmatddmError(Exception):
    """Base class of every error raised on purpose by hmatddm."""


class InputError(HmatddmError, ValueError):
    """Invalid user input; the message names the field and its allowed range."""


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
