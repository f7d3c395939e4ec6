"""Coupled elasticity-flow solution of a time step (ref. Sec. 4.4)."""
from .._lazy import attach

_EXPORTS = {
    "ElasticSolver": ".elastic", "SCHEMES": ".step_problem", "SchemeSettings": ".step_problem",
    "StepProblem": ".step_problem", "solve_step": ".schemes",
}
__getattr__, __dir__ = attach(__name__, _EXPORTS)

__all__ = ["ElasticSolver", "SCHEMES", "SchemeSettings", "StepProblem", "solve_step"]
