"""Names and defaults of the engine's options, in a module without dependencies.

The engine modules that own these options import them from here, and so does the scene
schema (:mod:`hmatddm.scene.schema`), which can then validate a scene without loading
scipy, numba or the H-matrix engine (a refused scene answers within a second).
"""

BACKENDS = ("dense", "hmatrix")                 # hmatddm.operators.ElasticityOperator
SINGULAR_CORRECTIONS = ("none", "average")
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
                       provisional_linear_rtol=1e-4)  # SchemeSettings

CRITERIA = ("mcs", "energy")                    # hmatddm.fracture.growth.Propagation
TURNING = ("none", "plan", "any")
FRONTS = ("element", "asymptotic")
