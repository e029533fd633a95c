"""Small text helpers shared by the report's sections (numbers as table cells, percentages, words)."""
from __future__ import annotations

import math

from ..core.display import fmt

PROVENANCE_WORDS = {
    "measured": "measured",
    "reported": "values reported in a publication",
    "reconstructed": "RECONSTRUCTED from published numbers, not measured",
    "synthetic": "SYNTHETIC, made up (by a model or by hand), not measured",
}


def fixed(x, digits: int) -> str:
    return "" if x is None or not math.isfinite(x) else f"{x:.{digits}f}"


def pct(x: float) -> str:
    return f"{100 * x:.0f}%" if math.isfinite(x) else ""


def rtol_text(r: float) -> str:
    return f"{r:.0e}".replace("e-0", "e-")


def sig(x, digits: int = 3) -> str:
    """A table number with ``digits`` significant figures ('' for None/nan)."""
    return fmt(x, digits)


def micro(text: str) -> str:
    """'40 um', '500 us' as a file may spell them, written '40 µm', '500 µs' as the figures and tables do."""
    import re

    return re.sub(r"(?<=\d) u([sm])\b", r" µ\1", text)
