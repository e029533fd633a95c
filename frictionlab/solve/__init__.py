"""Solving a scene under a law: the plan (state vector and right-hand side), the per-scene solvers
(``solvers``: exact, series, ode), the batch engine (vectorized RK, optional numba kernel), impact
outcomes and rebound predictions. Imports ``core`` and ``physics``."""
