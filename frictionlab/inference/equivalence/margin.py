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
#: A multiple of the noise: a number (any sign, inf or nan: refused unless positive and finite), then x, σ or sigma.
_MULTIPLE = re.compile(r"^\s*([-+]?(?:[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?|inf(?:inity)?|nan))\s*(?:x|×|σ|sigma|s\.d\.)?\s*$",
                       re.IGNORECASE)


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


#: What a margin may be, said whenever one is refused.
FORMS = "a positive multiple of the noise (e.g. 2) or a positive quantity in the observable's unit (e.g. '150 rpm')"


def parse_margin(value, where: str = "margin") -> Margin:
    """A Margin from what a user gives: a number or '2', '2x', '2 sigma' (a multiple of the noise), a quantity
    string with a unit ('150 rpm') or a pint Quantity. None: the default. Anything not positive and finite is
    refused here, once, naming ``where`` (the parameter or option) and what a margin may be."""
    import numbers

    from ...core.units import check_one_number, check_text, is_quantity, leading_number

    if value is None:
        return Margin()
    if isinstance(value, Margin):
        return value
    refused = ParameterError(f"{where} must be {FORMS}, got {value!r:.60}")
    if isinstance(value, bool):
        raise refused
    if isinstance(value, numbers.Real):
        if not (math.isfinite(value) and value > 0):
            raise refused
        return Margin(float(value))
    if is_quantity(value):
        if str(value.units) == "dimensionless":
            return parse_margin(float(value.magnitude), where)
        value = f"{float(value.magnitude)!r} {value.units}"
    if not isinstance(value, str):
        raise TypeError(f"{where}: expected {FORMS}, got {type(value).__name__} {value!r:.60}")
    try:
        text = check_text(value, where)
        m = _MULTIPLE.match(text)
        if not m:
            check_one_number(text, where, value)
    except FrictionLabError as exc:
        raise ParameterError(str(exc)) from None
    first = float(m.group(1)) if m else leading_number(text)
    if first is None or not (math.isfinite(first) and first > 0):
        raise refused
    return Margin(first) if m else Margin(quantity=text)


def _num(x: float) -> str:
    return f"{x:,.0f}" if abs(x) >= 100 else f"{x:.3g}"
