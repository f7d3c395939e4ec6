"""Growing tips that meet natural fractures (ref. Ch. 5; see
:mod:`hmatddm.simulation.natural`): the candidate element of a tip may activate an
intact natural element instead (deflection, or the fluid running along the natural
fracture), connect the tip to a natural element already in the system, or cross. A
candidate whose path cuts a natural element, intact or already in the system (activated,
failed remotely), is put to the crossing criterion; at one already in the system the tip
is connected to it whether it crosses (a branch) or not."""
import numpy as np

from ..mesh import concatenate
from .linking import link
from .state import NewElements, Origin


def meet_natural_fractures(simulation, state, edges, faces, tips, grown, parent, rows, events):
    """The new elements and connections of the candidates ``grown`` (row ``rows`` of
    ``tips``, grown from element ``parent`` of ``state.mesh``) in ``simulation``'s natural
    network: ``(NewElements or None, [Connection])``. The kept candidates come first in
    the new elements, then the activated natural elements; ``events`` counts crossings
    and deflections."""
    network = simulation.network
    mesh = state.mesh
    available = state.intact.copy()
    # natural elements already in the system (activated, or failed remotely): a tip
    # that reaches one connects to it instead of adding an element on top of it
    active_of = -np.ones(network.mesh.n_elements, np.int64)
    joined = state.natural_index >= 0
    active_of[state.natural_index[joined]] = np.flatnonzero(joined)
    reachable = available | (active_of >= 0)
    # what a candidate's path may cut: intact elements and those in the system (kept
    # through the pass: an element activated in it is connected to, not activated again)
    on_path = reachable.copy()
    # pairs already connected (a tip never links to itself or to a neighbour twice)
    linked = {(int(a), int(b)) for a, b in zip(faces.first, faces.second)}
    linked |= {(b, a) for a, b in linked}
    kept, activated, activated_parent, connections = [], [], [], []
    activated_at = {}  # natural element -> its place in `activated` (this pass)

    def activate(target, tip):
        available[target] = reachable[target] = False
        activated_at[int(target)] = len(activated)
        activated.append(target)
        activated_parent.append(tip)

    def connect(tip, row, target, point, size):
        """A flow face from ``tip`` to natural element ``target``, which is already in the
        system or was activated by another tip in this pass (two tips reaching the same
        element would otherwise put a hydraulic element on top of it, a singular pair:
        found by the 3D DFN benchmark); never to itself, never twice."""
        if active_of[target] >= 0:
            other = int(active_of[target])
            number, is_new = other, False
        else:
            place = activated_at[int(target)]
            other, number, is_new = ("new", place), place, True
            if activated_parent[place] == tip:
                return
        if other == tip or (tip, other) in linked:
            return
        linked.add((tip, other))
        connections.append(link(edges, tip, tips.edge[row], network, target, point, size, number, is_new))

    def joined(tip, target):
        """Whether ``tip`` already joins natural element ``target`` (in the system or
        activated in this pass): it is that element, or linked to it."""
        if active_of[target] >= 0:
            other = int(active_of[target])
        else:
            place = activated_at[int(target)]
            if activated_parent[place] == tip:
                return True
            other = ("new", place)
        return other == tip or (tip, other) in linked

    for k in range(grown.n_elements):
        row, tip = rows[k], int(parent[k])
        distance, nearest = network.tree.query(grown.centers[k])
        size = min(float(grown.radii[k]), float(network.mesh.radii[nearest]))
        if distance < 0.5 * size and (reachable[nearest] or int(nearest) in activated_at):
            if available[nearest]:
                # the next element is an intact natural element: the fluid runs into it
                activate(nearest, tip)
            else:
                # it is in the system or was activated in this pass: connect the tip to it
                connect(tip, row, nearest, grown.centers[k], size)
            continue
        hinge = edges.midpoints[tip, tips.edge[row]]
        path = on_path
        own = int(state.natural_index[tip])
        if own >= 0 and on_path[own]:  # a natural tip's path starts on its own element
            path = on_path.copy()
            path[own] = False
        hit = network.encounter(grown, k, hinge, path)
        if hit is None:
            kept.append(k)
            continue
        target, point = hit
        if not available[target] and joined(tip, target):
            continue  # arrested at this natural element before (or by another tip in this pass): it stays so
        far_field, toughness = simulation.far_field_stress, simulation.propagation.toughness
        if simulation.medium is not None:  # the layer where the tip meets it (hmatddm.layered.engine)
            from ..layered.engine import crossing_setting

            far_field, toughness = crossing_setting(simulation.medium, hinge[-1] if mesh.dim == 3 else point[-1],
                                                    far_field, toughness)
        crosses = network.decide_crossing(tips.k_1[row], tips.k_2[row], tips.theta[row],
                                          edges.ahead[tip, tips.edge[row]], mesh.normals[tip], target, far_field,
                                          toughness)
        if not available[target]:
            # in the system already (activated, failed remotely, or activated in this pass)
            # and not yet joined by this tip: it joins its flow either way, and goes on
            # across it where it crosses (a branch, ref. Sec. 6.4: remote failure creates
            # branches at intersections)
            events.natural_crossed += int(crosses)
            events.natural_deflected += int(not crosses)
            if crosses:
                kept.append(k)
            connect(tip, row, target, point, size)
            continue
        if crosses:
            events.natural_crossed += 1
            kept.append(k)
            continue
        events.natural_deflected += 1
        connections.append(link(edges, tip, tips.edge[row], network, target, point, size, len(activated), True))
        activate(target, tip)
    # the activated elements follow the kept candidates
    connections = [c.shifted(len(kept)) for c in connections]
    if not kept and not activated:
        return None, connections
    pieces, parents = [], []
    if kept:
        pieces.append(grown.subset(np.asarray(kept)))
        parents.append(parent[np.asarray(kept)])
    if activated:
        pieces.append(network.mesh.subset(np.asarray(activated)))
        parents.append(np.asarray(activated_parent, dtype=np.int64))
    natural_index = np.concatenate([-np.ones(len(kept), np.int64), np.asarray(activated, dtype=np.int64)])
    m = natural_index.size
    origin = np.where(natural_index >= 0, Origin.ACTIVATED, Origin.HYDRAULIC).astype(np.int64)
    return NewElements(concatenate(pieces), np.concatenate(parents), origin, natural_index, np.full(m, np.nan)), \
        connections
