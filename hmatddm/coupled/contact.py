"""Contact and Coulomb friction on closed fracture elements: open / stick / slip.

A fracture element that the fluid cannot hold open closes: its faces touch and carry a
contact traction ``c`` (tension positive, our sign). With the elasticity equation of
an element written as its residual (docs/conventions.md §1, ref. Eq. 4.4 with fluid)::

    c_i = (A DD + B p - f)_i        (the part of the rock traction the fluid does not carry)

the element obeys, per step (``s`` the slip, ``s^n`` its value at the start of the step,
``mu`` the friction coefficient, ``C_0`` the cohesion; ref. Eq. 5.17 is the same
Coulomb law for intact natural fractures)::

    open:   w_i >= 0,  c_i = 0
    stick:  w_i = 0,   s_i = s_i^n,                |c_s| <= C_0 - mu c_n,  c_n <= 0
    slip:   w_i = 0,   c_s = (C_0 - mu c_n) m,     m = (s_i - s_i^n)/|s_i - s_i^n|

(with a packed proppant bed, ``w_i = 0`` reads ``w_i = w_p``, its width: ``propped_width``).

(``c_n = c.n`` is compressive, ``c_s`` the tangential part.) Each status replaces the
element's rows of the elasticity equation by a block-diagonal combination
``S_i (A DD + B p - f)_i + D_i DD_i = g_i``:

* open:  ``S = I``, ``D = 0``, ``g = 0`` (the plain fluid-loaded equation);
* stick: ``S = 0``, ``D = k I``, ``g = k s^n`` (DDs fixed; ``k`` the element's own normal
  stiffness, so the rows keep the scale of a traction);
* slip:  normal row ``k n.DD = 0``; row ``(m + mu n).c = C_0`` (the friction law); in 3D
  also ``(n x m).c = 0`` (the contact traction is aligned with the slip).

Because ``S`` and ``D`` are block diagonal, the modified operator ``S A + D`` keeps the
H-matrix matvec, and its near field (for the ILU), dense matrix (for the LU) and element
diagonal blocks (for the scaling of the fully coupled system) are ``S`` times those of
``A`` plus ``D``.

The status is an active set updated once per nonlinear iteration
(:meth:`ContactModel.update`) from the complementarity functions of the conditions above
(a primal-dual active set, the semismooth Newton method of Hüeber & Wohlmuth for contact
with Coulomb friction), read at the iterate whatever the element's status. With
``lambda~ = -c_n - k (w - w_p)`` (``k`` the element's own normal stiffness)::

    closed  where  lambda~ > 0                        (else open)
    slip    where  |c_s + k (s - s^n)| > C_0 + mu lambda~   (a closed element; else stick)

a slipping element slipping along ``c_s + k (s - s^n)`` (2D: the other way when that
turns against its direction; frictionless elements keep theirs: their rows are the same;
3D: it turns toward its slip increment, damped, see :meth:`ContactModel._turn`). At an
iterate that solves its rows (``w = w_p`` closed, ``c = 0`` open) these are the plain
tests: an open element closes when it interpenetrates, a closed one opens when its contact
traction turns tensile, a stuck one slips when its shear exceeds the strength, a slipping
one sticks when its slip reverses. At a relaxed or accelerated iterate (neither) each
test weighs the traction and the displacement together, so a closed element still
interpenetrating does not open on a tensile traction, and a stuck one does not slip on the
shear that a reversal of its slip explains (measured on the dfn-3cluster network at 4x
its area, t = 152-154 s: 4373 status changes and 345 held elements with the tests of one
status at a time, 802 and 17 with these; benchmarks/RESULTS.md). Every switch has a band
``k tol_w`` that a status must cross to change, ``tol_w = relative_tolerance * max|DD|``
(the largest DD of the mesh, opening or slip; ``k tol_w`` the traction of that much
opening): it keeps the active set from flipping on round-off when an element sits at the
boundary between two states (fluid pressure equal to the normal stress), and the error it
allows is ``tol_w`` of displacement, a ``relative_tolerance`` (1e-3) of the largest DD. A
step has converged only when no status changed and no slip direction turned. An element
that changes status more than ``max_flips`` times in one step is held closed and stuck
from then on in the step (and counted in :attr:`ContactModel.frozen`), so the active set
cannot cycle forever: its DDs are bounded. Some elements have no status that meets their
conditions with the others' (closed it is tensile, open it interpenetrates: seen at the
unresolved near pairs and acute junctions of a network, whose contact matrix is not a
P-matrix); those the answer violates are counted in :attr:`ContactModel.violated`.
"""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..element_blocks import apply_blocks
from ..errors import InputError

