"""The option groups of a :class:`~hmatddm.Simulation`: how its elasticity operator is
built, when a grown operator is rebuilt, and where its checkpoints go.

``Simulation`` takes each group as an object (``operator_settings=OperatorSettings(...)``)
or, as before, as flat keywords (``backend="dense", eps=1e-6``); :func:`group_options`
sorts the flat keywords into their groups.
"""
from dataclasses import dataclass, fields

from .._validation import finite_scalar
from ..errors import InputError
from ..options import DEFAULT_EPS, DEFAULT_ETA, DEFAULT_LEAF_SIZE
from ..settings import NUMERICS, OPERATOR


@dataclass(frozen=True)
class OperatorSettings:
    """Passed to :class:`~hmatddm.ElasticityOperator` at every build; checked against
    :data:`hmatddm.settings.OPERATOR` (the values are kept as given: they enter the
    run's fingerprint)."""

    backend: str = "hmatrix"
    eps: float = DEFAULT_EPS
    eta: float = DEFAULT_ETA
    leaf_size: int = DEFAULT_LEAF_SIZE
    singular_correction: str = "none"
    alpha: float = None

    def __post_init__(self):
        for name, setting in OPERATOR.items():
            setting.value(name, getattr(self, name))


@dataclass(frozen=True)
class RebuildSettings:
    """``hmatrix`` backend: elements added by growth join the operator as exact border
    blocks (:class:`~hmatddm.elasticity.extended.ExtendedElasticityOperator`) until they
    exceed ``rebuild_fraction`` of the compressed elements or the border exceeds
    ``max_border_bytes``; then the H-matrix is rebuilt."""

    rebuild_fraction: float = 0.25
    max_border_bytes: float = 2**28

    def __post_init__(self):
        fraction = finite_scalar("rebuild_fraction", self.rebuild_fraction)
        if not 0.0 <= fraction <= 10.0:
            raise InputError(f"rebuild_fraction must be in [0, 10], got {fraction}")
        object.__setattr__(self, "rebuild_fraction", fraction)
        object.__setattr__(self, "max_border_bytes", finite_scalar("max_border_bytes", self.max_border_bytes))

    def border_fits(self, compressed, added, dof, entries_per_pair=None, bytes_per_added=None, base_bytes=None):
        """Whether ``added`` elements may join ``compressed`` ones (``dof`` unknowns per
        element) as border blocks; ``entries_per_pair``: the border entries an element
        pair stores (default ``dof**2``; a planar crack's split operator stores 1 for its
        opening part, 4 more once its shear part is built). ``bytes_per_added``: what
        ``A_on`` and ``A_no`` hold per added element when they are compressed
        (:mod:`hmatddm.elasticity.extended`); None: dense, ``2 x compressed`` pairs. The
        added elements' own block ``A_nn`` is dense (``added**2`` pairs) either way, and its
        block LU holds about twice as much again; ``base_bytes`` (the base H-matrix's
        memory, given with compressed borders): ``A_nn`` and its factors may not outgrow
        it, so that they never cost a product more than the base does (on the h = 0.25 m
        radial K run, compressed borders with ``A_nn`` allowed a quarter of the base took
        309.7 s of CPU against 288.0 s for the dense borders of the version before, in one
        session on a shared machine; benchmarks/RESULTS.md, issue 33)."""
        entries = dof * dof if entries_per_pair is None else entries_per_pair
        border = 8.0 * entries * 2 * compressed * added if bytes_per_added is None else bytes_per_added * added
        own = 8.0 * entries * added * added
        border_bytes = border + own
        return (added <= self.rebuild_fraction * compressed and border_bytes <= self.max_border_bytes
                and (base_bytes is None or 3.0 * own <= base_bytes))


@dataclass(frozen=True)
class CheckpointSettings:
    """Where a checkpoint is written after every step (None: nowhere), and how many of
    the newest are kept."""

    checkpoint_dir: object = None
    keep_checkpoints: int = 3

    def __post_init__(self):
        object.__setattr__(self, "keep_checkpoints",
                           NUMERICS["keep_checkpoints"].value("keep_checkpoints", self.keep_checkpoints))


GROUPS = {"operator_settings": OperatorSettings, "rebuild_settings": RebuildSettings,
          "checkpoint_settings": CheckpointSettings}


def group_options(options, **given):
    """The settings objects of ``given`` (``operator_settings=...``, None where not given)
    completed from the flat keywords ``options`` (``backend="dense"``, ...), as a dict
    keyed like ``given``. A flat keyword beside its group's object is refused; an
    unknown keyword is a TypeError, as for any function."""
    names = {f.name: group for group, kind in GROUPS.items() for f in fields(kind)}
    unknown = sorted(set(options) - set(names))
    if unknown:
        raise TypeError(f"Simulation() got an unexpected keyword argument {unknown[0]!r}")
    grouped = {}
    for group, kind in GROUPS.items():
        flat = {name: value for name, value in options.items() if names[name] == group}
        settings = given.get(group)
        if settings is None:
            settings = kind(**flat)
        elif not isinstance(settings, kind):
            raise InputError(f"{group} must be an hmatddm.simulation.{kind.__name__} or None, "
                             f"got {type(settings).__name__}")
        elif flat:
            raise InputError(f"give {', '.join(sorted(flat))} either in {group} or as keywords, not both")
        grouped[group] = settings
    return grouped
