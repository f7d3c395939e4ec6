"""Natural-fracture networks (ref. Sec. 6.2): synthetic generation and intersections.

Quick tour::

    from hmatddm import network as nw
    spec = nw.NetworkSpec(region=(-50, 50, -50, 50), density=0.05, length_exponent=2.0,
                          l_min=1.0, l_max=30.0, mean_azimuths_deg=45.0, kappas=5.0, seed=1)
    net = nw.generate_network(spec)              # plan-view segments p0 -> p1
    conforming = nw.split_at_intersections(net)  # pieces end at every intersection
    mesh = conforming.to_mesh2d(element_length=1.0)
    graph = nw.intersection_graph(net)           # clusters of connected fractures
    p10 = nw.intersection_frequency(net)         # ref. Fig. 6.9, per metre of the y axis

Conventions: azimuths are strikes measured from the +x axis counter-clockwise, in
``[0, pi)`` (radians in arrays and sampling functions, degrees in :class:`NetworkSpec`);
``kappa`` is the von Mises concentration of the doubled angle; density is fractures per
square metre (Eq. 6.12).
"""
from .generation import (Network, NetworkSpec, bimodal_directions, generate_network, power_law_lengths,
                         von_mises_directions)
from .intersections import (IntersectionGraph, Intersections, find_intersections, intersection_frequency,
                            intersection_graph, scanline_frequency, split_at_intersections)

__all__ = [
    "power_law_lengths", "von_mises_directions", "bimodal_directions", "NetworkSpec", "Network",
    "generate_network", "Intersections", "find_intersections", "split_at_intersections", "IntersectionGraph",
    "intersection_graph", "scanline_frequency", "intersection_frequency",
]
