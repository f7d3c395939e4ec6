"""Flow faces at intersections (hmatddm.simulation.linking): the geometry of a tip's link
to the element it reached, and faces that the mesh already has are not doubled."""
import numpy as np

import hmatddm as hd
from hmatddm.mesh import topology
from hmatddm.simulation.linking import link, with_links
from hmatddm.simulation.natural import NaturalNetwork


def test_a_2d_link_spans_the_flow_height_and_keeps_a_tenth_of_the_size_apart():
    tip = hd.mesh.line([-0.5, 0.0], [0.5, 0.0], 1)
    edges = topology.element_edges(tip, 2.0)
    ahead = int(np.argmax(edges.ahead[0, :, 0]))  # the +x edge
    network = NaturalNetwork(hd.mesh.line([0.8, -0.5], [0.8, 0.5], 1), None)
    far = link(edges, 0, ahead, network, 0, np.array([0.5, 0.0]), 1.0, target=3)
    assert (far.tip, far.target, far.target_is_new, far.tip_edge) == (0, 3, False, ahead)
    assert far.length == 2.0 and far.tip_distance == 0.5 and np.isclose(far.target_distance, 0.3)
    near = link(edges, 0, ahead, network, 0, np.array([0.78, 0.0]), 1.0, target=0, target_is_new=True)
    assert near.target_is_new and near.target_distance == 0.1  # 0.02 m gap, floored at 0.1 * size


def test_a_3d_link_is_cut_to_the_height_of_the_element_reached():
    tip = hd.mesh.rectangle([0.0, 0.0, 0.0], [1, 0, 0], [0, 0, 1], 1.0, 2.0, 1, 1)
    edges = topology.element_edges(tip, None)
    ahead = int(np.argmax(edges.ahead[0, :, 0]))
    natural = hd.mesh.rectangle([0.75, 0.0, 0.0], [0, 1, 0], [0, 0, 1], 1.0, 0.5, 1, 1)
    connection = link(edges, 0, ahead, NaturalNetwork(natural, None), 0, np.array([0.5, 0.0]), 0.5, target=1)
    assert connection.length == 0.5  # the natural element's height, not the 2 m tip edge
    assert np.isclose(connection.target_distance, 0.25)


def test_links_beside_a_shared_edge_are_dropped():
    mesh = hd.mesh.line([0.0, 0.0], [2.0, 0.0], 2)
    faces = topology.element_faces(mesh, topology.element_edges(mesh, 1.0))
    assert len(faces.first) == 1
    both = with_links(faces, np.array([[0, 1, 1.0, 0.5, 0.5, 1], [1, 0, 1.0, 0.5, 0.5, 0]]))
    assert len(both.first) == 1
    assert with_links(faces, np.zeros((0, 6))) is faces
