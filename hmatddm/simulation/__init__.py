"""The simulation loop: time stepping, growth passes, records and checkpoints (ref. Ch. 4)."""
from .._lazy import attach

_EXPORTS = {
    "CheckpointError": ".checkpoint", "RECORD_KEYS": ".records", "Simulation": ".simulation", "State": ".state",
    "OperatorSettings": ".settings", "RebuildSettings": ".settings", "CheckpointSettings": ".settings",
    "StepControl": ".step_control",
}
__getattr__, __dir__ = attach(__name__, _EXPORTS)

__all__ = ["Simulation", "State", "RECORD_KEYS", "CheckpointError", "OperatorSettings", "RebuildSettings",
           "CheckpointSettings", "StepControl"]
