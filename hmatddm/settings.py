"""One declaration per setting: kind, default, range, unit and description.

The scene schema (:mod:`hmatddm.scene.schema`) and the dataclasses the scene builds
(:class:`hmatddm.Propagation`, :class:`hmatddm.SchemeSettings`, ...) read the same
:class:`Setting` objects, so a range, a default or an error message is written once.
Every message names the setting and its allowed range, e.g.
``propagation.toughness must be > 0 Pa m^0.5, got 0``.

This module imports neither numpy nor scipy nor numba: a refused scene answers within a
second (issue 19).
"""
import difflib
import math
from numbers import Integral, Real

from .errors import InputError
from .options import (BACKENDS, CONTACT_MODES, CRITERIA, DEFAULT_EPS, DEFAULT_ETA, DEFAULT_LEAF_SIZE, FRONTS,
                      GROWTH_CHECKS, SCHEME_DEFAULTS, SCHEMES, SINGULAR_CORRECTIONS, STOPPING_RULES, TURNING)

REQUIRED = object()  # marker: the key has no default
ABSENT = object()    # marker: optional key without a default (left out of the echo when not given)
OLSON_CORRECTION = 0.806  # C_cor of ref. Eqs 4.18-4.19 (Olson 1991)


def show(value):
    """A value as error messages print it (numbers with up to 12 significant digits)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:.12g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(show(v) for v in value) + "]"
    if isinstance(value, dict):
        return "a table"
    return repr(value)


class Setting:
    """One setting: its kind, default, range, unit and description (``doc``).

    kind: ``number``, ``number_or_auto`` (a number, or the string ``"auto"``), ``integer``,
    ``boolean``, ``string``, ``choice`` (one of ``choices``),
    ``point`` (``length`` numbers; ``length="dim"`` is the scene dimension),
    ``numbers`` (a non-empty list of numbers, or one number), ``integers`` (a list of
    integers >= 0), ``matrix`` (dim x dim numbers), ``pairs`` (a list of [low, high]), ``rows`` (a
    non-empty list of rows of ``length`` numbers).
    ``low``/``high`` bound numbers (and every entry of a list), open when
    ``low_open``/``high_open``.
    """

    def __init__(self, kind, default=ABSENT, *, low=None, high=None, low_open=False, high_open=False,
                 choices=None, length=None, unit="", doc=""):
        self.kind, self.default = kind, default
        self.low, self.high, self.low_open, self.high_open = low, high, low_open, high_open
        self.choices, self.length, self.unit, self.doc = choices, length, unit, doc

    # -- ranges --------------------------------------------------------------------
    def range_text(self):
        unit = f" {self.unit}" if self.unit else ""
        low, high = self.low, self.high
        if low is not None and high is not None:
            return (f"in {'(' if self.low_open else '['}{show(float(low))}, {show(float(high))}"
                    f"{')' if self.high_open else ']'}{unit}")
        if low is not None:
            return f"{'>' if self.low_open else '>='} {show(float(low))}{unit}"
        if high is not None:
            return f"{'<' if self.high_open else '<='} {show(float(high))}{unit}"
        return f"a finite number{unit}"

    def in_range(self, value):
        if self.low is not None and (value <= self.low if self.low_open else value < self.low):
            return False
        if self.high is not None and (value >= self.high if self.high_open else value > self.high):
            return False
        return True

    # -- checks -----------------------------------------------------------------------
    def _number(self, path, value, what=None):
        what = what or path
        if isinstance(value, bool) or not isinstance(value, Real):
            raise InputError(f"{what} must be a number ({self.range_text()}), got {show(value)}")
        number = float(value)
        if not math.isfinite(number):
            raise InputError(f"{what} must be a finite number ({self.range_text()}), got {show(number)}")
        if not self.in_range(number):
            raise InputError(f"{what} must be {self.range_text()}, got {show(value)}")
        return number

    def _integer(self, path, value):
        if isinstance(value, bool) or not isinstance(value, Integral):
            allowed = f"one of {show(list(self.choices))}" if self.choices else self.range_text()
            raise InputError(f"{path} must be an integer ({allowed}), got {show(value)}")
        if self.choices is not None and value not in self.choices:
            raise InputError(f"{path} must be one of {show(list(self.choices))}, got {show(value)}")
        if not self.in_range(value):
            raise InputError(f"{path} must be an integer {self.range_text()}, got {show(value)}")
        return int(value)

    def _list(self, path, value, length, item_text):
        if not isinstance(value, list):
            raise InputError(f"{path} must be a list of {item_text}, got {show(value)}")
        if length is not None and len(value) != length:
            raise InputError(f"{path} must be a list of {length} {item_text}, got {len(value)}: {show(value)}")
        return value

    def check(self, path, value, dim):
        kind = self.kind
        if kind == "number":
            return self._number(path, value)
        if kind == "number_or_auto":
            if value == "auto":
                return value
            if isinstance(value, str):
                raise InputError(f"{path} must be a number ({self.range_text()}) or \"auto\", got {show(value)}")
            return self._number(path, value)
        if kind == "integer":
            return self._integer(path, value)
        if kind == "boolean":
            if not isinstance(value, bool):
                raise InputError(f"{path} must be true or false, got {show(value)}")
            return value
        if kind == "string":
            if not isinstance(value, str):
                raise InputError(f"{path} must be a string, got {show(value)}")
            return value
        if kind == "choice":
            if not isinstance(value, str) or value not in self.choices:
                hint = ""
                if isinstance(value, str):
                    close = difflib.get_close_matches(value, self.choices, n=1)
                    hint = f"; did you mean {close[0]!r}?" if close else ""
                raise InputError(f"{path} must be one of {', '.join(map(repr, self.choices))}, "
                                 f"got {show(value)}{hint}")
            return value
        if kind == "point":
            length = dim if self.length == "dim" else self.length
            self._list(path, value, length, f"coordinates{f' ({self.unit})' if self.unit else ''}")
            return [self._number(path, v, f"{path}[{i}]") for i, v in enumerate(value)]
        if kind == "numbers":
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                value = [value]
            self._list(path, value, None, "numbers")
            if not value:
                raise InputError(f"{path} must be a non-empty list of numbers, got []")
            return [self._number(path, v, f"{path}[{i}]") for i, v in enumerate(value)]
        if kind == "integers":
            self._list(path, value, None, "integers")
            for i, v in enumerate(value):
                if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                    raise InputError(f"{path}[{i}] must be an integer >= 0, got {show(v)}")
            return [int(v) for v in value]
        if kind == "matrix":
            self._list(path, value, dim, f"rows (a {dim} x {dim} tensor)")
            rows = []
            for i, row in enumerate(value):
                self._list(f"{path}[{i}]", row, dim, "numbers")
                rows.append([self._number(path, v, f"{path}[{i}][{j}]") for j, v in enumerate(row)])
            return rows
        if kind == "points":  # a list of points of `length` coordinates (e.g. well positions)
            self._list(path, value, None, f"[{', '.join(['x', 'y', 'z'][:self.length])}] points")
            return [Setting("point", length=self.length, unit=self.unit).check(f"{path}[{i}]", v, dim)
                    for i, v in enumerate(value)]
        if kind == "rows":  # a non-empty table of rows of `length` finite numbers (e.g. a pump schedule)
            self._list(path, value, None, f"rows of {self.length} numbers")
            if not value:
                raise InputError(f"{path} must hold at least one row of {self.length} numbers, got []")
            rows = []
            for i, row in enumerate(value):
                self._list(f"{path}[{i}]", row, self.length, "numbers")
                rows.append([Setting("number")._number(path, v, f"{path}[{i}][{j}]") for j, v in enumerate(row)])
            return rows
        if kind == "pairs":
            self._list(path, value, None, "[low, high] pairs")
            pairs = []
            for i, pair in enumerate(value):
                if not isinstance(pair, list) or len(pair) != 2:
                    raise InputError(f"{path}[{i}] must be a pair [low, high], got {show(pair)}")
                low, high = (float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None
                             for v in pair)
                if low is None or high is None or math.isnan(low) or math.isnan(high) or not low < high:
                    raise InputError(f"{path}[{i}] must be numbers [low, high] with low < high "
                                     f"(m; +-inf allowed), got {show(pair)}")
                pairs.append([low, high])
            return pairs
        raise AssertionError(kind)  # pragma: no cover

    def value(self, name, value):
        """``value`` checked against this setting outside a scene (a dataclass field):
        ``name`` is how the message names it; ``None`` passes when the setting has no default."""
        if value is None and self.default is ABSENT:
            return None
        if self.kind == "number_or_auto" and value == "auto":
            return value
        if self.kind in ("number", "number_or_auto") and (isinstance(value, bool) or not isinstance(value, Real)):
            try:  # a 0-d array, or a string of a number, as hmatddm._validation.finite_scalar takes them
                value = float(value)
            except (TypeError, ValueError):
                raise InputError(f"{name} must be a finite number ({self.range_text()}), got {show(value)}") from None
        return self.check(name, value, None)


def integer(name, value, minimum=1, maximum=None):
    """``value`` as an int in [``minimum``, ``maximum``] (Python or numpy integer; bools
    refused): the package's one integer check."""
    return Setting("integer", low=minimum, high=maximum).check(name, value, None)


