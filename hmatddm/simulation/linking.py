"""Flow faces at intersections: the :class:`~hmatddm.simulation.state.Connection` from a
tip edge to the element it reached, and the flow faces of a mesh plus those connections
(ref. Sec. 6.2.3, Figs 6.5-6.7)."""
import numpy as np

from .state import Connection


def link(edges, tip, edge, network, reached, point, size, target, target_is_new=False):
    """The :class:`Connection` of tip ``tip`` (its edge ``edge``; ``edges``:
    :func:`hmatddm.mesh.topology.element_edges`) to element ``reached`` of ``network`` (a
    :class:`~hmatddm.simulation.natural.NaturalNetwork`), which it meets at ``point``.
    ``target`` numbers that element in the system (see :class:`Connection`).

    The face is the tip edge (3D: within the height of the element reached; 2D: the
    flow height, the edge length); the distance on the far side is the plan-view gap
    from ``point`` to the centre reached, at least a tenth of ``size``."""
    length = min(float(edges.length[tip, edge]), 2.0 * float(network.vertical_half[reached]))
    gap = np.linalg.norm(network.mesh.centers[reached, :2] - point[:2])
    return Connection(int(tip), int(target), bool(target_is_new), length, float(edges.half_width[tip, edge]),
                      max(gap, 0.1 * size), int(edge))


def with_links(faces, links):
    """The flow faces plus the intersection links ``(K, 6)`` (i, j, length, d_i, d_j, edge
    of i), except links between elements that already share an edge: a tip linked to a
    natural element that another tip activated beside it in the same growth pass gets
    its face from the mesh topology, and a second face would double the conductance."""
    if len(links) == 0:
        return faces
    shared = set(zip(faces.first.tolist(), faces.second.tolist()))
    shared |= {(b, a) for a, b in shared}
    i, j, length, d_i, d_j, edge_i = np.asarray(links, dtype=np.float64).T
    i, j, edge_i = i.astype(np.int64), j.astype(np.int64), edge_i.astype(np.int64)
    keep = np.array([(a, b) not in shared for a, b in zip(i.tolist(), j.tolist())], dtype=bool)
    return faces.append(i[keep], j[keep], length[keep], d_i[keep], d_j[keep], edge_i[keep])
