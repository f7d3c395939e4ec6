"""The simulation loop: time stepping, growth passes, records and checkpoints (ref. Ch. 4)."""
from .checkpoint import CheckpointError
from .simulation import RECORD_KEYS, Simulation, State

__all__ = ["Simulation", "State", "RECORD_KEYS", "CheckpointError"]