def check_fields(instance, declarations, prefix=""):
    """Check (and convert) the fields of a frozen dataclass ``instance`` that
    ``declarations`` declares, in place; messages name ``prefix + field``."""
    for name, setting in declarations.items():
        if hasattr(instance, name):
            object.__setattr__(instance, name, setting.value(prefix + name, getattr(instance, name)))


# ---------------------------------------------------------------------------------
# Declarations shared by a scene section and the dataclass it builds
# ---------------------------------------------------------------------------------

_UNIT_INTERVAL = dict(low=0.0, high=1.0, low_open=True, high_open=True)

PROPAGATION = {  # -> hmatddm.fracture.growth.Propagation (ref. Sec. 4.2.2)
    "toughness": Setting("number", REQUIRED, low=0.0, low_open=True, unit="Pa m^0.5", doc="K_Ic"),
    "criterion": Setting("choice", "mcs", choices=CRITERIA),
    "critical_energy_release_rate": Setting("number", low=0.0, low_open=True, unit="J/m^2",
                                            doc="G_c (default K_Ic^2 / E')"),
    "correction": Setting("number", OLSON_CORRECTION, low=0.0, high=2.0, low_open=True,
                          doc="C_cor of Olson's SIF estimate (ref. Eqs 4.18-4.19)"),
    "turning": Setting("choice", "plan", choices=TURNING),
    "min_turn_angle_deg": Setting("number", 1.0, low=0.0, high=90.0, high_open=True, unit="deg"),
    "max_growth_passes": Setting("integer", 50, low=0),
    "bounds": Setting("pairs", unit="m"),
    "growing_fractures": Setting("integers"),
    "front": Setting("choice", "element", choices=FRONTS),
    "front_iterations": Setting("integer", 40, low=1),
    "front_tolerance": Setting("number", **_UNIT_INTERVAL,
                               doc="elements; default 1e-2, 1e-3 with leak-off (hmatddm.simulation.asymptotic)"),
}

