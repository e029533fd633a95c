"""The equivalence margin delta: how far apart two laws' best curves may lie and still be called equivalent.

delta is stated in the observable's unit. By default it is MARGIN times the noise the likelihood uses (the
root mean square of the dataset's sigma: measured, estimated from the data, or a reconstruction's stated
precision); ``compare --margin`` and ``fl.compare(margin=...)`` change it, either as another multiple of the
noise (``2``, ``"2x"``, ``"2 sigma"``) or as a quantity in the observable's unit (``"150 rpm"``,
``"0.5 mm/s"``). A reconstruction fitted to its stated numbers measures distances in stated precisions, so
its margin is always a multiple (an absolute margin is refused there, naming the dataset).
"""
from __future__ import annotations

import math
import re

import attrs
import numpy as np

from ...core.errors import FrictionLabError, ParameterError

#: The default margin: delta = MARGIN x the noise sigma. Curves closer than one noise sigma (RMS) differ by less
#: than the scatter of one measurement.
MARGIN = 1.0
_MULTIPLE = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*(?:x|×|σ|sigma|s\.d\.)?\s*$")


@attrs.frozen
class Margin:
    """A margin as asked for: a multiple of the noise (``multiple``) or a quantity (``quantity``, text)."""

    multiple: float = MARGIN
    quantity: str = ""

    @property
    def relative(self) -> bool:
        return not self.quantity

    @property
    def default(self) -> bool:
        return self.relative and self.multiple == MARGIN

    def resolve(self, target, dataset: str = "") -> tuple[float, str]:
        """(delta in the observable's SI unit, or stated precisions, and the sentence that states it) for a
        fit ``target`` (predict.Target)."""
        from ...core.display import unit

        stated = target.observable == "stated"
        sigma = float(np.sqrt(np.mean(np.square(np.asarray(target.sigma, dtype=float)))))
        how = "the default margin" if self.default else "the margin asked for"  # said after a comma
        if self.relative:
            if stated:
                return self.multiple, f"δ = {self.multiple:g} stated precision{'s' * (self.multiple != 1)}, {how}"
            name, f = unit(target.observable)
            delta = self.multiple * sigma
            return delta, f"δ = {self.multiple:g} × σ = {_num(delta * f)} {name}, {how}"
        if stated:
            raise ParameterError(f"margin {self.quantity!r} cannot apply to {dataset or target.name}: it is compared on "
                                 "stated numbers in different units, in stated precisions; give the margin as a "
                                 "multiple of the noise (e.g. --margin 2)")
        from ...core.units import to_si
        from ...io.dataset import COLUMN_SI

        si = COLUMN_SI.get(target.observable, "")
        try:
            delta = to_si(self.quantity, si, "margin")
        except FrictionLabError as exc:
            raise ParameterError(f"margin {self.quantity!r} is not a quantity of {dataset or target.name}'s observable "
                                 f"{target.observable} ({si or 'no unit'}): {exc}") from None
        if not delta > 0:
            raise ParameterError(f"margin {self.quantity!r} must be positive")
        return delta, f"δ = {self.quantity}, {how}"

    def check(self, datasets) -> None:
        """Refuse, before any work, an absolute margin some dataset's observable cannot be measured in."""
        if self.relative:
            return
        from types import SimpleNamespace

        for d in datasets:
            stated = d.noise_kind == "none" and bool(getattr(d, "stated", None))
            fake = SimpleNamespace(observable="stated" if stated else d.observable, sigma=np.ones(1), name=d.name)
            self.resolve(fake, d.name)

    def as_text(self) -> str:
        return self.quantity or f"{self.multiple:g} × σ"


def parse_margin(value) -> Margin:
    """A Margin from what a user gives: a number or '2', '2x', '2 sigma' (a multiple of the noise), or a quantity
    string with a unit ('150 rpm'). None: the default."""
    if value is None:
        return Margin()
    if isinstance(value, Margin):
        return value
    if isinstance(value, bool):
        raise ParameterError(f"margin must be a positive multiple of the noise or a quantity, got {value!r}")
    if isinstance(value, (int, float)):
        if not (math.isfinite(value) and value > 0):
            raise ParameterError(f"margin must be a positive multiple of the noise, got {value!r}")
        return Margin(float(value))
    if not isinstance(value, str) or not value.strip():
        raise ParameterError(f"margin must be a positive multiple of the noise or a quantity, got {value!r}")
    m = _MULTIPLE.match(value)
    if m:
        return parse_margin(float(m.group(1)))
    from ...core.units import check_text

    try:
        check_text(value, "margin")
    except FrictionLabError as exc:
        raise ParameterError(str(exc)) from None
    return Margin(quantity=value.strip())


def _num(x: float) -> str:
    return f"{x:,.0f}" if abs(x) >= 100 else f"{x:.3g}"
