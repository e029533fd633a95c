"""The built-in friction laws, installed as ``frictionlab.laws``: the four of the mission (coulomb, area-rate,
wear, couette), stribeck, and the laws with memory lugre, dahl, rate-state-aging and rate-state-slip.

They reach the registry through the ``frictionlab.laws`` entry-point group declared in
pyproject.toml, exactly as a third-party law does.
"""