SCHEME = {  # -> hmatddm.coupled.step_problem.SchemeSettings (ref. Sec. 4.5)
    "scheme": Setting("choice", SCHEME_DEFAULTS["scheme"], choices=SCHEMES),
    "tolerance_pressure": Setting("number", SCHEME_DEFAULTS["tolerance_pressure"], **_UNIT_INTERVAL),
    "tolerance_opening": Setting("number", SCHEME_DEFAULTS["tolerance_opening"], **_UNIT_INTERVAL),
    "max_iterations": Setting("integer", SCHEME_DEFAULTS["max_iterations"], low=1),
    "relaxation": Setting("number", SCHEME_DEFAULTS["relaxation"], low=0.0, high=1.0, low_open=True),
    "min_relaxation": Setting("number", SCHEME_DEFAULTS["min_relaxation"], low=0.0, high=1.0, low_open=True),
    "omega": Setting("number", SCHEME_DEFAULTS["omega"], low=0.0, high=1.0),
    "relaxation_growth": Setting("number", low=1.0,
                                 doc="factor raising alpha after a step without restart (default 2 coupled, "
                                     "1 segregated)"),
    "linear_rtol": Setting("number", SCHEME_DEFAULTS["linear_rtol"], **_UNIT_INTERVAL),
    "linear_restart": Setting("integer", SCHEME_DEFAULTS["linear_restart"], low=1),
    "linear_maxiter": Setting("integer", SCHEME_DEFAULTS["linear_maxiter"], low=1),
    "stopping": Setting("choice", SCHEME_DEFAULTS["stopping"], choices=STOPPING_RULES,
                        doc="change: stop when the change between iterates is below the tolerances; "
                            "contraction: also when the next change, extrapolated from the last two, is"),
    "first_linear_rtol": Setting("number", SCHEME_DEFAULTS["first_linear_rtol"], **_UNIT_INTERVAL,
                                 doc="GMRES relative residual of the first nonlinear iteration of a solve "
                                     "(coupled schemes; at least linear_rtol)"),
    "provisional_linear_rtol": Setting("number", SCHEME_DEFAULTS["provisional_linear_rtol"], **_UNIT_INTERVAL,
                                       doc="relative residual at which the first GMRES solve of a growth-deciding "
                                           "solve pauses first (then tenfold smaller, down to first_linear_rtol): "
                                           "a pass decides there when no tip is near its threshold"),
    "linear_forcing": Setting("number", SCHEME_DEFAULTS["linear_forcing"], low=0.0, high=1.0, high_open=True,
                              doc="coupled schemes: an iterate after the first is solved to this times the "
                                  "last relative change (between linear_rtol and first_linear_rtol; 0: "
                                  "every one to linear_rtol); an accepted iterate is always solved to linear_rtol"),
    "growth_check": Setting("choice", SCHEME_DEFAULTS["growth_check"], choices=GROWTH_CHECKS,
                            doc="element front: first: decide a growth pass on a solve's first (loose) iterate "
                                "and converge only the mesh the step keeps; converged: on the converged solve"),
}

