'''Scenes: a hydraulic-fracturing simulation described in a TOML file.

    import hmatddm.scene as hs
    scene = hs.load_scene("radial-k")            # an embedded scene, or a path to a .toml file
    sim = hs.build_simulation(scene)             # an hmatddm.Simulation, ready to run
    records = sim.run(scene.numerics["end_time"])
    hs.reference_values(scene.data, records)     # closed-form values at each step

``hmatddm run SCENE --out DIR`` does the same and writes the outputs (see
:mod:`hmatddm.app.runner`). ``hmatddm scenes`` lists the embedded scenes and
``hmatddm scenes NAME`` prints one, a good start for a scene of your own.

Conventions
-----------
* SI units everywhere: Pa, m, s, Pa s, m^3/s, 1/Pa. Angles are in degrees and their
  keys end in ``_deg``.
* Stresses are COMPRESSIVE POSITIVE in the file (``s_hmin = 8e6`` is 8 MPa of
  compression), as engineers write them. The engine counts tension positive: the
  tensor it receives is the negative of the file's (:func:`far_field_stress`).
* Plan view is the x-y plane, z is vertical. A 2D scene is plane strain in the x-y
  plane. ``azimuth_deg`` is the direction of ``s_hmax`` in degrees from +x,
  counter-clockwise; ``s_hmin`` acts perpendicular to it in the x-y plane (so with
  ``azimuth_deg = 0`` hydraulic fractures open along y and grow along x).
* Validation names the key, the value and the allowed range of every problem, and
  refuses unknown keys with a "did you mean" suggestion (InputError).

The format, annotated (``=`` values are the defaults unless marked REQUIRED)::

    name = "my-scene"              # optional; default: file name or embedded name
    description = "one line shown by `hmatddm scenes`"
    dimension = 3                  # 3: rectangular elements in space; 2: plane strain (x-y)
    # height = 1.0                 # 2D only: flow height of the plane-strain fracture, m

    [material]
    shear_modulus = 24e9           # REQUIRED, Pa, > 0
    poisson_ratio = 0.25           # REQUIRED, [0, 0.5)

    [fluid]
    viscosity = 1e-3               # REQUIRED (Newtonian), Pa s, > 0 (1 cP = 1e-3 Pa s)
    compressibility = 4.4e-10      # 1/Pa, >= 0 (default 0)
    rheology = "newtonian"         # "newtonian" or "power-law" (tau = K gamma_dot^n)
    # consistency = 0.1            # power-law: K, Pa s^n, > 0 (default: viscosity, i.e. K = mu)
    # flow_index = 0.5             # power-law: n, (0, 1] (default 1); a viscosity beside a
                                   # consistency is dropped from the echo
    # minimum_shear_rate = 1e-3    # power-law: 1/s, > 0; slower shear flows as Newtonian
    density = 1000.0               # kg/m^3, > 0: perforation and wellbore friction of a [well]

    [stress]                       # compressive positive, Pa; EITHER principal values:
    s_hmin = 8e6                   #   minimum horizontal stress
    s_hmax = 10e6                  #   maximum horizontal stress (>= s_hmin)
    s_v = 12e6                     #   vertical stress (3D only)
    azimuth_deg = 0.0              #   direction of s_hmax from +x, counter-clockwise
    # OR the full tensor (d x d, symmetric, compressive positive):
    # tensor = [[10e6, 0, 0], [0, 8e6, 0], [0, 0, 12e6]]

    [[cluster]]                    # one table per perforation cluster (at least one)
    position = [0.0, 0.0, 0.0]     # REQUIRED, m (d coordinates); must lie on an initial fracture
    rate = 0.01                    # REQUIRED without a [well], m^3/s, >= 0 (2D: into the whole flow
                                   # height); left out with a [well] (its pump schedule sets the rates)
    wellbore_volume = 0.005        # m^3, >= 0 (default 0; 0 with a [well], whose volume stores)
    # perforations = 6             # with a [well]: number of perforations, integer >= 1 (required
                                   # when several clusters share the well; none: no perforation loss)
    # perforation_diameter = 0.01  # with perforations: m, > 0
    # discharge_coefficient = 0.6  # with perforations: C_d in (0, 1] (default 0.6)

    [[initial_fracture]]           # one table per initial fracture; fracture ids 0, 1, ...
    shape = "rectangle"            # 3D: "rectangle" (default) or "penny"; 2D: "line"
    center = [0.0, 0.0, 0.0]       # m
    e1 = [1.0, 0.0, 0.0]           # direction of the length (default +x)
    e2 = [0.0, 0.0, 1.0]           # direction of the height (default +z); normal = e1 x e2
    length = 3.0                   # REQUIRED, m, a whole multiple of element_size
    height = 3.0                   # REQUIRED, m, a whole multiple of element_size
    element_size = 1.0             # REQUIRED, m (square elements)
    # penny: center, normal = [0, 1, 0], radius, element_size (staircase disc)
    # line (2D): p0 = [-1.5, 0.0], p1 = [1.5, 0.0], element_size

    [propagation]                  # leave out for a fixed (non-growing) mesh
    toughness = 5e6                # REQUIRED, K_Ic, Pa m^0.5, > 0
    criterion = "mcs"              # "mcs" (K-bar_I >= K_Ic) or "energy" (G >= G_c)
    # critical_energy_release_rate = 100.0   # G_c, J/m^2 (default K_Ic^2 / E')
    correction = 0.806             # Olson's C_cor, (0, 2]
    turning = "plan"               # "none", "plan" (edges along z may turn) or "any"
    min_turn_angle_deg = 1.0       # [0, 90): smaller turns grow straight
    max_growth_passes = 50         # re-solves of a step after adding elements, >= 0
    # bounds = [[-100, 100], [-100, 100], [-10, 10]]   # m, per-axis limits of new elements
    # growing_fractures = [0]      # fracture ids allowed to grow (default: all)

    [leak_off]                     # Carter leak-off (default: none)
    coefficient = 0.0              # m/(s^0.5 Pa), >= 0 (through both faces)
    pore_pressure = 0.0            # Pa
    # or, instead of coefficient, the reservoir it comes from (ref. Eq. 4.26, both faces):
    # permeability = 1e-16         # m^2, > 0 (1 mD = 9.869e-16 m^2)
    # porosity = 0.1               # (0, 1)
    # reservoir_compressibility = 1e-9   # 1/Pa, > 0, total
    # reservoir_viscosity = 1e-3   # Pa s, > 0, of the reservoir fluid

    [numerics]
    time_step = "auto"             # "auto" (default): steps that follow the front (then:), or s > 0
    # step_advance = 1.0           # element rows the front crosses per step, (0, 10]
    # first_time_step = 0.1        # s, > 0
    # min_time_step = 1e-3         # s, > 0
    # max_time_step = 10.0         # s, > 0 (default: no bound)
    end_time = 30.0                # REQUIRED, s, > 0
    backend = "hmatrix"            # "hmatrix" or "dense"
    eps = 1e-4                     # H-matrix tolerance, (0, 1)
    eta = 3.0                      # admissibility, > 0
    leaf_size = 32                 # elements per leaf cluster, >= 1
    scheme = "krylov"              # "krylov", "fully-coupled", "fracture-compliance", "fixed-width"
    tolerance_pressure = 1e-6      # (0, 1), ref. Eq. 4.43
    tolerance_opening = 1e-6       # (0, 1), ref. Eq. 4.44
    max_iterations = 400           # nonlinear iterations per attempt, >= 1
    relaxation = 1.0               # initial alpha, (0, 1]
    min_relaxation = 0.00390625    # smallest alpha tried, (0, relaxation]
    # relaxation_growth = 2.0      # >= 1, alpha grows back by it after a step without restart
                                   # (default 2 for krylov / fully-coupled, 1 for the segregated)
    omega = 1.0                    # fracture-compliance weight, [0, 1]
    linear_rtol = 1e-9             # GMRES relative residual, (0, 1)
    linear_restart = 100           # GMRES Krylov dimension, >= 1
    linear_maxiter = 20            # GMRES restart cycles, >= 1
    stopping = "contraction"       # "contraction" (also stop on the extrapolated next change) or "change"
    first_linear_rtol = 1e-6       # GMRES relative residual of a solve's first iteration, (0, 1)
    linear_forcing = 0.1           # later iterations: this times the last change (>= linear_rtol), [0, 1)
    growth_check = "first"         # growth pass decided on a solve's first iterate, or "converged"
    provisional_linear_rtol = 1e-4  # that first GMRES solve pauses there first to decide, (0, 1)
    initial_pressure = 10e6        # Pa, fluid pressure at t = 0 (default 0)
    initial_opening = 1e-5         # m, >= 0, opening of the initial elements
    # minimum_width = 1e-5         # m, > 0, width floor of the flow (default initial_opening)
    singular_correction = "none"   # "none" or "average"
    # alpha = 10.0                 # >= 1, influence scaling of ref. Eq. 6.11 (default off)
    keep_checkpoints = 3           # newest checkpoints kept, >= 1
    # contact = "natural"          # elements that close (open / stick / Coulomb slip): "natural",
                                   # "all" or "none"; default "all" when the scene has natural
                                   # fractures (hydraulic elements close too), else "natural"
    max_elements = 200000          # more elements (at the start, or by growth) stop the run with
                                   # exit code 2 and a resumable checkpoint; `--check` prints
                                   # the estimate (elements, memory, time)

    [output]
    every = 1                      # write a .vtu every k steps (the last one always), >= 1
    vtu = true
    snapshots = true               # PNG views of the last state
    history_plot = true

    [reference]                    # optional closed form reported at every step
    kind = "radial-k"              # "radial-k", "radial-m", "radial-km" (3D; K-M transition,
                                   # Dontsov 2016), "kgd-k", "kgd-m" (2D);
                                   # needs one cluster, [propagation] and no leak-off;
                                   # with leak-off: "kgd-k-leak-off", "radial-k-leak-off"
                                   # (the K-K~ edge, Carter leak-off; records C_m too),
                                   # "kgd-m-leak-off", "radial-m-leak-off" (the M~
                                   # vertices; warned off below C_m 10.4 / 11.4),
                                   # "kgd-km-leak-off",
                                   # "radial-km-leak-off" (Dontsov 2017 / 2016 at any
                                   # K_m, C_m; no net pressure);
                                   # or "three-layer-height" (2D, three [[layer]]s: the
                                   # equilibrium height of a symmetric stack under a
                                   # stress contrast, Simonson et al. 1978)
                                   # summary.json's reference rows record the regime number
                                   # K_m and the solution (formula, source); `hmatddm run`
                                   # warns when the vertex does not apply over the run

    # Natural fractures (ref. Ch. 5-6): activated by shear or opening, crossed or
    # deflected at encounters, failed remotely; explicit segments or a generated network.
    [network]                      # properties of every natural fracture (ref. Table 6.2)
    friction_coefficient = 0.25    # >= 0
    cohesion = 0.0                 # Pa, >= 0
    tensile_strength = 0.0         # Pa, >= 0
    toughness = 0.5e6              # Pa m^0.5, > 0
    critical_radius = 0.005        # m, > 0
    shear_toughness = 0.0          # Pa m^0.5, >= 0, K_IIc of the natural fractures (energy criterion)
    rock_shear_toughness = 0.0     # Pa m^0.5, >= 0, K_IIc of the rock (energy criterion)
    crossing = "mohr-coulomb"      # "mohr-coulomb", "energy-release-rate", "stress-intensity"
    remote_failure = true
    element_size = 1.0             # m
    height = 1.0                   # m (3D: vertical rectangles of this height)
    z_center = 0.0                 # m
    # generator (ref. Sec. 6.2, Table 6.1), used when density is given:
    # region = [-50, 50, -100, 100]      # m, [x_min, x_max, y_min, y_max]
    # density = 0.05                     # fractures per m^2 (Eq. 6.12)
    # length_exponent = 2.0              # >= 1
    # l_min = 1.0                        # m
    # l_max = 30.0                       # m
    # mean_azimuths_deg = [45.0]         # one per orientation set
    # kappas = [5.0]                     # >= 0, one per set
    # weights = [1.0]                    # >= 0, summing to 1
    # seed = 0
    # boundary = "resample"              # or "clip"

    [[natural_fracture]]           # explicit natural fractures: plan-view segments
    p0 = [5.0, -10.0]              # m
    p1 = [5.0, 10.0]               # m

    [microseismic]                 # synthetic monitoring (ref. Ch. 7): DIR/events.csv and
                                   # DIR/microseismic_map.png (hmatddm.microseismic)
    wells = [[50.0, 50.0]]         # REQUIRED, plan positions [x, y] of vertical observation wells, m
    receiver_top = 20.0            # m, receivers from receiver_bottom to receiver_top
    receiver_bottom = -20.0        # m
    receiver_spacing = 5.0         # m, > 0
    p_wave_speed = 4000.0          # m/s (ref. Table 7.1; the dynamic moduli follow)
    s_wave_speed = 2350.0          # m/s, < sqrt(3)/2 p_wave_speed
    density = 3000.0               # kg/m^3
    shear_ratio = 2.0              # events: |slip| >= shear_ratio |opening| (ref. Eq. 7.29)
    rotation_noise_deg = 0.0       # standard deviations of the noise (ref. Table 7.2): horizontal
    travel_time_noise = 0.0        #   rotation of the direction cosines (deg), S-P time (s) and
    amplitude_noise = 0.0          #   amplitude, a share of the largest one (ref. Table 7.5)
    seed = 0                       # of the noise
    merge = false                  # one event per element (the reference), or merge neighbours
                                   # that fail in the same step

    [poroelastic]                  # undrained rock (ref. Sec. 5.3.1): [material] holds the drained
                                   # G and nu; the run uses the undrained nu_u (Eq. 5.19) and the
                                   # remote-failure check B (Eq. 5.21); `--check` prints them
    biot = 0.8                     # REQUIRED, alpha = 1 - K/K_s, in (0, 1], >= porosity
    fluid_bulk_modulus = 2.2e9     # REQUIRED, K_f of the reservoir fluid, Pa (gas: 30e6)
    porosity = 0.15                # REQUIRED, in (0, 1)

    [proppant]                     # sand carried by the slurry (issue 34; hmatddm.simulation.proppant_step):
                                   # advected with the fluid after each step's solve, hindered settling
                                   # along the vertical (z; 2D only in a layered cross-section),
                                   # Maron-Pierce slurry viscosity, bridging, the packed bed a closing
                                   # element keeps (with contact); summary.json proppant_injected_mass,
                                   # proppant_mass (kg), .vtu proppant_fraction, propped_width,
                                   # snapshots/step-NNNNNN_proppant.png, proppant_history.png
    diameter = 2e-4                # REQUIRED, m, > 0, particle diameter
    density = 2650.0               # kg/m^3, > 0
    fluid_density = 1000.0         # kg/m^3, > 0, carrier fluid (settling)
    packing_limit = 0.6            # (0, 1), volume fraction of a packed bed
    bridging_factor = 3.0          # >= 1: faces narrower than this many diameters carry no proppant
    hindrance_exponent = 4.65      # >= 0, Richardson-Zaki: v = v_Stokes (1 - c)^m
    schedule = [[0.0, 0.0], [5.0, 0.1]]   # REQUIRED, [time (s), volume fraction in [0, packing_limit)]
                                   # stages in increasing time, each held until the next (0 before
                                   # the first); every cluster pumps this slurry

    [well]                         # one pump shared by the clusters (issue 35; hmatddm.flow.well): the
                                   # rate into each cluster follows from the heel pressure less the
                                   # wellbore friction and the perforation friction
                                   # dp = 8 rho q^2 / (pi^2 C_d^2 n^2 d^4), solved inside every step;
                                   # summary.json cluster_rates, cluster_pressures, perforation_friction,
                                   # heel_pressure; DIR/rate_split.png
    schedule = [[0.0, 0.02]]       # REQUIRED, [time (s), rate (m^3/s, >= 0)] rows in increasing time
    interpolation = "constant"     # "constant" (held until the next row) or "linear"; 0 before the first
    heel = [0.0, -50.0, 0.0]       # REQUIRED, m: the pump's end of the well (heel pressure)
    direction = [0.0, 1.0, 0.0]    # REQUIRED: from the heel to the toe; every cluster on this line
    volume = 10.0                  # m^3, >= 0: wellbore storage c_f V at the heel pressure
    # diameter = 0.1               # m, > 0: inner diameter (required with friction_factor > 0)
    friction_factor = 0.0          # >= 0, Darcy f_D between clusters: dp = 8 f_D rho L Q^2 / (pi^2 D^5)
                                   # (fluid.density rho, default 1000 kg/m^3)
    # perforations = 6             # the perforations of every [[cluster]] that gives none of its own
    # perforation_diameter = 0.01  #   (count >= 1, diameter m > 0, discharge_coefficient in (0, 1],
    # discharge_coefficient = 0.6  #   default 0.6): `--set well.perforations=1` limits the entry

    [[monitor]]                    # displacement and tilt at a point after every step: DIR/monitor.csv
    position = [0.0, 0.0, 50.0]    # and DIR/monitor.png (hmatddm.app.monitor); layered rock too
'''
import difflib
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from .._lazy import attach
from ..errors import InputError
from .schema import far_field_stress, has_natural_fractures, to_toml, validate

