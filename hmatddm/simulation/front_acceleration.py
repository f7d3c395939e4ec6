"""Anderson acceleration of the asymptotic front's fixed point (:mod:`hmatddm.simulation.asymptotic`).

Within a time step the ribbon distances ``s`` solve ``s = g(s)``: a coupled solve with the
front at ``s``, then the universal asymptote inverted at the ribbon's openings. The plain
iteration ``s <- s + w (g(s) - s)`` converges linearly, and slowly where the front's
elements interact: 10-25 iterations a step on a 0.5 m radial K-vertex run, each a coupled
solve. Anderson acceleration (type II; Walker and Ni 2011, SIAM J. Numer. Anal. 49:1715)
takes the combination of the last ``memory`` iterates whose residuals ``f = g(s) - s``
cancel best,

    gamma = argmin || f_k - dF gamma ||,   s_(k+1) = s_k + f_k - (dS + dF) gamma,

with ``dS``, ``dF`` the differences of consecutive iterates and residuals. Safeguard: when
a residual is not smaller than the last one (a new element joined, a clip bit, or the
combination overshot), the history restarts and the caller takes its own relaxed step.

The history and the combination are :class:`hmatddm.coupled.acceleration.AndersonMixing`,
which the coupled schemes' iterates share.
"""
from ..coupled.acceleration import AndersonMixing

#: Iterates kept (the columns of dS and dF).
MEMORY = 4
#: Singular values of dF below this share of the largest are dropped from the least-squares
#: fit: nearly parallel residual differences would otherwise amplify round-off (and an
#: H-matrix's eps) into the combination.
RCOND = 1e-3


def front_mixing():
    """The Anderson history of one time step's front iteration (a new one each step): the
    shared :class:`hmatddm.coupled.acceleration.AndersonMixing` with this module's
    :data:`MEMORY` and :data:`RCOND`; its ``step(point, residual)`` is the step to add to
    ``point``, or None for the caller's own relaxed step."""
    return AndersonMixing(MEMORY, RCOND)


__all__ = ["front_mixing", "MEMORY", "RCOND"]