MATERIAL = {  # -> hmatddm.material.Elastic
    "shear_modulus": Setting("number", REQUIRED, low=0.0, low_open=True, unit="Pa"),
    "poisson_ratio": Setting("number", REQUIRED, low=0.0, high=0.5, high_open=True),
}

FLUID = {  # -> hmatddm.flow.fluid.Fluid (ref. Eqs 4.22-4.24)
    "viscosity": Setting("number", ABSENT, low=0.0, low_open=True, unit="Pa s",
                         doc="Newtonian viscosity mu (required when rheology = 'newtonian')"),
    "compressibility": Setting("number", 0.0, low=0.0, unit="1/Pa"),
    # power-law fluids (issue 34, beyond the reference: ref. Sec. 8.2 item 3)
    "rheology": Setting("choice", "newtonian", choices=("newtonian", "power-law"),
                        doc="newtonian (viscosity) or power-law (consistency K, flow_index n: tau = K rate^n)"),
    "consistency": Setting("number", ABSENT, low=0.0, low_open=True, unit="Pa s^n",
                           doc="power-law consistency index K (required when rheology = 'power-law')"),
    "flow_index": Setting("number", 1.0, low=0.0, high=1.0, low_open=True,
                          doc="power-law flow behaviour index n (1: Newtonian, < 1: shear thinning)"),
    "density": Setting("number", 1000.0, low=0.0, low_open=True, unit="kg/m^3",
                       doc="fluid density rho (the perforation and wellbore friction of a [well])"),
    "minimum_shear_rate": Setting("number", 1e-3, low=0.0, low_open=True, unit="1/s",
                                  doc="power-law: below this wall shear rate the fluid flows as a Newtonian "
                                      "one of the apparent viscosity there (keeps a still fluid's conductivity)"),
}

