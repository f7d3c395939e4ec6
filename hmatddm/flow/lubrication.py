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

    @property
    def n_elements(self):
        return len(self.areas)

    def effective_width(self, width):
        return np.maximum(width, self.minimum_width)

    def transmissibility(self, width):
        """K_e of every face (ref. Eq. 4.36) for element widths ``width``."""
        w = self.effective_width(width)
        f = self.faces
        distance = f.first_distance + f.second_distance
        face_width = (f.second_distance * w[f.first] + f.first_distance * w[f.second]) / distance
        return f.length * face_width**3 / (self.fluid.viscosity_prime * distance)

    def leak_off_rate(self, creation_time, time_old, time_new):
        """Lambda_i, the step-averaged Carter coefficient (1/s per Pa scale: m/(s Pa))."""
        c = self.leak_off.coefficient
        if c == 0.0:
            return np.zeros(self.n_elements)
        dt = time_new - time_old
        new = np.sqrt(np.maximum(time_new - creation_time, 0.0))
        old = np.sqrt(np.maximum(time_old - creation_time, 0.0))
        return 2.0 * c * (new - old) / dt

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

    def assemble(self, width_iterate, width_old, pressure_old, dt, leak_off_rate):
        """``D`` (sparse CSR, N x N) and ``g`` (N,) of ref. Eqs 4.39-4.40.

        ``width_iterate`` is w^{n+1,k} (lags the nonlinear terms), ``width_old`` w^n,
        ``pressure_old`` p^n, ``leak_off_rate`` Lambda from :meth:`leak_off_rate`.
        """
        n = self.n_elements
        c_f = self.fluid.compressibility
        storage = c_f * (self.areas * self.effective_width(width_iterate) + self.wellbore_storage()) / dt
        leak = self.areas * leak_off_rate
        k = self.transmissibility(width_iterate)
        f = self.faces
        diagonal = storage + leak
        np.add.at(diagonal, f.first, k)
        np.add.at(diagonal, f.second, k)
        rows = np.concatenate([np.arange(n), f.first, f.second])
        cols = np.concatenate([np.arange(n), f.second, f.first])
        values = np.concatenate([diagonal, -k, -k])
        matrix = sp.csr_matrix((values, (rows, cols)), shape=(n, n))
        rhs = (self.injection() + storage * pressure_old + self.areas * width_old / dt
               + leak * self.leak_off.pore_pressure)
        return matrix, rhs
