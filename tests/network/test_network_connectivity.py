"""Connectivity of a network (ref. Sec. 6.2.3, Fig. 6.9): the intersection graph and its
clusters, and the intersection frequency along a scanline."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm import network as nw
from test_network_intersections import _random_network


# ----------------------------------------------------------------------------- graph and frequency

def test_intersection_graph_clusters():
    p0 = [[0, 0], [5, -1], [20, 0], [25, -1], [25, 5], [40, 40]]
    p1 = [[10, 0], [5, 1], [30, 0], [25, 5], [26, 6], [41, 41]]
    graph = nw.intersection_graph(nw.Network.from_segments(p0, p1))
    assert graph.pairs.tolist() == [[0, 1], [2, 3], [3, 4]]
    assert np.allclose(graph.points, [[5, 0], [25, 0], [25, 5]])
    assert graph.n_clusters == 3 and graph.sizes.tolist() == [3, 2, 1]
    assert [c.tolist() for c in graph.clusters()] == [[2, 3, 4], [0, 1], [5]]
    assert graph.cluster_of(3).tolist() == [2, 3, 4]
    assert graph.intersections_per_fracture == pytest.approx(1.0)
    with pytest.raises(hd.InputError, match="fracture"):
        graph.cluster_of(17)


def test_graph_of_a_split_network_is_the_same():
    network = _random_network(6)
    graph = nw.intersection_graph(network)
    split_graph = nw.intersection_graph(nw.split_at_intersections(network))
    assert np.array_equal(graph.pairs, split_graph.pairs)
    assert np.array_equal(graph.labels, split_graph.labels)
    # trimming dangling stubs keeps every intersection (a near-miss X becomes a T)
    trimmed = nw.split_at_intersections(network, min_stub=0.5)
    assert len(trimmed) < len(nw.split_at_intersections(network))
    assert np.array_equal(nw.intersection_graph(trimmed).pairs, graph.pairs)
    assert graph.sizes.sum() == len(network) and graph.n_clusters < len(network)
    # clusters are connected components: no pair joins two clusters
    labels = dict(zip(graph.fracture_ids.tolist(), graph.labels.tolist()))
    assert all(labels[f] == labels[g] for f, g in graph.pairs.tolist())


def test_intersection_frequency_along_the_y_axis():
    # ten horizontal fractures crossing x = 0, one of them split in two pieces
    y = np.arange(10) + 0.5
    p0 = np.column_stack([np.full(10, -1.0), y])
    p1 = np.column_stack([np.full(10, 1.0), y])
    p0 = np.vstack([p0, [[2.0, 3.0], [-3.0, 7.0]]])  # one fracture off the line, one piece
    p1 = np.vstack([p1, [[3.0, 4.0], [-1.0, 7.0]]])
    ids = np.r_[np.arange(10), 10, 6]  # the last piece belongs to fracture 6
    network = nw.Network.from_segments(p0, p1, fracture_id=ids, region=(-5, 5, 0, 10))
    assert nw.intersection_frequency(network) == pytest.approx(1.0)  # 10 per 10 m
    assert nw.intersection_frequency(network, x=2.5) == pytest.approx(0.1)
    assert nw.scanline_frequency(network, (-4, 0), (-4, 10)) == 0.0
    assert nw.scanline_frequency(network, (-2, 0), (-2, 10)) == pytest.approx(0.1)
    assert nw.scanline_frequency(network, (0, 0), (0, 4)) == pytest.approx(1.0)
    with pytest.raises(hd.InputError, match="end"):
        nw.scanline_frequency(network, (0, 0), (0, 0))


def test_frequency_grows_with_density_and_falls_with_exponent_fig_6_9():
    def mean_frequency(density, exponent):
        return np.mean([nw.intersection_frequency(nw.generate_network(nw.NetworkSpec(
            region=(-50, 50, -50, 50), density=density, length_exponent=exponent, l_min=1.0, l_max=30.0,
            mean_azimuths_deg=45.0, kappas=5.0, seed=seed))) for seed in range(10)])

    f = {(d, a): mean_frequency(d, a) for d in (0.05, 0.1) for a in (2.0, 3.0)}
    assert f[(0.1, 2.0)] > f[(0.05, 2.0)] > f[(0.05, 3.0)]
    assert f[(0.1, 3.0)] > f[(0.05, 3.0)]
    assert f[(0.1, 2.0)] / f[(0.05, 2.0)] == pytest.approx(2.0, rel=0.35)  # ~linear in density for a = 2
