"""Solves with a matrix that grows by a few rows and columns at a time, factored level by
level (block elimination by Schur complements), so that bordering it by ``b`` unknowns
costs O(s^2 b) instead of a new O((s + b)^3) factorisation.

Used for the ``A_nn`` block of a grown mesh's operator (:mod:`hmatddm.elasticity.extended`)
and for the contact-modified base ``S_0 A + D_0`` of one step's growth passes
(:mod:`hmatddm.coupled.contact_factor`).
"""
import numpy as np
import scipy.linalg


class GrowingBlockLU:
    """Solves with a matrix ``M`` (the ``A_nn`` of a grown mesh) factored level by level:
    when ``M`` gains rows and columns ``s:e`` (a growth pass's elements), the factors of
    ``M[:s, :s]`` are kept and the level adds ``R = M[s:e, :s]``, ``H = M[:s, :s]^-1
    M[:s, s:e]`` and the inverse of the Schur complement ``S = M[s:e, s:e] - R H`` (a
    growth pass's few elements: a small dense block; an explicit inverse makes a level
    three matrix-vector products, without the per-call cost of an LU solve). A solve runs
    the levels in order: ``y[s:e] = S^-1 (r[s:e] - R y[:s])``, ``y[:s] -= H y[s:e]`` keeps
    ``y[:e] = M[:e, :e]^-1 r[:e]`` (block elimination without pivoting between levels,
    which suits the diagonally dominant DDM blocks). Adding ``b`` unknowns to ``s`` costs
    O(s^2 b) instead of the O((s + b)^3) of a new LU.

    ``kept``: the levels of an earlier ``GrowingBlockLU`` whose matrix is ``M[:s, :s]``
    (from :meth:`prefix`), or None. ``pivoted_first``: the first level (a whole matrix, not
    a border) as a partially pivoted LU instead of an explicit inverse (a large first block:
    the contact base of :mod:`hmatddm.coupled.contact_factor`)."""

    def __init__(self, matrix, kept=None, pivoted_first=False):
        self.levels = list(kept or [])
        start = self.levels[-1][1] if self.levels else 0
        size = matrix.shape[0]
        if start < size:
            coupling = matrix[:start, start:]
            solved = self.solve(coupling) if start else None
            rows = matrix[start:, :start] if start else None
            schur = matrix[start:, start:] - rows @ solved if start else matrix
            if pivoted_first and not start:
                factor = scipy.linalg.lu_factor(schur, check_finite=False)
            else:
                factor = np.linalg.inv(schur)
            self.levels.append((start, size, rows, solved, factor))

    def prefix(self, size):
        """The levels that factor ``M[:size, :size]`` whole (a shared run of unknowns)."""
        return [level for level in self.levels if level[1] <= size]

    def solve(self, r):
        """``M^-1 r`` (``r``: a vector or a matrix of columns)."""
        return self.continue_solve(np.array(r, dtype=np.float64), 0)

    def continue_solve(self, y, solved):
        """``M^-1 r`` in place in ``y``, whose first ``solved`` rows already hold ``M[:solved,
        :solved]^-1 r[:solved]`` (``solved``: a level's start; 0: a whole solve) and the rest
        ``r[solved:]``: only the levels from ``solved`` on run (a solution bordered by a
        growth pass's rows). Returns ``y``."""
        for start, stop, rows, solved_block, factor in self.levels:
            if start < solved:
                continue
            if start:
                y[start:stop] -= rows @ y[:start]
            if isinstance(factor, tuple):
                y[start:stop] = scipy.linalg.lu_solve(factor, y[start:stop], check_finite=False)
            else:
                y[start:stop] = factor @ y[start:stop]
            if start:
                y[:start] -= solved_block @ y[start:stop]
        return y