OPEN, STICK, SLIP = 0, 1, 2
from ..options import CONTACT_MODES  # noqa: E402,F401  (which elements of a simulation may close)


@dataclass
class ContactLaw:
    """Which elements may close, and their Coulomb strength.

    Parameters
    ----------
    enabled : (N,) bool
        Elements subject to the contact condition (others stay fluid-loaded at any w).
    friction : (N,) float >= 0
        Coulomb friction coefficient mu.
    cohesion : (N,) float >= 0
        Cohesion C_0, Pa.
    """

    enabled: np.ndarray
    friction: np.ndarray
    cohesion: np.ndarray

    def __post_init__(self):
        self.enabled = np.asarray(self.enabled, dtype=bool)
        n = self.enabled.shape[0]
        for name in ("friction", "cohesion"):
            value = np.asarray(getattr(self, name), dtype=np.float64)
            if value.shape != (n,) or not np.all(np.isfinite(value)) or np.any(value < 0.0):
                raise InputError(f"contact {name} must be {n} finite values >= 0")
            setattr(self, name, value)


class ContactRows:
    """The block-diagonal row operators ``S`` (N, d, d), ``D`` (N, d, d) and right-hand
    side ``g`` (N, d) of one set of statuses (see the module docstring)."""

    def __init__(self, select, direct, rhs, key):
        self.select, self.direct, self.g = select, direct, rhs
        self.n, self.d = select.shape[0], select.shape[1]
        self.key = key

    def _blocks(self, blocks, x):
        return apply_blocks(blocks, x)

    def select_rows(self, v):
        """``S v`` for a flat traction vector ``v``."""
        return self._blocks(self.select, v)

    def apply(self, traction, dd):
        """``S traction + D dd`` (flat) with ``traction = A dd (+ B p)``."""
        return self._blocks(self.select, traction) + self._blocks(self.direct, dd)

    def rhs(self, v):
        """``S v + g`` (flat)."""
        return self._blocks(self.select, v) + self.g.ravel()

    def modify_blocks(self, blocks):
        """``S_i A_ii + D_i`` for element diagonal blocks ``A_ii`` (N, d, d)."""
        return np.einsum("eij,ejk->eik", self.select, blocks) + self.direct

    def _sparse(self, blocks):
        n, d = self.n, self.d
        rows = np.repeat(np.arange(n * d).reshape(n, d), d, axis=1).ravel()
        cols = np.tile(np.arange(n * d).reshape(n, 1, d), (1, d, 1)).ravel()
        return sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(n * d, n * d))

    def modify_sparse(self, matrix):
        """``S M + D`` for a sparse (near-field) matrix ``M`` in element-major order."""
        return (self._sparse(self.select) @ matrix + self._sparse(self.direct)).tocsc()

    def modify_dense(self, matrix, first_row=0):
        """``S M + D`` for a dense matrix whose rows are elements ``first_row..`` and whose
        columns are all elements (``D`` lands on the matching diagonal)."""
        d = self.d
        rows = matrix.shape[0] // d
        select = self.select[first_row:first_row + rows]
        out = np.einsum("eij,ejc->eic", select, matrix.reshape(rows, d, -1)).reshape(matrix.shape)
        if matrix.shape[1] == self.n * d:
            index = np.arange(first_row, first_row + rows)
            view = out.reshape(rows, d, self.n, d)
            view[np.arange(rows), :, index, :] += self.direct[index]
        return out

    def modify_rows(self, matrix, first_row):
        """``S M`` for an off-diagonal block, dense or sparse (rows of elements ``first_row..``)."""
        d = self.d
        rows = matrix.shape[0] // d
        select = self.select[first_row:first_row + rows]
        if sp.issparse(matrix):
            return (self.subset(first_row, first_row + rows)._sparse(select) @ matrix).tocsr()
        return np.einsum("eij,ejc->eic", select, matrix.reshape(rows, d, -1)).reshape(matrix.shape)

    def subset(self, start, stop):
        """The rows of elements ``start..stop-1`` (for a block of a partitioned operator)."""
        return ContactRows(self.select[start:stop], self.direct[start:stop], self.g[start:stop],
                           (self.key, start, stop))


