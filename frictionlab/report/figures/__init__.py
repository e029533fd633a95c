"""Report figures as PNG bytes (matplotlib, Agg backend). Display units: rpm, deg, us/ms/s, N.

Each function takes results and returns PNG bytes; nothing here fits or ranks. One module per kind of
figure; ``base`` holds what they share.
"""
from .base import (DPI, EXTRA_COLORS, LAW_COLORS, SAME_CURVE, _plt, _png, distinct_curves, is_png, same_curve,
                   simplest_first)
from .derivation import derivation_figure
from .equivalence import discrimination_figure, equivalence_figure
from .finding import group_figure
from .fits import column_unit, fit_figure, force_figure, outcome_figure
from .ranking import ranking_figure

__all__ = ["DPI", "EXTRA_COLORS", "LAW_COLORS", "SAME_CURVE", "_plt", "_png", "column_unit", "derivation_figure",
           "discrimination_figure", "distinct_curves", "equivalence_figure", "fit_figure", "group_figure",
           "force_figure", "is_png", "outcome_figure", "ranking_figure", "same_curve", "simplest_first"]
