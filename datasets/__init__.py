"""Built-in datasets (CSV + TOML sidecars), installed as ``frictionlab.data``."""