PROPPANT = {  # -> hmatddm.flow.proppant.Proppant (issue 34, beyond the reference: ref. Sec. 8.2 item 2)
    "diameter": Setting("number", REQUIRED, low=0.0, low_open=True, unit="m", doc="particle diameter d"),
    "density": Setting("number", 2650.0, low=0.0, low_open=True, unit="kg/m^3", doc="particle density"),
    "fluid_density": Setting("number", 1000.0, low=0.0, low_open=True, unit="kg/m^3",
                             doc="carrier fluid density"),
    "packing_limit": Setting("number", 0.6, low=0.0, high=1.0, low_open=True, high_open=True,
                             doc="volume fraction c_max of a packed bed"),
    "bridging_factor": Setting("number", 3.0, low=1.0,
                               doc="faces narrower than this many particle diameters carry no proppant"),
    "hindrance_exponent": Setting("number", 4.65, low=0.0,
                                  doc="m of the hindered settling velocity v_Stokes (1 - c)^m (Richardson-Zaki)"),
}

#: [proppant] of a scene: the particles (PROPPANT) and the pump schedule (hmatddm.flow.pump_schedule)
PROPPANT_SECTION = {
    **PROPPANT,
    "schedule": Setting("rows", REQUIRED, length=2,
                        doc="stages [time (s), proppant volume fraction of the pumped slurry, in "
                            "[0, packing_limit)]: each from its time until the next (0 before the first)"),
}

CLUSTER = {  # -> hmatddm.flow.fluid.Cluster (ref. Eqs 4.34-4.35)
    "position": Setting("point", REQUIRED, length="dim", unit="m"),
    "rate": Setting("number", ABSENT, low=0.0, unit="m^3/s",
                    doc="fixed injection rate (required without a [well]; left out with one)"),
    "wellbore_volume": Setting("number", 0.0, low=0.0, unit="m^3"),
    # perforations of a cluster on a shared [well] (issue 35, hmatddm.flow.well)
    "perforations": Setting("integer", ABSENT, low=1, doc="number of perforations n (with a [well])"),
    # bounded so that the orifice law's d^4 stays a finite, non-zero float (a perforation is
    # millimetres to centimetres across)
    "perforation_diameter": Setting("number", ABSENT, low=1e-4, high=1.0, unit="m",
                                    doc="perforation diameter d (with perforations)"),
    "discharge_coefficient": Setting("number", ABSENT, low=0.0, high=1.0, low_open=True,
                                     doc="C_d of the orifice law, in (0, 1] (default 0.6 with perforations)"),
}

#: [well] of a scene -> hmatddm.flow.well.Well (issue 35): one pump shared by the clusters
WELL = {
    "schedule": Setting("rows", REQUIRED, length=2,
                        doc="pump schedule [time (s), rate (m^3/s)] rows in increasing time (rate 0 before the "
                            "first)"),
    "interpolation": Setting("choice", "constant", choices=("constant", "linear"),
                             doc="the rate between rows: held (constant) or interpolated (linear)"),
    "heel": Setting("point", REQUIRED, length="dim", unit="m", doc="where the pump pressure (heel pressure) is"),
    "direction": Setting("point", REQUIRED, length="dim", doc="the well's direction from the heel to the toe"),
    "volume": Setting("number", 0.0, low=0.0, unit="m^3", doc="wellbore volume storing fluid (c_f V)"),
    # bounded so that the Darcy-Weisbach D^5 stays a finite, non-zero float (a casing's inner
    # diameter is a few centimetres to decimetres)
    "diameter": Setting("number", ABSENT, low=1e-3, high=10.0, unit="m",
                        doc="inner diameter (needed with friction_factor > 0)"),
    "friction_factor": Setting("number", 0.0, low=0.0,
                               doc="Darcy friction factor f_D of the pipe between clusters (0: no friction)"),
    # the perforations of every cluster that gives none of its own (one --set changes them all)
    "perforations": CLUSTER["perforations"],
    "perforation_diameter": CLUSTER["perforation_diameter"],
    "discharge_coefficient": CLUSTER["discharge_coefficient"],
}