# .build imports the engine (Simulation, scipy.special through the closed forms): it loads
# on first use, so that validating and refusing a scene stays quick
__getattr__, __dir__ = attach(__name__, {name: ".build" for name in (
    "build_simulation", "natural_mesh", "natural_network", "natural_properties", "confining_stress", "initial_mesh",
    "reference_curves", "reference_values", "reference_regime", "reference_warning")})


@dataclass(frozen=True)
class Scene:
    """A validated scene: ``data`` is the echo (every default filled in, SI units),
    ``source`` the file it came from (or ``embedded:NAME``), ``text`` its TOML text."""

    data: dict
    source: str = "<dict>"
    text: str = ""

    @property
    def name(self):
        return self.data["name"]

    @property
    def description(self):
        return self.data.get("description", "")

    @property
    def dimension(self):
        return self.data["dimension"]

    @property
    def numerics(self):
        return self.data["numerics"]

    @property
    def has_natural_fractures(self):
        return has_natural_fractures(self.data)

    def to_dict(self):
        """The validated scene as a plain, JSON-able dict (a deep copy)."""
        import copy

        return copy.deepcopy(self.data)

    def to_toml(self, header=None):
        return to_toml(self.data, header)


def _scenes_folder():
    return resources.files(__name__).joinpath("scenes")