class ContactModel:
    """The active set of one time step (statuses, slip directions, step-start slip).

    Parameters
    ----------
    law : ContactLaw
    normals : (N, d)
    dd_start : (N, d) DDs at the start of the step (their tangential part is ``s^n``)
    status : (N,) int, initial statuses (``OPEN``, ``STICK``, ``SLIP``)
    direction : (N, d) unit slip directions of slipping elements (zeros otherwise)
    stiffness : (N,) the elements' own normal stiffness ``|n.A_ii.n|``, Pa/m
    max_flips : int
    relative_tolerance : float, the band ``tol_w / max|DD|`` of the status tests
    propped_width : (N,) or None
        The opening ``w_p`` a closed element keeps (m, >= 0; None: 0): the width of the packed
        proppant bed it holds (issue 34, :func:`hmatddm.flow.proppant.propped_width`). A closed
        element's normal row is ``k (n.DD - w_p) = 0`` and an open one closes below
        ``w_p - tol_w`` (a rigid bed: the proppant's own compliance is not modelled).
    """

    def __init__(self, law, normals, dd_start, status, direction, stiffness, max_flips=4, relative_tolerance=1e-3,
                 propped_width=None):
        self.law = law
        self.normals = np.asarray(normals, dtype=np.float64)
        self.n, self.d = self.normals.shape
        dd_start = np.asarray(dd_start, dtype=np.float64).reshape(self.n, self.d)
        opening = np.sum(dd_start * self.normals, axis=1)
        self.shear_start = dd_start - opening[:, None] * self.normals
        self.initial_status = np.where(law.enabled, np.asarray(status, dtype=np.int64), OPEN)
        self.initial_direction = np.asarray(direction, dtype=np.float64).reshape(self.n, self.d).copy()
        self.stiffness = np.asarray(stiffness, dtype=np.float64)
        self.max_flips = int(max_flips)
        self.relative_tolerance = float(relative_tolerance)
        self.propped_width = (np.zeros(self.n) if propped_width is None
                              else np.maximum(np.asarray(propped_width, dtype=np.float64), 0.0))
        self.reset()

    def reset(self):
        """Back to the statuses the step started with (a relaxation restart)."""
        self.status = self.initial_status.copy()
        self.direction = self.initial_direction.copy()
        self.flips = np.zeros(self.n, dtype=np.int64)
        self.inconsistent = np.zeros(self.n, dtype=bool)  # held elements the last update would change
        self.direction_damping = np.ones(self.n)          # 3D slip-direction step, per element
        self._last_turn = np.zeros(self.n)                 # the last rotation applied (signed, rad)
        self._rows = None

    @property
    def frozen(self):
        """Elements whose status stopped changing because they flipped too often."""
        return int(np.count_nonzero(self.flips > self.max_flips))

    @property
    def violated(self):
        """Held elements whose contact conditions fail (beyond the band) at the last update:
        at a converged iterate, the elements whose conditions the answer violates."""
        return int(np.count_nonzero(self.inconsistent))

    @property
    def closed(self):
        return self.status != OPEN

    def _tangents(self):
        """(N, d-1, d) tangent basis: the slip direction (and n x m) for slipping
        elements, a fixed in-plane basis otherwise."""
        normals = self.normals
        if self.d == 2:
            tangent = np.stack([-normals[:, 1], normals[:, 0]], axis=1)
            slip = self.status == SLIP
            tangent[slip] = self.direction[slip]
            return tangent[:, None, :]
        helper = np.where((np.abs(normals[:, 2]) < 0.9)[:, None], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
        first = np.cross(normals, helper)
        first /= np.linalg.norm(first, axis=1)[:, None]
        slip = self.status == SLIP
        first[slip] = self.direction[slip]
        return np.stack([first, np.cross(normals, first)], axis=1)

    def rows(self):
        """The :class:`ContactRows` of the current statuses (``None`` when all are open).

        Rows in the local frame ``(n, t_1[, t_2])`` of each element: open rows are the
        residual along them; a closed element's normal row is ``k n.DD = 0``; stick rows
        fix the tangential DDs; slip rows are the friction law along ``m = t_1`` and no
        traction across it.
        """
        if self._rows is not None or not np.any(self.closed):
            return self._rows
        n, d = self.n, self.d
        normals = self.normals
        tangents = self._tangents()
        k = self.stiffness
        select = np.zeros((n, d, d))
        direct = np.zeros((n, d, d))
        g = np.zeros((n, d))
        closed, stick, slip = self.status != OPEN, self.status == STICK, self.status == SLIP
        # normal row
        select[:, 0, :] = np.where(closed[:, None], 0.0, normals)
        direct[closed, 0, :] = k[closed, None] * normals[closed]
        g[closed, 0] = k[closed] * self.propped_width[closed]  # a packed proppant bed keeps w_p
        # tangential rows
        for j in range(d - 1):
            t = tangents[:, j, :]
            select[~closed, 1 + j, :] = t[~closed]
            direct[stick, 1 + j, :] = k[stick, None] * t[stick]
            g[stick, 1 + j] = k[stick] * np.sum(t[stick] * self.shear_start[stick], axis=1)
        if np.any(slip):
            m = tangents[slip, 0, :]
            select[slip, 1, :] = m + self.law.friction[slip, None] * normals[slip]
            g[slip, 1] = self.law.cohesion[slip]
            if d == 3:
                select[slip, 2, :] = tangents[slip, 1, :]
        # exact: the dense backend solves with the cached LU of these rows, so two sets of
        # rows may share a factorisation only when they are the same rows
        key = (self.status.tobytes(), self.direction.tobytes())
        self._rows = ContactRows(select, direct, g, hash(key))
        return self._rows

    def _turn(self, follow, increment, increment_norm, tol_w):
        """New slip directions of slipping elements (3D) that turn toward their slip increment.

        The direction of a slip is a fixed point ``m = Δs(m)/|Δs(m)|``, and the plain update
        can overshoot it: on a vertical natural fracture slipping ~0.2 µm per step, the
        vertical part of the increment answered a tilt of ``m`` with -1.2 times that tilt,
        and ``m`` swung between +0.5 and -0.4 for hundreds of iterations (the 3D DFN
        benchmark, t = 31 s). Each element therefore rotates ``m`` in its plane through a
        fraction (its damping, from 1) of the angle to the increment's direction, halving
        that fraction each time the rotation changes sense; and a turn is made (and counts
        as a status change) only when it moves the element's slip by more than ``tol_w``,
        the band of the other status tests, so a direction the DDs cannot resolve stops
        changing. Returns ``(turned, directions)``: a mask and the unit directions of the
        turned elements.
        """
        m, normals = self.direction, self.normals
        across = np.cross(normals, m)  # in-plane, perpendicular to m
        angle = np.zeros(self.n)
        angle[follow] = np.arctan2(np.sum(increment[follow] * across[follow], axis=1),
                                   np.sum(increment[follow] * m[follow], axis=1))
        reversed_ = follow & (angle * self._last_turn < 0.0)
        self.direction_damping[reversed_] *= 0.5
        rotation = self.direction_damping * angle
        moved = 2.0 * np.abs(np.sin(0.5 * rotation)) * increment_norm  # |m_new - m| |Δs|
        turned = follow & (moved > tol_w)
        self._last_turn[turned] = rotation[turned]
        directions = (np.cos(rotation)[turned, None] * m[turned] + np.sin(rotation)[turned, None] * across[turned])
        directions /= np.linalg.norm(directions, axis=1)[:, None]
        return turned, directions

    def update(self, dd, contact_traction):
        """Update the statuses from the iterate ``dd`` (N*d,) and the contact traction
        ``c = A dd + B p - f`` (N*d,); returns the number of elements that changed.

        The statuses are those of the complementarity functions (module docstring), read at
        the iterate whatever the element's status, with a band ``tol_c = k tol_w`` around
        each switch that the status must cross to change:

        * closed where the normal indicator ``lambda~ = -c_n - k (w - w_p)`` is positive;
        * a closed element sticks where its tangential trial traction
          ``t = c_s + k (s - s^n)`` is within the friction bound
          ``C_0 + mu lambda~``, and slips along ``t`` where it is beyond it.
        """
        n, d = self.n, self.d
        dd = np.asarray(dd).reshape(n, d)
        c = np.asarray(contact_traction).reshape(n, d)
        normals = self.normals
        opening = np.sum(dd * normals, axis=1)
        c_n = np.sum(c * normals, axis=1)
        c_s = c - c_n[:, None] * normals
        increment = dd - opening[:, None] * normals - self.shear_start
        k = self.stiffness
        enabled = self.law.enabled
        scale = np.max(np.linalg.norm(dd, axis=1)) if n else 0.0  # the largest DD (opening or slip)
        tol_w = self.relative_tolerance * max(scale, 1e-30)
        tol_c = k * tol_w
        was_closed, was_slip = self.status != OPEN, self.status == SLIP
        # normal: closed where lambda~ > 0 (a status crosses the band to change)
        pressure = -c_n - k * (opening - self.propped_width)
        closed = enabled & np.where(was_closed, pressure >= -tol_c, pressure > tol_c)
        # tangential: stick within the bound, slip along the trial traction beyond it
        trial = c_s + k[:, None] * increment
        trial_norm = np.linalg.norm(trial, axis=1)
        bound = self.law.cohesion + self.law.friction * np.maximum(pressure, 0.0)
        frictionless = (self.law.cohesion == 0.0) & (self.law.friction == 0.0)
        slip = closed & np.where(was_slip, trial_norm >= bound - tol_c, trial_norm > bound + tol_c)
        new_status = np.where(closed, np.where(slip, SLIP, STICK), OPEN).astype(np.int64)
        new_direction = self.direction.copy()
        starts = slip & ~was_slip
        new_direction[starts] = trial[starts] / trial_norm[starts, None]
        turned = np.zeros(n, dtype=bool)
        stays = slip & was_slip
        if d == 2:
            # the trial traction against the slip: it slips the other way (a frictionless
            # element's rows are the same both ways: it keeps its direction)
            along = np.sum(trial * self.direction, axis=1)
            turned = stays & ~frictionless & (along < -tol_c)
            new_direction[turned] = -self.direction[turned]
        else:
            # (a frictionless element's rows do not depend on its direction: it keeps it)
            follow = stays & ~frictionless & (np.linalg.norm(increment, axis=1) > 0.0)
            if np.any(follow):
                turned, directions = self._turn(follow, increment, np.linalg.norm(increment, axis=1), tol_w)
                new_direction[turned] = directions
        new_direction[new_status != SLIP] = 0.0
        # elements that flipped too often are held closed and stuck (the most constrained
        # state: bounded DDs); those whose conditions fail there are counted (:attr:`violated`)
        self.flips += new_status != self.status
        held = self.flips > self.max_flips
        self.inconsistent = held & (new_status != STICK)
        new_status[held] = STICK
        new_direction[held] = 0.0
        changed = (new_status != self.status) | (turned & (new_status == SLIP))
        self.status, self.direction = new_status, new_direction
        n_changed = int(np.count_nonzero(changed))
        if n_changed:
            self._rows = None
        return n_changed