LEAK_OFF = {  # -> hmatddm.flow.fluid.LeakOff (ref. Eqs 4.25-4.26)
    "coefficient": Setting("number", 0.0, low=0.0, unit="m/(s^0.5 Pa)"),
    "pore_pressure": Setting("number", 0.0, unit="Pa"),
    # or the coefficient from the reservoir (ref. Eq. 4.26, both faces): hmatddm.flow.carter_coefficient
    "permeability": Setting("number", low=0.0, low_open=True, unit="m^2", doc="k_r (1 mD = 9.869e-16 m^2)"),
    "porosity": Setting("number", low=0.0, high=1.0, low_open=True, high_open=True),
    "reservoir_compressibility": Setting("number", low=0.0, low_open=True, unit="1/Pa", doc="total c_t"),
    "reservoir_viscosity": Setting("number", low=0.0, low_open=True, unit="Pa s", doc="of the reservoir fluid"),
}

#: network.* in a scene and the defaults of hmatddm.fracture.crossing.NaturalFractureProperties
#: (one default per field: the natural-fracture runs of ref. Table 6.2).
NATURAL_FRACTURE = {
    "friction_coefficient": Setting("number", 0.25, low=0.0, doc="C (ref. Table 6.2: NF friction coefficient)"),
    "cohesion": Setting("number", 0.0, low=0.0, unit="Pa", doc="S_0 (ref. Table 6.2: NF cohesion)"),
    "tensile_strength": Setting("number", 0.0, low=0.0, unit="Pa", doc="T_0"),
    "toughness": Setting("number", 0.5e6, low=0.0, low_open=True, unit="Pa m^0.5",
                         doc="K_Ic of the natural fractures (ref. Table 6.2: NF K_Ic)"),
    "critical_radius": Setting("number", 0.005, low=0.0, low_open=True, unit="m",
                               doc="r_c of the Mohr-Coulomb crossing criterion (ref. Table 6.2: characteristic "
                                   "length)"),
    "skempton": Setting("number", 0.0, low=0.0, high=1.0, doc="Skempton's B (ref. Eq. 5.18)"),
    "shear_toughness": Setting("number", 0.0, low=0.0, unit="Pa m^0.5",
                               doc="K_IIc of the natural fractures (ref. Eqs 5.15-5.16; energy crossing criterion)"),
    "rock_shear_toughness": Setting("number", 0.0, low=0.0, unit="Pa m^0.5",
                                    doc="K_IIc of the rock (ref. Eqs 5.15-5.16; energy crossing criterion)"),
}

_POSITIVE_LENGTH = dict(low=0.0, low_open=True, unit="m")

OPERATOR = {  # -> hmatddm.elasticity.operator.ElasticityOperator (the H-matrix options, ref. Ch. 5)
    "backend": Setting("choice", "dense", choices=BACKENDS),
    "eps": Setting("number", DEFAULT_EPS, **_UNIT_INTERVAL, doc="ACA tolerance of the admissible blocks"),
    "eta": Setting("number", DEFAULT_ETA, low=0.0, low_open=True, doc="admissibility, min(diam) <= eta * dist"),
    "leaf_size": Setting("integer", DEFAULT_LEAF_SIZE, low=1, doc="largest cluster that is not split"),
    "singular_correction": Setting("choice", "none", choices=SINGULAR_CORRECTIONS),
    "alpha": Setting("number", low=1.0, doc="scaling of the shear unknowns (None: no scaling)"),
}

