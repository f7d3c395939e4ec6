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
from .._lazy import attach

_EXPORTS = {
    "Network": ".generation", "NetworkSpec": ".generation", "bimodal_directions": ".sampling",
    "generate_network": ".generation", "power_law_lengths": ".sampling", "von_mises_directions": ".sampling",
    "IntersectionGraph": ".connectivity", "Intersections": ".intersections", "find_intersections": ".intersections",
    "intersection_frequency": ".connectivity", "intersection_graph": ".connectivity",
    "scanline_frequency": ".connectivity", "split_at_intersections": ".intersections",
}
__getattr__, __dir__ = attach(__name__, _EXPORTS)

__all__ = [
    "power_law_lengths", "von_mises_directions", "bimodal_directions", "NetworkSpec", "Network",
    "generate_network", "Intersections", "find_intersections", "split_at_intersections", "IntersectionGraph",
    "intersection_graph", "scanline_frequency", "intersection_frequency",
]
