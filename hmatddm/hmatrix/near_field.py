"""The compiled passes of the near-field extraction of an H-matrix: the stored exact
(dense) blocks of a square operator read into sparse CSR or BSR matrices in the original
ordering (:meth:`HMatrix.near_field_csr <hmatddm.hmatrix.HMatrix.near_field_csr>`,
:meth:`~hmatddm.hmatrix.HMatrix.near_field_bsr`, which the preconditioners use), with the
frame-independent Frobenius rule that decides which d x d element blocks are kept.
"""

import numpy as np
from numba import njit


@njit(cache=True)
def _element_norms(dof, row_start, row_stop, offset, values, diagonal_blocks, n_elements):
    """Frobenius norm of each element's d x d diagonal block (tree positions)."""
    d = dof
    norms = np.zeros(n_elements)
    for b in diagonal_blocks:
        me = row_stop[b] - row_start[b]
        n = d * me
        for a in range(me):
            total = 0.0
            for p in range(d):
                base = offset[b] + (d * a + p) * n + d * a
                for q in range(d):
                    total += values[base + q] ** 2
            norms[row_start[b] + a] = np.sqrt(total)
    return norms


@njit(cache=True)
def _keep_blocks(d, values, base, n, me, ne, r_el, c_el, element_norm, threshold, element_diagonal, keep):
    """keep[a, c]: element block (a, c) of a stored block kept by the Frobenius rule."""
    for a in range(me):
        for c in range(ne):
            same = r_el + a == c_el + c
            if element_diagonal and not same:
                keep[a, c] = False
                continue
            total = 0.0
            for p in range(d):
                row = base + (d * a + p) * n + d * c
                for q in range(d):
                    total += values[row + q] ** 2
            if total == 0.0:
                keep[a, c] = False
            elif same:
                keep[a, c] = True
            else:
                limit = threshold * threshold * element_norm[r_el + a] * element_norm[c_el + c]
                keep[a, c] = total >= limit


@njit(cache=True, inline="always")
def _kept_blocks_of(d, b, row_start, row_stop, col_start, col_stop, offset, values, element_norm, threshold,
                    element_diagonal):
    """``(me, ne, n, keep)`` of dense block ``b``: its element counts, its row length in
    entries and :func:`_keep_blocks`' mask of the element blocks to keep."""
    me = row_stop[b] - row_start[b]
    ne = col_stop[b] - col_start[b]
    n = d * ne
    keep = np.empty((me, ne), dtype=np.bool_)
    _keep_blocks(d, values, offset[b], n, me, ne, row_start[b], col_start[b], element_norm, threshold,
                 element_diagonal, keep)
    return me, ne, n, keep


@njit(cache=True)
def _csr_pass(dof, row_start, row_stop, col_start, col_stop, offset, values, selected, permutation,
              element_norm, threshold, element_diagonal, indptr, cursor, indices, data, fill):
    """CSR of the kept element blocks of the selected dense blocks (original ordering),
    without their exact zeros, in two passes.

    fill=False: count the kept entries of each row into indptr[row + 1].
    fill=True: write them at cursor[row] (initialised to indptr[:-1]).
    """
    d = dof
    for b in selected:
        me, ne, n, keep = _kept_blocks_of(d, b, row_start, row_stop, col_start, col_stop, offset, values,
                                          element_norm, threshold, element_diagonal)
        for a in range(me):
            row_element = permutation[row_start[b] + a]
            for p in range(d):
                row = d * row_element + p
                base = offset[b] + (d * a + p) * n
                for c in range(ne):
                    if not keep[a, c]:
                        continue
                    col_element = permutation[col_start[b] + c]
                    for q in range(d):
                        value = values[base + d * c + q]
                        if value == 0.0:
                            continue
                        if fill:
                            position = cursor[row]
                            indices[position] = d * col_element + q
                            data[position] = value
                            cursor[row] = position + 1
                        else:
                            indptr[row + 1] += 1


@njit(cache=True)
def _bsr_pass(dof, row_start, row_stop, col_start, col_stop, offset, values, selected, permutation,
              element_norm, threshold, element_diagonal, indptr, cursor, indices, data, fill):
    """BSR (element blocks, original ordering) of the kept element blocks, two passes
    as :func:`_csr_pass` (counts in indptr[row_element + 1])."""
    d = dof
    for b in selected:
        me, ne, n, keep = _kept_blocks_of(d, b, row_start, row_stop, col_start, col_stop, offset, values,
                                          element_norm, threshold, element_diagonal)
        for a in range(me):
            row_element = permutation[row_start[b] + a]
            for c in range(ne):
                if not keep[a, c]:
                    continue
                if not fill:
                    indptr[row_element + 1] += 1
                    continue
                position = cursor[row_element]
                indices[position] = permutation[col_start[b] + c]
                for p in range(d):
                    base = offset[b] + (d * a + p) * n + d * c
                    for q in range(d):
                        data[position, p, q] = values[base + q]
                cursor[row_element] = position + 1


@njit(cache=True)
def _sort_block_rows(indptr, indices, data):
    """Sort the column indices (and blocks) of every block row in place."""
    for i in range(indptr.size - 1):
        start, stop = indptr[i], indptr[i + 1]
        if stop - start < 2:
            continue
        order = np.argsort(indices[start:stop])
        sorted_indices = indices[start:stop][order]
        sorted_data = data[start:stop][order]
        # element by element, not by slice assignment (docs/conventions.md, §5)
        for k in range(stop - start):
            indices[start + k] = sorted_indices[k]
            for p in range(data.shape[1]):
                for q in range(data.shape[2]):
                    data[start + k, p, q] = sorted_data[k, p, q]
