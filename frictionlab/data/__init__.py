"""Built-in datasets (CSV + TOML pairs), installed as ``frictionlab.data``. See README: Datasets."""
