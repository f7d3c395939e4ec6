"""Flat storage of an H-matrix: the layout of its blocks and the class that owns them
(:class:`BlockStorage`). Its parallel assembly is :mod:`.assembly`, its parallel matvec
:mod:`.matvec`.

Everything lives in a few flat arrays, in the PERMUTED ordering of the cluster trees
(tree position k holds original element ``permutation[k]``; unknown ``d*k + p``; a
rectangular matrix has a row tree with d_r unknowns per element and a column tree with
d_c, a square one the same tree and d for both):

* dense blocks (near field, plus far blocks whose low rank would not pay): element
  ranges ``dense_row_start/stop``, ``dense_col_start/stop`` (tree positions), values
  row-major in ``dense_values[dense_offset[b]:dense_offset[b+1]]``;
* low-rank blocks U V^T: element ranges as above, ``lowrank_rank``, U (m x k) and
  V (n x k) stored column by column (i.e. U^T and V^T row-major, so every matvec
  loop is a long contiguous dot product or axpy): the first ``lowrank_head[b]``
  columns in ``u_values[u_offset[b]:...]``, ``v_values[v_offset[b]:...]`` (float32
  or float64), the trailing ones (adaptive precision, :mod:`.factor_precision`) as
  int16 codes in ``u_fixed[u_fixed_offset[b]:...]``, ``v_fixed[v_fixed_offset[b]:...]``
  times one scale per column, ``u_scale[rank_offset[b] + q]``, ``v_scale[...]``;
* for the matvec, the row space is split into the leaf clusters ("segments"); each
  segment lists (CSR) the dense and low-rank blocks whose rows cover it, so threads
  own whole segments of y and never race.
"""

from dataclasses import dataclass

import numpy as np

from .factor_precision import factor_columns
from .matvec import _matmat_permuted, _matmat_serial


#: Names of the BlockStorage arrays holding low-rank factor entries.
_FACTOR_ARRAYS = ("u_values", "v_values", "u_fixed", "v_fixed", "u_scale", "v_scale")

# Block kinds recorded for every admissible block.
KIND_LOWRANK = 0
KIND_DENSE = 1
KIND_ZERO = 2


@dataclass
class BlockStorage:
    """Flat arrays of all blocks; see the module docstring for the layout."""

    dof: int
    n_elements: int
    col_dof: int
    n_col_elements: int
    dense_row_start: np.ndarray
    dense_row_stop: np.ndarray
    dense_col_start: np.ndarray
    dense_col_stop: np.ndarray
    dense_offset: np.ndarray
    dense_values: np.ndarray
    dense_is_near: np.ndarray
    lowrank_row_start: np.ndarray
    lowrank_row_stop: np.ndarray
    lowrank_col_start: np.ndarray
    lowrank_col_stop: np.ndarray
    lowrank_rank: np.ndarray
    u_offset: np.ndarray
    v_offset: np.ndarray
    rank_offset: np.ndarray
    u_values: np.ndarray
    v_values: np.ndarray
    lowrank_head: np.ndarray
    u_fixed_offset: np.ndarray
    v_fixed_offset: np.ndarray
    u_fixed: np.ndarray
    v_fixed: np.ndarray
    u_scale: np.ndarray
    v_scale: np.ndarray
    segment_start: np.ndarray
    segment_dense_ptr: np.ndarray
    segment_dense_ids: np.ndarray
    segment_lowrank_ptr: np.ndarray
    segment_lowrank_ids: np.ndarray
    admissible_kind: np.ndarray
    admissible_index: np.ndarray
    admissible_rank: np.ndarray
    far_seconds: float = 0.0
    near_seconds: float = 0.0

    @property
    def lowrank_bytes(self):
        """Bytes of the low-rank factors: float columns, fixed-point columns and their scales."""
        return int(sum(getattr(self, name).nbytes for name in _FACTOR_ARRAYS))

    @property
    def memory_bytes(self):
        """Bytes of stored matrix entries (dense blocks + U + V)."""
        return int(self.dense_values.nbytes) + self.lowrank_bytes

    @property
    def index_bytes(self):
        """Bytes of the bookkeeping arrays (offsets, ranges, segment lists)."""
        total = 0
        for name, value in vars(self).items():
            if isinstance(value, np.ndarray) and name != "dense_values" and name not in _FACTOR_ARRAYS:
                total += value.nbytes
        return int(total)

    @property
    def factor_format(self):
        """"float64", "float32", or "float32+int16" when trailing columns are fixed point."""
        name = str(self.u_values.dtype)
        return name + "+int16" if self.u_fixed.size or self.v_fixed.size else name

    def factors(self, b):
        """(U^T, V^T) of low-rank block b as float64 rows (k x m, k x n)."""
        k, head, r0 = self.lowrank_rank[b], self.lowrank_head[b], self.rank_offset[b]
        m = self.dof * (self.lowrank_row_stop[b] - self.lowrank_row_start[b])
        n = self.col_dof * (self.lowrank_col_stop[b] - self.lowrank_col_start[b])
        ut = factor_columns(self.u_values, self.u_offset[b], self.u_fixed, self.u_fixed_offset[b], self.u_scale, r0,
                            k, head, m)
        vt = factor_columns(self.v_values, self.v_offset[b], self.v_fixed, self.v_fixed_offset[b], self.v_scale, r0,
                            k, head, n)
        return ut, vt

    def matmat_permuted(self, x):
        """y = A x for x of shape (nrhs, N_c*d_c) (transposed!) in the permuted ordering;
        returns y of shape (nrhs, N*d_r). Parallel and race-free; on one thread below
        ``SERIAL_MATVEC_ENTRIES`` stored entries x right-hand sides and on the cores
        other processes leave free (:func:`~hmatddm.hmatrix._threads.threads_for`;
        the same result whatever the count)."""
        from ._threads import SERIAL_MATVEC_ENTRIES, threads_for

        entries = self.dense_values.size + self.u_values.size + self.v_values.size
        with threads_for(entries * x.shape[0], SERIAL_MATVEC_ENTRIES) as threads:
            return self._matmat_permuted(x, _matmat_permuted if threads > 1 else _matmat_serial)

    def _matmat_permuted(self, x, kernel):
        return kernel(
            self.dof,
            self.col_dof,
            self.n_elements * self.dof,
            self.dense_col_start,
            self.dense_row_start,
            self.dense_col_stop,
            self.dense_offset,
            self.dense_values,
            self.lowrank_row_start,
            self.lowrank_row_stop,
            self.lowrank_col_start,
            self.lowrank_col_stop,
            self.lowrank_rank,
            self.u_offset,
            self.v_offset,
            self.rank_offset,
            self.u_values,
            self.v_values,
            self.lowrank_head,
            self.u_fixed_offset,
            self.v_fixed_offset,
            self.u_fixed,
            self.v_fixed,
            self.u_scale,
            self.v_scale,
            self.segment_start,
            self.segment_dense_ptr,
            self.segment_dense_ids,
            self.segment_lowrank_ptr,
            self.segment_lowrank_ids,
            np.ascontiguousarray(x, dtype=np.float64),
        )
