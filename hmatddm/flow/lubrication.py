"""Finite-volume lubrication flow in the fracture elements (ref. Sec. 4.3, Eqs 4.27-4.40).

Per element ``i`` (area ``S_i``; in 2D the segment length times the flow height) and
time step ``dt``, backward Euler with widths lagged one nonlinear iteration (ref.
Eq. 4.36)::

    c_f (S_i w_i^k + V_wi) (p_i - p_i^n)/dt + S_i (w_i - w_i^n)/dt
        + S_i Lambda_i (p_i - p_r) - sum_e K_e^k (p_j - p_i) = q_wi

with the opening ``w_i = n_i . DD_i`` (our sign convention, docs/conventions.md §1; the
reference writes ``w = -n . Delta u``). In matrix form ``C DD + D p = g`` (ref.
Eqs 4.37-4.40) with

* ``C = diag(S_i / dt) n_i^T`` (N x dN),
* ``D`` the storage, leak-off and transmissibility matrix (sparse, symmetric),
* ``g`` the injection, old storage and old width.

Transmissibility of a face (ref. Eqs 4.32-4.33): face length ``l``, centre-to-face
distances ``d_i``, ``d_j``, and the width at the face interpolated linearly between
the two centres, ``w_e = (d_j w_i + d_i w_j) / (d_i + d_j)``:
``K_e = l w_e^3 / (mu' (d_i + d_j))``, which is ``l w^3 / (mu' d_e)`` of the reference
for equal neighbours. The flux is antisymmetric, so mass is conserved across size
jumps. (A harmonic mean of ``w^3`` would throttle the flow into a freshly created tip
element to its floor width and lock a viscosity-dominated front; measured.)

Power-law fluids (beyond the reference, ref. Sec. 8.2; :class:`~hmatddm.flow.fluid.Fluid`):
the flux across a face is the parallel-plate flux of Adachi and Detournay (2002),
``F_e = c_e |dp_e|^(m-1) dp_e`` with ``dp_e = p_i - p_j``, ``m = 1/n`` and
``c_e = l (w_e^(2n+1) / M')^(1/n) / (d_i + d_j)^m`` (the same face width ``w_e``). The
conductivity depends on the pressure difference: :meth:`LubricationModel.assemble` linearises
the flux at the pressure iterate ``dp^k`` (Newton in ``dp``, the widths lagged as above)::

    F_e ~ k_e dp_e - r_e,   k_e = m c_e |dp^k|^(m-1),   r_e = (m - 1) c_e |dp^k|^(m-1) dp^k,

so the face's ``k_e`` enters ``D`` like a transmissibility and ``r_e`` enters ``g``; at the
fixed point ``dp = dp^k`` the flux is exact. (Lagging ``|dp|^(m-1)`` instead, a Picard
iteration, maps a gradient error ``e`` to ``-(m - 1) e``: it oscillates without contraction
at n = 1/2.) Below the wall shear rate ``gamma_0`` (``Fluid.minimum_shear_rate``), i.e. for
``|dp_e| < dp_0 = 2 K gamma_0^n (d_i + d_j) / w_e`` (wall shear stress ``w |grad p| / 2``),
the flux is linear, ``F_e = c_e dp_0^(m-1) dp_e`` (a Newtonian fluid of the apparent
viscosity there, continuous at ``dp_0``): a still fluid keeps a finite conductivity and
the first iterate of a uniform pressure is defined. At n = 1 the linearisation is the
Newtonian row itself (``k_e = c_e``, ``r_e = 0``).

Slurry (issue 34, :mod:`hmatddm.flow.proppant`): ``viscosity_factor`` (per element, default 1)
multiplies the viscosity (Newtonian ``mu'``; power-law ``K``, so ``M'`` and the shear-rate floor)
by the Maron-Pierce factor of the proppant the element holds; a face takes the mean of its two
elements' factors (``K_e`` divided by it, resp. ``c_e`` by its ``1/n``-th power).

Carter leak-off over a step is integrated exactly: ``Lambda_i dt = 2 c_l
(sqrt(t^{n+1} - tau_i) - sqrt(max(t^n - tau_i, 0)))``, finite for elements created
during the step (``t - tau -> 0`` in ref. Eq. 4.25).
"""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..mesh import Mesh3D


def fracture_compliance(mesh, material):
    """Self compliance ``c_i`` of each element (ref. Eq. 4.49), m/Pa."""
    g, nu = material.shear_modulus, material.poisson_ratio
    if isinstance(mesh, Mesh3D):
        a, b = mesh.half_a, mesh.half_b
        return np.pi * (1.0 - nu) / g * a * b / np.sqrt(a * a + b * b)
    return np.pi * (1.0 - nu) * mesh.half_length / g


