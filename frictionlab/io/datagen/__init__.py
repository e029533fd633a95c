"""Generators of the built-in datasets: ``frictionlab datasets rebuild`` runs them all.

Each module has ``build(out_dir) -> list[Path]`` and writes CSV + TOML pairs reproducibly:
fixed seeds, values rounded to a stated number of significant digits, no time stamps.
"""
from __future__ import annotations

import importlib
from pathlib import Path

#: Generator modules, in the order they run.
GENERATORS = ("golf", "incline", "outcome", "kharaz", "springslider")
#: Generators of the known-truth folder (``examples/known-truth``, never built in): datasets the
#: project's defaults were not tuned on, for checking its verdicts.
KNOWN_TRUTH = ("knowntruth",)
KNOWN_TRUTH_DIR = Path("examples") / "known-truth"
#: The synthetic slide-hold-slide record (``examples/slide-hold-slide``): the healing table's known truth.
SLIDE_HOLD_SLIDE = ("holds",)
SLIDE_HOLD_SLIDE_DIR = Path("examples") / "slide-hold-slide"


def rebuild(out_dir: Path, generators=GENERATORS) -> list[Path]:
    """Regenerate every dataset of ``generators`` (default: the built-in ones) into ``out_dir``;
    returns the files written."""
    out_dir = Path(out_dir)
    written: list[Path] = []
    for name in generators:
        written += importlib.import_module(f"{__name__}.{name}").build(out_dir)
    return written
