"""Small helpers that turn bad input into :class:`~hmatddm.errors.InputError` early.

Every message names the field and the allowed range, e.g.
``poisson_ratio must be in [0, 0.5), got 0.5``.
"""
import numpy as np

from .errors import InputError
from .settings import integer


def finite_scalar(name, value):
    """Return ``value`` as a float, refusing non-numbers, NaN and inf."""
    try:
        result = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a finite number, got {value!r}") from None
    if not np.isfinite(result):
        raise InputError(f"{name} must be a finite number, got {result}")
    return result


def positive_scalar(name, value):
    result = finite_scalar(name, value)
    if result <= 0.0:
        raise InputError(f"{name} must be > 0, got {result}")
    return result


#: ``positive_int(name, value, minimum=1, maximum=None)``: the one integer check,
#: :func:`hmatddm.settings.integer`, under the name the engine modules import.
positive_int = integer


def finite_array(name, value, shape=None, dtype=np.float64):
    """Convert to a float array, check finiteness and (optionally) the shape.

    ``shape`` may contain ``None`` for a free dimension, e.g. ``(None, 3)``.
    """
    try:
        array = np.array(value, dtype=dtype)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be an array of numbers") from None
    if shape is not None:
        ok = array.ndim == len(shape) and all(s is None or s == t for s, t in zip(shape, array.shape))
        if not ok:
            want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
            raise InputError(f"{name} must have shape {want}, got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name} must contain only finite numbers (found NaN or inf)")
    return array
