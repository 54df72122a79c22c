"""Symbolic formulations (CVXPY / CasADi) and the solver backend registry."""