@dataclass
class LubricationModel:
    """Flow matrices of one mesh (ref. Eqs 4.36-4.40).

    Parameters
    ----------
    areas : (N,) element areas S_i, m^2
    normals : (N, d) unit normals
    faces : hmatddm.mesh.topology.Faces
    fluid : Fluid
    leak_off : LeakOff
    injection_elements : (C,) element of each cluster
    injection_rates : (C,) q_w, m^3/s
    wellbore_volumes : (C,) V_w, m^3
    minimum_width : float
        Floor of the width used in the transmissibility and the storage term, m (a
        closed or not yet opened element keeps a small conductivity; the reference's
        "initial fracture width").
    viscosity_factor : (N,) array or None
        Slurry viscosity over the carrier fluid's per element (>= 1; None: clean fluid).
    well : hmatddm.flow.well.WellLink or None
        Clusters sharing one pump (issue 35, :mod:`hmatddm.flow.well`): every :meth:`assemble`
        linearises the well at its pressure iterate and adds the injection of the clusters,
        a linear function of their pressures with the heel pressure eliminated (a symmetric
        block on the cluster elements), in place of ``injection_rates``; the well's storage
        is in that block, at the heel pressure. A direct well (one cluster without
        perforation friction) is the fixed-rate path: ``injection_rates`` holds the pump's
        mean rate and ``wellbore_volumes`` the well's volume.
    """

    areas: np.ndarray
    normals: np.ndarray
    faces: object
    fluid: object
    leak_off: object
    injection_elements: np.ndarray
    injection_rates: np.ndarray
    wellbore_volumes: np.ndarray
    minimum_width: float
    viscosity_factor: np.ndarray = None
    well: object = None

    @property
    def n_elements(self):
        return len(self.areas)

    def effective_width(self, width):
        return np.maximum(width, self.minimum_width)

    def face_width(self, width):
        """``(w_e, d_i + d_j)`` of every face: the width interpolated linearly between the two
        centres (module docstring) and the centre-to-centre distance."""
        w = self.effective_width(width)
        f = self.faces
        distance = f.first_distance + f.second_distance
        return (f.second_distance * w[f.first] + f.first_distance * w[f.second]) / distance, distance

    def transmissibility(self, width):
        """K_e of every face (ref. Eq. 4.36) for element widths ``width`` (Newtonian fluid)."""
        if self.fluid.power_law:
            raise ValueError("a power-law fluid's conductivity depends on the pressure: use "
                             "power_law_conductance(width, pressure)")
        face_width, distance = self.face_width(width)
        return self.faces.length * face_width**3 / (self.fluid.viscosity_prime * self.face_viscosity_factor()
                                                    * distance)

    def face_viscosity_factor(self):
        """The slurry's viscosity factor of every face: the mean of its two elements' (1 for a
        clean fluid)."""
        if self.viscosity_factor is None:
            return 1.0
        f = self.faces
        return 0.5 * (self.viscosity_factor[f.first] + self.viscosity_factor[f.second])

    def power_law_conductance(self, width, pressure):
        """``(k_e, r_e)`` of every face: the power-law flux linearised at ``pressure`` (module
        docstring), ``F_e ~ k_e (p_i - p_j) - r_e`` from the first element to the second."""
        fluid = self.fluid
        n = fluid.flow_index
        m = 1.0 / n
        f = self.faces
        face_width, distance = self.face_width(width)
        factor = self.face_viscosity_factor()
        coefficient = f.length * (face_width ** (2.0 * n + 1.0) / (fluid.viscosity_prime * factor)) ** m / distance**m
        difference = pressure[f.first] - pressure[f.second]
        floor = 2.0 * fluid.consistency * factor * fluid.minimum_shear_rate**n * distance / face_width
        magnitude = np.abs(difference)
        sheared = magnitude > floor
        scale = coefficient * np.maximum(magnitude, floor) ** (m - 1.0)
        conductance = np.where(sheared, m * scale, scale)
        correction = np.where(sheared, (m - 1.0) * scale * difference, 0.0)
        return conductance, correction

    def face_flux(self, width, pressure):
        """Volume flux of every face from its first element to its second, m^3/s (the exact
        flux law, Newtonian or power-law, at ``width`` and ``pressure``)."""
        f = self.faces
        difference = pressure[f.first] - pressure[f.second]
        if not self.fluid.power_law:
            return self.transmissibility(width) * difference
        conductance, correction = self.power_law_conductance(width, pressure)
        return conductance * difference - correction

    #: ``(elements, Lambda)`` that replace :meth:`leak_off_rate` of those elements (the
    #: asymptotic front's tip elements, leaking point by point; None: none)
    tip_leak_off = None

    def leak_off_rate(self, creation_time, time_old, time_new):
        """Lambda_i, the step-averaged Carter coefficient (1/s per Pa scale: m/(s Pa)), with
        :attr:`tip_leak_off` in place where given."""
        c = self.leak_off.coefficient
        if c == 0.0:
            return np.zeros(self.n_elements)
        dt = time_new - time_old
        new = np.sqrt(np.maximum(time_new - creation_time, 0.0))
        old = np.sqrt(np.maximum(time_old - creation_time, 0.0))
        rate = 2.0 * c * (new - old) / dt
        if self.tip_leak_off is not None:
            rate[self.tip_leak_off[0]] = self.tip_leak_off[1]
        return rate

    def wellbore_storage(self):
        """V_w per element (summed when clusters share an element)."""
        volume = np.zeros(self.n_elements)
        np.add.at(volume, self.injection_elements, self.wellbore_volumes)
        return volume

    def injection(self):
        """q_w per element."""
        rate = np.zeros(self.n_elements)
        np.add.at(rate, self.injection_elements, self.injection_rates)
        return rate

    def coupling_matrix(self, dt):
        """C = diag(S_i/dt) n_i^T, sparse (N, dN) (ref. Eq. 4.38, our sign)."""
        n, d = self.normals.shape
        rows = np.repeat(np.arange(n), d)
        cols = np.arange(n * d)
        values = (self.areas[:, None] / dt * self.normals).ravel()
        return sp.csr_matrix((values, (rows, cols)), shape=(n, n * d))

    def assemble(self, width_iterate, width_old, pressure_old, dt, leak_off_rate, pressure_iterate=None):
        """``D`` (sparse CSR, N x N) and ``g`` (N,) of ref. Eqs 4.39-4.40.

        ``width_iterate`` is w^{n+1,k} (lags the nonlinear terms), ``width_old`` w^n,
        ``pressure_old`` p^n, ``leak_off_rate`` Lambda from :meth:`leak_off_rate`.
        ``pressure_iterate`` p^{n+1,k}: where a power-law flux is linearised (module
        docstring; default ``pressure_old``); a Newtonian fluid does not read it.
        """
        n = self.n_elements
        c_f = self.fluid.compressibility
        storage = c_f * (self.areas * self.effective_width(width_iterate) + self.wellbore_storage()) / dt
        leak = self.areas * leak_off_rate
        f = self.faces
        correction = None
        if self.fluid.power_law:
            at = pressure_old if pressure_iterate is None else pressure_iterate
            k, correction = self.power_law_conductance(width_iterate, np.asarray(at, dtype=np.float64))
        else:
            k = self.transmissibility(width_iterate)
        diagonal = storage + leak
        np.add.at(diagonal, f.first, k)
        np.add.at(diagonal, f.second, k)
        indices, indptr, slot = self._pattern()
        data = np.bincount(slot, weights=np.concatenate([diagonal, -k, -k]), minlength=indices.size)
        matrix = sp.csr_matrix((data, indices.copy(), indptr.copy()), shape=(n, n))
        rhs = (self.injection() + storage * pressure_old + self.areas * width_old / dt
               + leak * self.leak_off.pore_pressure)
        if correction is not None:  # the linearised power-law flux: F_e = k_e dp_e - r_e
            np.add.at(rhs, f.first, correction)
            np.subtract.at(rhs, f.second, correction)
        if self.well is not None and not self.well.direct:  # clusters sharing a pump (hmatddm.flow.well)
            at = pressure_old if pressure_iterate is None else pressure_iterate
            well_matrix, well_rhs = self.well.linearise(at).matrix_terms(self.well.elements, n)
            matrix = (matrix + well_matrix).tocsr()
            rhs = rhs + well_rhs
        return matrix, rhs

    def _pattern(self):
        """The CSR pattern of ``D`` (each cell's diagonal, the two entries of each face) and
        the slot of each assembled value in it, ``(indices, indptr, slot)``: made once per
        model (mesh), not sorted again at every nonlinear iterate as a COO matrix's would be."""
        n, f = self.n_elements, self.faces
        cached = getattr(self, "_csr_pattern", None)
        if cached is not None and cached[0] is f and cached[1] == n:
            return cached[2]
        rows = np.concatenate([np.arange(n), f.first, f.second]).astype(np.int64)
        cols = np.concatenate([np.arange(n), f.second, f.first]).astype(np.int64)
        unique, slot = np.unique(rows * n + cols, return_inverse=True)
        indptr = np.zeros(n + 1, dtype=np.int32)
        np.cumsum(np.bincount(unique // n, minlength=n), out=indptr[1:])
        pattern = ((unique % n).astype(np.int32), indptr, slot.ravel())
        self._csr_pattern = (f, n, pattern)
        return pattern

    def cluster_rates(self, pressure):
        """The rate into each cluster (m^3/s) at the element pressures ``pressure``: the fixed
        rates, or those of the well (its last linearisation, :class:`hmatddm.flow.well.WellLink`)."""
        if self.well is None:
            return np.asarray(self.injection_rates, dtype=float).copy()
        return self.well.state(pressure)[1]
