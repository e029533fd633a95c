"""Data in and out: datasets (CSV + TOML sidecar, loaded into SI arrays), templates for a dataset of
one's own, and the generators of the built-in datasets (``datagen``). Imports ``core``, ``physics`` and
``solve``. (The built-in dataset files themselves are the package ``frictionlab.data``.)"""
