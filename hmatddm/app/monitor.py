"""Displacement and tilt at monitor points through a run (the ``[[monitor]]`` tables of a
scene): what a GPS station or a tiltmeter array sees of the fractures (ref. Eqs 2.43,
2.55-2.57, :func:`hmatddm.displacement_at`).

After every step the displacement induced by the DDs of the state's elements is
evaluated at each monitor position (the exact sum; the far field of the fractures moves
the ground as 1/r^2 in 3D), and the tilt with it: in 3D (z up) ``tilt_x = du_z/dx``,
``tilt_y = du_z/dy``; in 2D ``tilt_x = du_y/dx`` (a vertical cross-section with y up;
in a plan-view scene the same derivative of the in-plane displacement). The tilt is the
central difference of the closed-form displacement over ``1e-4`` of the distance to the
nearest element centre. Units: m and radians.

Writes into the run folder ``monitor.csv`` (one row per step and position: ``step,
time, monitor, x, y[, z], u_x, u_y[, u_z], tilt_x[, tilt_y]``; rewritten atomically
after every step, so a partial run is readable, and cut back to the resumed step on
``--resume``) and, at the end, ``monitor.png`` (displacement and tilt against time, one
line per position). In a :class:`hmatddm.LayeredMedium` (ref. Ch. 3) the displacement is
the layered one (:mod:`hmatddm.layered.displacement`: each element's closed form plus its
image terms); a position on the free surface is in the rock (what a tiltmeter on the
ground sees). A position that an element's edge reaches, where the displacement
is log-singular, gets empty cells for that step (and a note).
"""
import csv
import io
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io import atomic_output

MONITOR_CSV = "monitor.csv"
MONITOR_PNG = "monitor.png"
_RELATIVE_STEP = 1e-4


def _columns(dim):
    axes = "xyz"[:dim]
    tilts = ["tilt_x", "tilt_y"] if dim == 3 else ["tilt_x"]
    return ["step", "time", "monitor", *axes, *[f"u_{a}" for a in axes], *tilts]


def displacement_and_tilt(mesh, material, dd, positions):
    """``(u (M, d), tilt (M, d - 1))`` at ``positions`` from the global DDs ``dd`` of
    ``mesh``; rows with a singular value (a position on an element edge) are NaN."""
    from ..elasticity.fields import StressField

    positions = np.asarray(positions, dtype=float)
    dim = positions.shape[1]
    distance = np.min(np.linalg.norm(positions[:, None, :] - mesh.centers[None, :, :], axis=2), axis=1)
    step = _RELATIVE_STEP * np.maximum(distance, 1e-6)
    vertical = dim - 1
    shifted = [positions]
    for axis in range(dim - 1):
        for sign in (1.0, -1.0):
            moved = positions.copy()
            moved[:, axis] += sign * step
            shifted.append(moved)
    from ..material import Elastic

    if not isinstance(material, Elastic):  # a LayeredMedium: closed form + image terms (ref. Ch. 3)
        values = _layered_values(mesh, material, dd, np.vstack(shifted))
    else:
        values = StressField(mesh, material, np.vstack(shifted), "displacement", method="direct", dd=dd)()
    values = values.reshape(len(shifted), len(positions), dim)
    u = values[0]
    tilt = np.column_stack([(values[1 + 2 * a, :, vertical] - values[2 + 2 * a, :, vertical]) / (2.0 * step)
                            for a in range(dim - 1)])
    bad = ~(np.all(np.isfinite(u), axis=1) & np.all(np.isfinite(tilt), axis=1))
    u[bad] = np.nan
    tilt[bad] = np.nan
    return u, tilt


def _layered_values(mesh, medium, dd, points):
    """The layered displacement at ``points``, NaN rows where it is singular (on an
    element edge: the uniform path's convention) instead of the InputError."""
    from ..elasticity.fields import displacement_at

    try:
        return displacement_at(mesh, medium, dd, points)
    except InputError as error:
        if "where the displacement is singular" not in str(error):
            raise
    out = np.empty((len(points), mesh.dim))
    for t, point in enumerate(points):  # rare: find the singular rows one by one
        try:
            out[t] = displacement_at(mesh, medium, dd, point[None])[0]
        except InputError as error:
            if "where the displacement is singular" not in str(error):
                raise
            out[t] = np.nan
    return out


class Monitor:
    """The monitor points of a run and their time series (``rows``)."""

    def __init__(self, out, tables, dim, note=print):
        self.path = Path(out) / MONITOR_CSV
        self.positions = np.array([table["position"] for table in tables], dtype=float)
        if self.positions.shape[1] != dim:
            raise InputError(f"monitor[0].position must have {dim} coordinates")
        self.dim = dim
        self.rows = []
        self.note = note
        self._noted = False

    def resume(self, step):
        """Keep the rows of ``monitor.csv`` up to ``step`` (a resumed run's checkpoint)."""
        if not self.path.is_file():
            return
        with open(self.path, newline="", encoding="utf-8") as handle:
            reader = csv.reader(handle)
            header = next(reader, None)
            if header != _columns(self.dim):
                return
            self.rows = [row for row in reader if int(row[0]) <= step]

    def record(self, simulation, record):
        state = simulation.state
        u, tilt = displacement_and_tilt(state.mesh, simulation.material, state.dd, self.positions)
        for k, position in enumerate(self.positions):
            finite = bool(np.all(np.isfinite(u[k])))
            if not finite and not self._noted:
                self.note(f"hmatddm: note: monitor[{k}] lies on an element edge at step {record['step']}, where the "
                          "displacement is singular: its cells are empty there")
                self._noted = True
            values = [f"{v:.10g}" for v in (*u[k], *tilt[k])] if finite else [""] * (self.dim + self.dim - 1)
            self.rows.append([str(record["step"]), f"{record['time']:.10g}", str(k),
                              *[f"{v:.10g}" for v in position], *values])
        self.write()

    def write(self):
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(_columns(self.dim))
        writer.writerows(self.rows)
        with atomic_output(self.path) as temporary:
            temporary.write_text(buffer.getvalue(), encoding="utf-8")
        return self.path

    def plot(self, name="run"):
        """``monitor.png`` next to ``monitor.csv``; None without rows."""
        if not self.rows:
            return None
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        header = _columns(self.dim)
        table = np.array([[float(c) if c != "" else np.nan for c in row] for row in self.rows])
        axes_names = "xyz"[:self.dim]
        fig, axes = plt.subplots(2, 1, figsize=(7, 6.5), sharex=True)
        for k in range(len(self.positions)):
            rows = table[table[:, 2] == k]
            for a in axes_names:
                axes[0].plot(rows[:, 1], 1e3 * rows[:, header.index(f"u_{a}")],
                             label=f"monitor {k} u_{a}")
            for tilt in header[header.index(f"u_{axes_names[-1]}") + 1:]:
                axes[1].plot(rows[:, 1], 1e6 * rows[:, header.index(tilt)], label=f"monitor {k} {tilt}")
        axes[0].set_ylabel("displacement (mm)")
        axes[1].set_ylabel("tilt (microradian)")
        axes[1].set_xlabel("time (s)")
        axes[0].set_title(f"{name}: displacement and tilt at the monitor points")
        for ax in axes:
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, ncol=2)
        fig.tight_layout()
        path = self.path.with_name(MONITOR_PNG)
        with atomic_output(path) as temporary:
            fig.savefig(temporary, dpi=100, format="png")
        plt.close(fig)
        return path


__all__ = ["Monitor", "displacement_and_tilt", "MONITOR_CSV", "MONITOR_PNG"]
