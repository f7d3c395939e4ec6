"""The sections of a scene file: their keys, defaults, ranges and units.

Each key is a :class:`hmatddm.settings.Setting`; the keys that a dataclass of the engine
checks too (propagation, numerics, layers, network, microseismic, ...) are the very
objects declared in :mod:`hmatddm.settings`, so a range or a default is written once.
The checks that read these declarations are :mod:`hmatddm.scene.schema`'s.
"""
from .. import settings
from ..settings import CLUSTER, FLUID, LEAK_OFF, MATERIAL, NATURAL_FRACTURE, PROPAGATION, REQUIRED, SCHEME
from ..settings import Setting as Key  # a key of a scene section is one setting

REFERENCE_KINDS = ("radial-k", "radial-m", "radial-km", "kgd-k", "kgd-m", "three-layer-height")
# closed forms with Carter leak-off: the K-K~ edges (zero viscosity, any leak-off;
# hmatddm.analytical.leak_off), for a scene whose leak_off.coefficient is > 0
LEAK_OFF_REFERENCE_KINDS = ("kgd-k-leak-off", "radial-k-leak-off", "kgd-m-leak-off", "kgd-km-leak-off",
                            "radial-km-leak-off", "radial-m-leak-off")
REFERENCE_KINDS += LEAK_OFF_REFERENCE_KINDS
SHAPES = {2: ("line",), 3: ("rectangle", "penny")}
CROSSING_CRITERIA = ("mohr-coulomb", "energy-release-rate", "stress-intensity")


# ---------------------------------------------------------------------------------
# The sections
# ---------------------------------------------------------------------------------

TOP = {
    "name": Key("string", doc="short name of the scene (default: the file name)"),
    "description": Key("string", "", doc="one line shown by `hmatddm scenes`"),
    "dimension": Key("integer", 3, choices=(2, 3), doc="2: plane strain in the x-y plane; 3: rectangles in space"),
    "height": Key("number", 1.0, low=0.0, low_open=True, unit="m",
                  doc="2D only: flow height of the plane-strain fractures (ref. Table 4.2)"),
}

STRESS = {
    "tensor": Key("matrix", unit="Pa", doc="full tensor, compressive positive, symmetric"),
    "s_hmin": Key("number", unit="Pa", doc="minimum horizontal stress, compressive positive"),
    "s_hmax": Key("number", unit="Pa", doc="maximum horizontal stress, compressive positive"),
    "s_v": Key("number", unit="Pa", doc="vertical stress (along z), compressive positive; 3D only"),
    "azimuth_deg": Key("number", low=-360.0, high=360.0, unit="deg",
                       doc="direction of s_hmax, degrees from +x counter-clockwise (default 0)"),
}

_POSITIVE_LENGTH = dict(low=0.0, low_open=True, unit="m")
INITIAL_FRACTURE = {
    "shape": Key("choice", choices=("rectangle", "penny", "line"),
                 doc="rectangle (3D, default), penny (3D) or line (2D, default)"),
    "center": Key("point", length=3, unit="m"),
    "e1": Key("point", length=3, doc="rectangle: direction of its length"),
    "e2": Key("point", length=3, doc="rectangle: direction of its height"),
    "normal": Key("point", length=3, doc="penny: its unit normal"),
    "length": Key("number", **_POSITIVE_LENGTH),
    "height": Key("number", **_POSITIVE_LENGTH),
    "radius": Key("number", **_POSITIVE_LENGTH),
    "p0": Key("point", length=2, unit="m"),
    "p1": Key("point", length=2, unit="m"),
    "element_size": Key("number", REQUIRED, **_POSITIVE_LENGTH),
}
SHAPE_KEYS = {  # key -> default (REQUIRED or a value) for each shape
    "rectangle": {"center": [0.0, 0.0, 0.0], "e1": [1.0, 0.0, 0.0], "e2": [0.0, 0.0, 1.0],
                  "length": REQUIRED, "height": REQUIRED, "element_size": REQUIRED},
    "penny": {"center": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0], "radius": REQUIRED, "element_size": REQUIRED},
    "line": {"p0": REQUIRED, "p1": REQUIRED, "element_size": REQUIRED},
}


NUMERICS = settings.NUMERICS
SCHEME_KEYS = tuple(SCHEME)  # -> SchemeSettings

OUTPUT = {
    "every": Key("integer", 1, low=1, doc="write a .vtu every k steps (the last step always)"),
    "vtu": Key("boolean", True),
    "snapshots": Key("boolean", True, doc="PNG views of the last state"),
    "history_plot": Key("boolean", True),
}

REFERENCE = {
    "kind": Key("choice", REQUIRED, choices=REFERENCE_KINDS),
}

NETWORK_MECHANICS = {  # defaults: ref. Table 6.2 (natural-fracture properties)
    "friction_coefficient": NATURAL_FRACTURE["friction_coefficient"],
    "cohesion": NATURAL_FRACTURE["cohesion"],
    "tensile_strength": NATURAL_FRACTURE["tensile_strength"],
    "toughness": NATURAL_FRACTURE["toughness"],
    "critical_radius": NATURAL_FRACTURE["critical_radius"],
    "shear_toughness": NATURAL_FRACTURE["shear_toughness"],
    "rock_shear_toughness": NATURAL_FRACTURE["rock_shear_toughness"],
    "crossing": Key("choice", "mohr-coulomb", choices=CROSSING_CRITERIA),
    "remote_failure": Key("boolean", True),
    "element_size": Key("number", 1.0, **_POSITIVE_LENGTH),
    **settings.NETWORK_GEOMETRY,
}
NETWORK_GENERATOR = settings.NETWORK_GENERATOR
NETWORK = {**NETWORK_MECHANICS, **NETWORK_GENERATOR}

NATURAL_FRACTURE = {
    "p0": Key("point", REQUIRED, length=2, unit="m"),
    "p1": Key("point", REQUIRED, length=2, unit="m"),
}

MICROSEISMIC = settings.MICROSEISMIC  # synthetic monitoring of the run (ref. Ch. 7): hmatddm.microseismic
LAYER = settings.LAYER  # 2D vertical cross-section, y up; tables listed top down (ref. Ch. 3, hmatddm.LayeredMedium)

# name -> (keys, array of tables?, required?)
SECTIONS = {
    "material": (MATERIAL, False, True),
    "fluid": (FLUID, False, True),
    "stress": (STRESS, False, True),
    "cluster": (CLUSTER, True, True),
    "initial_fracture": (INITIAL_FRACTURE, True, True),
    "propagation": (PROPAGATION, False, False),
    "leak_off": (LEAK_OFF, False, False),
    "numerics": (NUMERICS, False, True),
    "output": (OUTPUT, False, False),
    "reference": (REFERENCE, False, False),
    "network": (NETWORK, False, False),
    "natural_fracture": (NATURAL_FRACTURE, True, False),
    "microseismic": (MICROSEISMIC, False, False),
    "layer": (LAYER, True, False),
    "poroelastic": (settings.POROELASTIC, False, False),  # undrained rock (ref. Sec. 5.3.1): build.material
    "monitor": (settings.MONITOR, True, False),  # displacement and tilt at points: hmatddm.app.monitor
    "proppant": (settings.PROPPANT_SECTION, False, False),  # slurry and pump schedule (issue 34): build.proppant
    "well": (settings.WELL, False, False),  # one pump shared by the clusters (issue 35): build.well
}
FILLED_WHEN_ABSENT = ("leak_off", "output")  # optional sections echoed with their defaults
