"""The velocity-step fit's parameter table in the field's units (``StepReport``): a value with its error and
interval (``Quantity``), one dataset's row (``StepRow``) and what the fit says beside the table."""
from __future__ import annotations

import math

import attrs


@attrs.frozen
class Quantity:
    """A value with its standard error and 95% interval, in the display unit."""

    value: float
    stderr: float | None
    low: float
    high: float
    unit: str
    held: bool = False  # held by the caller or the dataset (no interval: not fitted)
    bound: str = ""  # 'lower' | 'upper' where the fit ended at that bound (no interval: the bound's value)

    @property
    def digits(self) -> int:
        """Significant digits that resolve the standard error (at least 4)."""
        if not self.stderr or not self.value:
            return 4
        return max(4, min(10, math.ceil(math.log10(abs(self.value) / self.stderr)) + 2))

    @property
    def missing(self) -> str:
        """Why there is no interval: 'held', 'at its lower bound', 'at its upper bound' or 'no interval'."""
        return "held" if self.held else f"at its {self.bound} bound" if self.bound else "no interval"

    def text(self) -> str:
        unit = f" {self.unit}" if self.unit else ""
        if self.stderr is None:
            return f"{self.value:.4g}{unit} ({self.missing})"
        d = self.digits
        return f"{self.value:.{d}g} ± {self.stderr:.2g}{unit} [{self.low:.{d}g}, {self.high:.{d}g}]"


@attrs.frozen
class StepRow:
    """One dataset's velocity-step parameters in laboratory units (a, b, a - b, mu0 and mu_ss plain; Dc in um;
    k and the trend in 1/um)."""

    dataset: str
    law: str
    quantities: dict  # name -> Quantity: 'a', 'b', 'a-b', 'Dc', 'c' (Nagata's law), 'k', 'mu0', 'trend'
    phi: tuple  # (rate label, phi) per rate group, () without the AR(1) model
    steps: tuple  # ((V before, V after) [um/s]) of each step
    fits: bool | None
    goodness: str
    noise: tuple = ()  # (rate label, model name) per rate group of the data's AR(p) model, () otherwise
    whiteness: str = ""  # the noise model's adequacy: the Ljung-Box test of the whitened residuals, in words


@attrs.frozen
class StepReport:
    """What a velocity-step fit says, in the field's units: per dataset the parameter table, the sign of a - b
    against the trend, the parameters at a bound and what that means, and what the law misses."""

    rows: tuple[StepRow, ...]
    sign: tuple[str, ...] = ()
    bounds: tuple[str, ...] = ()
    missing: tuple[str, ...] = ()
    noise: tuple[str, ...] = ()

    ORDER = ("a", "b", "a-b", "Dc", "c", "k", "mu0", "trend")  # c: Nagata's law

    def lines(self) -> list[str]:
        out = []
        for r in self.rows:
            steps = ", ".join(f"{v1:g} -> {v2:g} um/s" for v1, v2 in r.steps)
            out.append(f"  velocity steps of {r.dataset} ({steps}), {r.law}: value ± standard error [95% interval]")
            for name in self.ORDER:
                if name in r.quantities:
                    out.append(f"    {name:<6} = {r.quantities[name].text()}")
            if r.phi:
                out.append("    noise: AR(1), " + ", ".join(f"phi = {p:.3f} ({lab})" for lab, p in r.phi))
            if r.noise:
                out.append("    noise chosen by the data: " + ", ".join(f"{m} at {lab}" for lab, m in r.noise)
                           + (f"; {r.whiteness}" if r.whiteness else ""))
        out += [f"  {s}" for s in self.sign + self.bounds + self.noise + self.missing]
        return out
