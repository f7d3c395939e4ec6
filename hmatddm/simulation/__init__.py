"""The simulation loop: time stepping, growth passes, records and checkpoints (ref. Ch. 4)."""
from .._lazy import attach

_EXPORTS = {
    "CheckpointError": ".checkpoint", "RECORD_KEYS": ".simulation", "Simulation": ".simulation",
    "State": ".simulation",
}
__getattr__, __dir__ = attach(__name__, _EXPORTS)

__all__ = ["Simulation", "State", "RECORD_KEYS", "CheckpointError"]
