"""The reference's correction of influence blocks near singular points (ref. Sec. 6.2.3).

Step 1 (NaN averaging) lives in each kernel's ``local_stress_corrected``, which knows the
element's geometry. Step 2, shared by every kernel, is :func:`scale_to_self`: ref. Eq. 6.11.
"""
from numba import njit


@njit(cache=True)
def scale_to_self(pair, limit):
    """Scale a d x d block in place so that its largest |entry| is at most ``limit``
    (``alpha`` times the largest |entry| of the source element's self block, Eq. 6.11)."""
    largest = 0.0
    for p in range(pair.shape[0]):
        for q in range(pair.shape[1]):
            largest = max(largest, abs(pair[p, q]))
    if largest > limit:
        factor = limit / largest
        for p in range(pair.shape[0]):
            for q in range(pair.shape[1]):
                pair[p, q] *= factor