NUMERICS = {  # [numerics] of a scene -> hmatddm.Simulation, its operator and its SchemeSettings
    "time_step": Setting("number_or_auto", "auto", low=0.0, low_open=True, unit="s",
                         doc='"auto" (default): steps that follow the front (hmatddm.simulation.step_control); '
                             'a number: fixed steps'),
    "end_time": Setting("number", REQUIRED, low=0.0, low_open=True, unit="s"),
    "step_advance": Setting("number", 1.0, low=0.0, low_open=True, high=10.0,
                            doc='time_step = "auto": element rows the front should cross per step'),
    "first_time_step": Setting("number", 0.1, low=0.0, low_open=True, unit="s",
                               doc='time_step = "auto": the first step'),
    "min_time_step": Setting("number", 1e-3, low=0.0, low_open=True, unit="s",
                             doc='time_step = "auto": the shortest step'),
    "max_time_step": Setting("number", low=0.0, low_open=True, unit="s",
                             doc='time_step = "auto": the longest step (default: no bound)'),
    "backend": Setting("choice", "hmatrix", choices=BACKENDS),
    **{key: OPERATOR[key] for key in ("eps", "eta", "leaf_size")},
    **SCHEME,
    "initial_pressure": Setting("number", 0.0, unit="Pa"),
    "initial_opening": Setting("number", 1e-5, low=0.0, unit="m"),
    "minimum_width": Setting("number", low=0.0, low_open=True, unit="m"),
    "singular_correction": OPERATOR["singular_correction"],
    "alpha": OPERATOR["alpha"],
    "contact": Setting("choice", "natural", choices=CONTACT_MODES,
                       doc="elements that close with contact and Coulomb friction: natural, all, none "
                           "(default: all in a scene with natural fractures, natural otherwise; "
                           "all for strong leak-off with a viscous fluid, see hmatddm.Simulation)"),
    "keep_checkpoints": Setting("integer", 3, low=1),
    "max_elements": Setting("integer", 200_000, low=1,
                            doc="refuse a scene (or stop a run, resumably) with more elements than this"),
}

LAYER = {  # a [[layer]] of a scene, and each entry of hmatddm.LayeredMedium's lists (ref. Ch. 3)
    "bottom": Setting("number", unit="m", doc="height of the interface below this layer; omit for the last layer"),
    "shear_modulus": Setting("number", REQUIRED, low=0.0, unit="Pa",
                             doc="0: void (a free surface), top or bottom only"),
    "poisson_ratio": Setting("number", REQUIRED, low=0.0, high=0.5, high_open=True),
    "s_hmin": Setting("number", unit="Pa", doc="compressive stress along x in this layer (default: the [stress] one)"),
    "toughness": Setting("number", low=0.0, low_open=True, unit="Pa m^0.5",
                         doc="K_Ic of this layer (default: propagation.toughness); a void layer's is not used"),
}

LAYERED_MEDIUM = {  # the image-series options of hmatddm.LayeredMedium (ref. Fig. 3.4, Eqs 3.12-3.13)
    "image_tol": Setting("number", 1e-4, **_UNIT_INTERVAL,
                         doc="images='auto' stops when one more image changes a sampled block by less"),
    "gauss_points": Setting("integer", 4, low=1, high=32, doc="Gauss points per sub-segment of the image terms"),
    "method": Setting("choice", "table", choices=("table", "quadrature"),
                      doc="3D: table: the far image triples from a table of the layered remainder, built once per "
                          "medium (hmatddm.layered.remainder_table3d), and a half-space's images in closed form "
                          "(hmatddm.layered.okada3d); quadrature: every triple by quadrature"),
    "table_tol": Setting("number", 1e-8, low=0.0, high=1e-4, low_open=True,
                         doc="error of the remainder table allowed relative to the largest influence entry"),
}

