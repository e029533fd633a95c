"""Generators of the built-in datasets: ``frictionlab datasets rebuild`` runs them all.

Each module has ``build(out_dir) -> list[Path]`` and writes CSV + TOML pairs reproducibly:
fixed seeds, values rounded to a stated number of significant digits, no time stamps.
"""
from __future__ import annotations

import importlib
from pathlib import Path

#: Generator modules, in the order they run.
GENERATORS = ("golf", "incline", "outcome", "kharaz", "springslider")


def rebuild(out_dir: Path) -> list[Path]:
    """Regenerate every generated built-in dataset into ``out_dir``; returns the files written."""
    out_dir = Path(out_dir)
    written: list[Path] = []
    for name in GENERATORS:
        written += importlib.import_module(f"{__name__}.{name}").build(out_dir)
    return written