def embedded_names():
    """Names of the scenes shipped in the package, sorted ("default" first)."""
    names = [Path(entry.name).stem for entry in _scenes_folder().iterdir() if entry.name.endswith(".toml")]
    return sorted(names, key=lambda name: (name != "default", name))


def embedded_text(name):
    """TOML text of an embedded scene; InputError with a suggestion for an unknown name."""
    names = embedded_names()
    if name not in names:
        close = difflib.get_close_matches(name, names, n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise InputError(f"unknown scene {name!r}: {hint}embedded scenes are {', '.join(names)} "
                         "(or give the path of a .toml file)")
    return _scenes_folder().joinpath(f"{name}.toml").read_text(encoding="utf-8")


def embedded_scenes():
    """``{name: description}`` of every embedded scene (read, not validated: the tests
    validate them, and listing them stays instant)."""
    return {name: str(_parse(embedded_text(name), f"embedded scene {name!r}").get("description", ""))
            for name in embedded_names()}


def _parse(text, source):
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise InputError(f"{source} is not valid TOML: {error}") from None


def parse_scene(text, name=None, source="<string>", overrides=()):
    """Validate scene TOML ``text``; ``name`` is used when the text has no ``name`` key;
    ``overrides`` are ``"section.key=value"`` strings applied before validation (see
    :func:`apply_override`)."""
    raw = _parse(text, source)
    for override in overrides:
        apply_override(raw, override)
    return Scene(validate(raw, name=None if "name" in raw else (name or "scene")), source, text)


def load_scene(scene, overrides=()):
    """A scene from an embedded name (``"radial-k"``) or a TOML file path.

    A string that names an existing file, or ends in ``.toml``, is read as a file;
    anything else is looked up among the embedded scenes. The scene's ``name`` is the
    one in the file, else the file's stem (or the embedded name).
    """
    if isinstance(scene, Scene):
        return scene
    text_name = str(scene)
    path = Path(text_name)
    if path.suffix == ".toml" or path.is_file() or "/" in text_name:
        if not path.is_file():
            raise InputError(f"scene file {text_name!r} does not exist")
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as error:
            raise InputError(f"scene file {text_name!r} cannot be read: {error}") from None
        raw = _parse(text, text_name)
        default_name, source = path.stem, str(path)
    else:
        text = embedded_text(text_name)
        raw = _parse(text, f"embedded scene {text_name!r}")
        default_name, source = text_name, f"embedded:{text_name}"
    for override in overrides:
        apply_override(raw, override)
    return Scene(validate(raw, name=None if "name" in raw else default_name), source, text)


def scene_from_dict(data, source="<dict>"):
    """Validate a scene given as a dict (e.g. the ``scene`` echo of a summary.json)."""
    return Scene(validate(data), source)


def apply_override(raw, assignment):
    """Apply ``"section.key=value"`` (or ``"cluster[0].rate=0.02"``, or a top-level
    ``"dimension=2"``) to a raw scene dict. The value is read as a TOML value (numbers,
    booleans, arrays, quoted strings); anything unreadable is taken as a string."""
    if "=" not in assignment:
        raise InputError(f"--set expects KEY=VALUE (e.g. numerics.end_time=10), got {assignment!r}")
    key, text = (part.strip() for part in assignment.split("=", 1))
    try:
        value = tomllib.loads(f"value = {text}")["value"]
    except tomllib.TOMLDecodeError:
        value = text
    parts = key.split(".")
    if not all(parts) or len(parts) > 2:
        raise InputError(f"--set key must be KEY, SECTION.KEY or SECTION[i].KEY, got {key!r}")
    if len(parts) == 1:
        raw[key] = value
        return raw
    section, leaf = parts
    index = None
    if section.endswith("]") and "[" in section:
        section, _, number = section[:-1].partition("[")
        if not number.isdigit():
            raise InputError(f"--set key {key!r}: the index in {section}[...] must be an integer >= 0")
        index = int(number)
    table = raw.setdefault(section, {} if index is None else [])
    if isinstance(table, list):
        position = 0 if index is None else index
        if position >= len(table):
            raise InputError(f"--set key {key!r}: the scene has {len(table)} [[{section}]] table(s)")
        table = table[position]
    elif index not in (None, 0):
        raise InputError(f"--set key {key!r}: [{section}] is a single table, use {section}.{leaf}")
    table[leaf] = value
    return raw


__all__ = ["Scene", "load_scene", "parse_scene", "scene_from_dict", "embedded_names", "embedded_text",
           "embedded_scenes", "apply_override", "validate", "build_simulation", "initial_mesh",
           "reference_values", "reference_curves", "reference_regime", "reference_warning",
           "confining_stress", "far_field_stress",
           "has_natural_fractures", "to_toml", "natural_mesh", "natural_network", "natural_properties"]
