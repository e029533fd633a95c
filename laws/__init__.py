"""The four built-in friction laws, installed as ``frictionlab.laws``.

They reach the registry through the ``frictionlab.laws`` entry-point group declared in
pyproject.toml, exactly as a third-party law does.
"""