MICROSEISMIC = {  # [microseismic] of a scene (ref. Ch. 7) -> hmatddm.microseismic (Well, Medium, NoiseLevels)
    "wells": Setting("points", REQUIRED, length=2, unit="m", doc="plan positions [x, y] of vertical observation wells"),
    "receiver_top": Setting("number", 20.0, unit="m", doc="ref. Sec. 7.4.2: every 5 m from -20 to 20 m"),
    "receiver_bottom": Setting("number", -20.0, unit="m"),
    "receiver_spacing": Setting("number", 5.0, **_POSITIVE_LENGTH),
    "p_wave_speed": Setting("number", 4000.0, low=0.0, low_open=True, unit="m/s", doc="ref. Table 7.1"),
    "s_wave_speed": Setting("number", 2350.0, low=0.0, low_open=True, unit="m/s"),
    "density": Setting("number", 3000.0, low=0.0, low_open=True, unit="kg/m^3"),
    "shear_ratio": Setting("number", 2.0, low=0.0, doc="events: |slip| >= shear_ratio |opening| (ref. Eq. 7.29)"),
    "rotation_noise_deg": Setting("number", 0.0, low=0.0, unit="deg",
                                  doc="noise standard deviation of the direction (ref. Table 7.2)"),
    "travel_time_noise": Setting("number", 0.0, low=0.0, unit="s", doc="noise standard deviation of t_S - t_P"),
    "amplitude_noise": Setting("number", 0.0, low=0.0, doc="noise standard deviation, share of the largest amplitude"),
    "seed": Setting("integer", 0, low=0),
    "merge": Setting("boolean", False, doc="merge neighbouring elements failing in the same step"),
}

NETWORK_GENERATOR = {  # network.* of a scene -> hmatddm.network.NetworkSpec (ref. Sec. 6.2, Table 6.1)
    "region": Setting("point", length=4, unit="m", doc="[x_min, x_max, y_min, y_max]"),
    "density": Setting("number", low=0.0, low_open=True, unit="1/m^2", doc="rho_NF of ref. Eq. 6.12"),
    "length_exponent": Setting("number", 2.0, low=1.0, doc="a of f(l) ~ l^-a (ref. Eq. 6.1; 1: log-uniform)"),
    "l_min": Setting("number", 1.0, **_POSITIVE_LENGTH),
    "l_max": Setting("number", 30.0, **_POSITIVE_LENGTH),
    "mean_azimuths_deg": Setting("numbers", [45.0], unit="deg"),
    "kappas": Setting("numbers", [5.0], low=0.0, doc="von Mises concentration of the doubled angle"),
    "weights": Setting("numbers", low=0.0, doc="mixing factor of each set, summing to 1 (default: equal)"),
    "seed": Setting("integer", 0, low=0),
    "boundary": Setting("choice", "resample", choices=("resample", "clip")),
}

NETWORK_GEOMETRY = {  # network.* of a scene: the vertical extent of the natural fractures in 3D
    "height": Setting("number", 1.0, **_POSITIVE_LENGTH),
    "z_center": Setting("number", 0.0, unit="m"),
}

POROELASTIC = {  # [poroelastic] of a scene -> hmatddm.fracture.poroelastic.UndrainedRock (ref. Eqs 5.17-5.21)
    "biot": Setting("number", REQUIRED, low=0.0, high=1.0, low_open=True,
                    doc="Biot coefficient alpha = 1 - K/K_s (ref. Eq. 5.20); >= the porosity"),
    "fluid_bulk_modulus": Setting("number", REQUIRED, low=0.0, low_open=True, unit="Pa",
                                  doc="K_f of the reservoir fluid (ref. Table 5.2: oil 2.2 GPa, gas 30 MPa)"),
    "porosity": Setting("number", REQUIRED, low=0.0, high=1.0, low_open=True, high_open=True, doc="phi"),
}

MONITOR = {  # a [[monitor]] of a scene -> hmatddm.app.monitor (displacement and tilt, ref. Eqs 2.43, 2.55-2.57)
    "position": Setting("point", REQUIRED, length="dim", unit="m", doc="where the displacement and tilt are recorded"),
}
