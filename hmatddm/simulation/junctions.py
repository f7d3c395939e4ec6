"""Tips that reach another hydraulic fracture (ref. Sec. 6.2.3, Figs 6.5-6.7): the tip
stops there and a flow face connects it to the element it would cut."""
import numpy as np

from .linking import link
from .natural import NaturalNetwork
from .state import Origin


def stop_at_other_fractures(mesh, edges, tips, grown, parent, rows, origin, events):
    """Candidates ``grown`` (new elements of the tips ``tips``, row ``rows`` of each, grown
    from element ``parent``) that would cut a hydraulic element of another fracture are
    dropped, and a :class:`~hmatddm.simulation.state.Connection` joins their tip to that
    element. Returns the remaining ``(grown, parent, rows)`` (``grown`` None when none
    remains) and the connections; ``events.junctions`` counts them."""
    hydraulic = origin == Origin.HYDRAULIC
    if np.unique(mesh.fracture_id[hydraulic]).size < 2:
        return grown, parent, rows, []
    active = NaturalNetwork(mesh, None)
    keep, connections, linked = [], [], set()
    for k in range(grown.n_elements):
        row, tip = rows[k], parent[k]
        others = hydraulic & (mesh.fracture_id != mesh.fracture_id[tip])
        hinge = edges.midpoints[tip, tips.edge[row]]
        hit = active.encounter(grown, k, hinge, others)
        if hit is not None:
            # touching only end to end or at the other's tip is not a cut: the element
            # is kept and ends on the other fracture (ref. Fig. 6.5b); the next pass connects
            reach = 2.0 * (grown.centers[k, :2] - hinge[:2])
            along = active.p1[hit[0]] - active.p0[hit[0]]
            t = float(np.dot(hit[1][:2] - active.p0[hit[0]], along)) / float(np.dot(along, along))
            if (float(np.dot(hit[1][:2] - hinge[:2], reach)) >= (1.0 - 1e-6) * float(np.dot(reach, reach))
                    or not 1e-6 < t < 1.0 - 1e-6):
                hit = None
        if hit is None:
            keep.append(k)
            continue
        target, point = hit
        if (tip, target) not in linked:
            linked.add((tip, target))
            size = min(float(grown.radii[k]), float(mesh.radii[target]))
            connections.append(link(edges, tip, tips.edge[row], active, target, point, size, target))
    if not connections:
        return grown, parent, rows, []
    events.junctions += len(connections)
    if not keep:
        return None, None, None, connections
    keep = np.asarray(keep)
    return grown.subset(keep), parent[keep], rows[keep], connections
