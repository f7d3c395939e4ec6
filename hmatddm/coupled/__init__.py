"""Coupled elasticity-flow solution of a time step (ref. Sec. 4.4)."""
from .elastic import ElasticSolver
from .schemes import SCHEMES, SchemeSettings, StepProblem, solve_step

__all__ = ["ElasticSolver", "SCHEMES", "SchemeSettings", "StepProblem", "solve_step"]
