"""Names and defaults of the engine's options, in a module without dependencies.

The engine modules that own these options import them from here, and so does the scene
schema (:mod:`hmatddm.scene.schema`), which can then validate a scene without loading
scipy, numba or the H-matrix engine (a refused scene answers within a second).
"""

BACKENDS = ("dense", "hmatrix")                 # hmatddm.elasticity.operator.ElasticityOperator
SINGULAR_CORRECTIONS = ("none", "average")
#: Fraction of the element half size by which the NaN averaging (``singular_correction =
#: "average"``) shifts a collocation point off an edge, to either side.
AVERAGE_SHIFT = 1e-3

#: A collocation point closer than this fraction of the smaller half size (of the
#: receiver and the source element; ``min(half_a, half_b)`` in 3D) to an edge of another
#: element (an end point in 2D) is treated as lying on it: refused with
#: ``singular_correction="none"``, averaged at the nearest edge point with "average".
#: Measured on a 2D T whose branch ends a gap g above (or beyond) an element centre of
#: the main crack (21 elements; branch half sizes 0.5-2.1 x the main's), against graded
#: meshes converged at that g: the exact ~1/g entry pins the branch's end element and
#: the crack volume is off by 27-250% (up to a sign flip) for g <= 0.25 half sizes of
#: the smaller element, 22-37% at 0.5 and 9-15% at 1, against 3-10% for the averaged
#: (touching) treatment; the two cross at g = 1.1-2 half sizes. On a 2D X whose branch
#: node lies g from the main crack's centre: -32% .. -21% for g <= 0.4, -15 .. -18% at
#: 0.6-0.8, against +5% averaged. 0.5 keeps a margin of 2 from conforming meshes, whose
#: neighbours' edges lie >= 1 half size from a centre whatever their size ratio, so
#: these are never affected.
NEAR_SINGULAR_FRACTION = 0.5
DEFAULT_EPS = 1e-4
DEFAULT_ETA = 3.0
DEFAULT_LEAF_SIZE = 32  # 64 costs ~25% more memory at N=100k in 3D (8.4 GB vs 6.8 GB)

CONTACT_MODES = ("natural", "all", "none")      # hmatddm.coupled.contact: which elements may close

SCHEMES = ("fixed-width", "fracture-compliance", "fully-coupled", "krylov")  # hmatddm.coupled.schemes
STOPPING_RULES = ("change", "contraction")    # SchemeSettings.stopping
GROWTH_CHECKS = ("first", "converged")       # SchemeSettings.growth_check
SCHEME_DEFAULTS = dict(scheme="krylov", omega=1.0, relaxation=1.0, min_relaxation=1.0 / 256.0,
                       tolerance_pressure=1e-6, tolerance_opening=1e-6, max_iterations=400, linear_rtol=1e-9,
                       linear_restart=100, linear_maxiter=20, relaxation_growth=None, stopping="contraction",
                       first_linear_rtol=1e-6, growth_check="first",
                       provisional_linear_rtol=1e-4, linear_forcing=0.1)  # SchemeSettings

CRITERIA = ("mcs", "energy")                    # hmatddm.fracture.growth.Propagation
TURNING = ("none", "plan", "any")
FRONTS = ("element", "asymptotic")
