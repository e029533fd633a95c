"""What a fit returns: parameters with their errors, statistics, per-dataset fits (see ``fitting``)."""
from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING

import attrs
import numpy as np

from ...physics.scene import Scene
from ..diagnostics.identifiability import Identifiability
from .predict import Target

if TYPE_CHECKING:  # annotations only
    import lmfit
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


@attrs.frozen
class ParamResult:
    """A fitted (or held) parameter of a `FitResult`.

    Attributes
    ----------
    name : str
        Display name: ``lam``, or ``u0[impact-golf-v28]`` for a per-dataset scene quantity.
    value, stderr : float
        The value and its standard error in ``unit`` (SI); ``stderr`` None where there is none.
    unit : str
        The SI unit; ``shown`` the unit it is displayed in ("" for ``unit``).
    vary : bool
        Fitted (True) or held (False; ``fixed_by`` says why).
    lower, upper : float
        The bounds of the fit [SI]; ``at_bound`` is "lower" or "upper" when the fit ends at one.
    """

    name: str  # display name: 'lam', or 'u0[impact-golf-v28]' for a per-dataset quantity
    key: str  # law parameter or scene quantity
    kind: str  # 'law' | 'scene'
    value: float
    stderr: float | None
    unit: str
    vary: bool
    initial: float
    lower: float
    upper: float
    datasets: tuple[str, ...]
    fixed_by: str = ""  # why it is held: '' when fitted
    shown: str = ""  # the unit the value is shown in everywhere ("": unit); the law's or the scene quantity's
    at_bound: str = ""  # 'lower' | 'upper' when the fit ends at that bound (identifiability.AT_BOUND_REL): no error bar

    @property
    def bound(self) -> float:
        """The bound the parameter sits at (nan when it is not at one)."""
        return {"lower": self.lower, "upper": self.upper}.get(self.at_bound, math.nan)

    def text(self) -> str:
        """The parameter as one line of text.

        Returns
        -------
        str
            ``"Dc = 397 ± 11 µm"``: the value in its display unit, rounded to its standard error; a parameter at
            a bound says so (``"k = 0.9974 1/µm (at its upper bound 1 1/µm: not identifiable)"``).
        """
        from ...core.display import param_text

        at = (f" (at its {self.at_bound} bound {param_text(self.bound, None, self.unit, self.shown)}: not identifiable)"
              if self.at_bound else "")
        return f"{self.name} = {param_text(self.value, self.stderr, self.unit, self.shown)}{at}"


@attrs.frozen
class Stats:
    """Fit statistics. chisqr uses noise-weighted residuals; rss and rmse are in the observable's
    SI unit (single-dataset fits only, else nan). n_params counts identifiable directions."""

    n_points: int
    n_params: int
    n_free: int
    chisqr: float
    redchi: float
    rss: float
    rmse: float
    aic: float
    aicc: float
    bic: float
    likelihood: str = "estimated"  # 'known' | 'estimated' | 'mixed' | 'none' (see fitting's docstring)
    neg2loglik: float = math.nan  # -2 ln L at the best fit, constant included
    k_lik: int = 0  # parameters counted by AIC/AICc/BIC: n_params (sigma is measured or estimated without the law)
    likelihood_reason: str = ""  # why this likelihood (the dataset's [noise] kind)


@attrs.frozen(eq=False)
class DatasetFit:
    """One dataset's part of a fit: data, best model, residuals (SI) and what produced them."""

    target: Target
    solver: str
    params: dict  # law parameters at the best fit (SI)
    scene: Scene
    model: np.ndarray
    rss: float
    rmse: float
    chisqr: float
    goodness: object = None  # goodness.Goodness of this dataset's residuals

    @property
    def name(self) -> str:
        return self.target.name

    @property
    def residual(self) -> np.ndarray:
        return self.model - self.target.y

    def trajectory(self, law, t=None, n: int = 401):
        """The best-fit trajectory on times t (default: n points over the scene), or None for
        kinds without a time series."""
        from ...solve.solvers import simulate

        if self.target.t is None:
            return None
        if t is None:
            t = np.linspace(0.0, max(self.scene.duration, float(self.target.t[-1])), n)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return simulate(law, self.scene, self.params, solver=self.solver, t=t)


@attrs.frozen(eq=False)
class FitResult:
    """What `fit` returns: parameters with errors, statistics, goodness of fit, identifiability.

    Attributes
    ----------
    law, solver : str
        The law and the solver fitted.
    datasets : tuple of str
        The datasets fitted (several in a global fit).
    status : {"ok", "failed", "skipped"}
        Whether the fit ran; ``reason`` says why it did not. "ok" says nothing about whether the law
        describes the data: ``goodness.fits`` does.
    params : dict of str to ParamResult
        Every parameter, fitted, held or derived, SI.
    correlations : dict of (str, str) to float
        Correlation coefficients between free parameters.
    stats : Stats
        chi-square, reduced chi-square, AIC, BIC, the number of points and of identifiable directions, and
        the likelihood used (known, estimated or stated sigma).
    goodness : Goodness
        The goodness-of-fit tests (chi-square, runs, whiteness) and their verdict, ``goodness.fits``.
    identifiability : Identifiability
        Parameters at a bound, without effect, or correlated; ``identifiability.warnings`` says each.
    notes : tuple of str
        What else a reader should know about this fit.
    velstep : StepReport or None
        A velocity-step fit's parameters in laboratory units.
    """

    law: str
    solver: str
    datasets: tuple[str, ...]
    status: str  # 'ok' | 'failed' | 'skipped'
    reason: str = ""
    params: dict = attrs.field(factory=dict)  # display name -> ParamResult
    correlations: dict = attrs.field(factory=dict)  # (a, b) -> r, free parameters only
    stats: Stats | None = None
    identifiability: Identifiability | None = None
    per_dataset: tuple[DatasetFit, ...] = ()
    nfev: int = 0
    wall_time: float = 0.0  # seconds on the clock
    cpu_time: float = 0.0  # CPU seconds of the fitting thread
    message: str = ""
    notes: tuple[str, ...] = ()
    goodness: object = None  # goodness.Goodness over the fitted datasets (Bonferroni over a group)
    flags: tuple[str, ...] = ()  # plausibility.check: why the fit is physically implausible ('' if none)
    plausibility: dict = attrs.field(factory=dict)  # the numbers behind the flags (SI)
    #: lmfit's MinimizerResult of the best start, in SI (None when nothing was fitted); its parameter
    #: names are identifiers ('lam', 'scene_u0__0'); ``params`` holds the display names.
    minimizer_result: object = attrs.field(default=None, repr=False)
    #: A velocity-step fit's parameters in laboratory units and what they say (``velstep_result.StepReport``);
    #: None for other fits.
    velstep: object = attrs.field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        """True when the fit succeeded (status 'ok')."""
        return self.status == "ok"

    @property
    def lmfit_params(self) -> lmfit.Parameters:
        """The parameters as ``lmfit.Parameters`` in SI (values, standard errors, bounds, correlations),
        named as in ``params`` with characters lmfit does not accept replaced by '_'."""
        from .frames import lmfit_parameters

        return lmfit_parameters(self)

    def fit_report(self, **kwargs: object) -> str:
        """lmfit's fit report of this fit.

        Parameters
        ----------
        **kwargs
            Passed to ``lmfit.fit_report``.

        Returns
        -------
        str
            The report (SI units), frictionlab's statistics first.
        """
        from .frames import fit_report

        return fit_report(self, **kwargs)

    def to_dataframe(self) -> pd.DataFrame:
        """The parameters as a tidy table.

        Returns
        -------
        pandas.DataFrame
            One row per parameter: value, stderr, unit, vary, bounds.
        """
        from .frames import parameters_frame

        return parameters_frame([self])

    def __repr__(self) -> str:
        on = ", ".join(self.datasets)
        if not self.ok:
            return f"<FitResult {self.law} [{self.solver}] on {on}: {self.status}: {self.reason}>"
        ps = ", ".join(p.text() for p in self.params.values() if p.vary or p.kind == "derived")
        return f"<FitResult {self.law} [{self.solver}] on {on}: {ps}; reduced chi2 {self.stats.redchi:.3g}>"

    def plot(self, ax: Axes | Sequence[Axes] | None = None) -> Figure | Axes | Sequence[Axes]:
        """The data with the best fit above and the residuals (in units of sigma) below, one column per
        fitted dataset; the legend says whether the fit passes its goodness-of-fit tests.

        Parameters
        ----------
        ax : matplotlib.axes.Axes or sequence of them, optional
            One Axes per dataset: the data and the fit only, drawn there.

        Returns
        -------
        matplotlib.figure.Figure or Axes
            The new figure, or ``ax`` when given.

        Raises
        ------
        ValueError
            The fit did not run (status "failed" or "skipped"), or ``ax`` has the wrong number of axes.
        """
        from .plots import plot_fit

        return plot_fit(self, ax)

    def _repr_html_(self) -> str:
        from .frames import fit_html

        return fit_html(self)

    def value(self, name: str) -> float:
        """The fitted (or held) value of one parameter.

        Parameters
        ----------
        name : str
            The parameter's display name (``"lam"``, ``"u0[impact-golf-v28]"``).

        Returns
        -------
        float
            Its value, SI.

        Raises
        ------
        KeyError
            No parameter of that name.
        """
        return self.params[name].value

    @property
    def determined(self) -> tuple[str, ...]:
        """Names of the parameters the data determine: the fitted ones, except those without effect
        or entering only through a ratio, plus the derived combinations (e.g. 'eta/h')."""
        ident = self.identifiability
        arbitrary = set(ident.no_effect) | {k for pair in ident.ratio_only for k in pair} if ident else set()
        return tuple(k for k, p in self.params.items()
                     if (p.vary and not {k, p.key} & arbitrary) or p.kind == "derived")

    def stderr(self, name: str) -> float | None:
        """The standard error of one parameter.

        Parameters
        ----------
        name : str
            The parameter's display name.

        Returns
        -------
        float or None
            Its standard error, SI; None where there is none (held, at a bound, not identifiable).
        """
        return self.params[name].stderr

    def summary(self) -> str:
        """A few lines for the terminal.

        Returns
        -------
        str
            The verdict of the goodness-of-fit tests, the statistics, the likelihood, each parameter in its
            display unit rounded to its standard error, and the warnings and notes.

        Examples
        --------
        >>> import frictionlab as fl
        >>> print(fl.fit("wear", "impact-golf-v28", solver="exact").summary().splitlines()[0])
        wear [exact] on impact-golf-v28 (stated): does not fit
        """
        from ...core.display import param_text

        on = ", ".join(d.target.label for d in self.per_dataset) if self.per_dataset else ", ".join(self.datasets)
        if not self.ok:
            return f"{self.law} [{self.solver}] on {on}: {self.status}: {self.reason}"
        # the head gives the verdict of the goodness-of-fit tests, not the optimizer's status ("ok" only says it ran)
        verdict = {True: "fits", False: "does not fit", None: "fitted (goodness of fit not tested)"}[
            None if self.goodness is None else self.goodness.fits]
        head = f"{self.law} [{self.solver}] on {on}: {verdict}"
        s = self.stats
        lines = [head, f"  chi2 = {s.chisqr:.5g}, reduced chi2 = {s.redchi:.4g}, AIC = {s.aic:.5g}, "
                       f"BIC = {s.bic:.5g}, n = {s.n_points}, k = {s.n_params}, nfev = {self.nfev}, "
                       f"{self.wall_time:.2f} s"]
        lines.append(f"  likelihood: {s.likelihood} sigma ({s.likelihood_reason})" if s.likelihood != "none"
                     else f"  likelihood: none ({s.likelihood_reason})")
        if self.goodness is not None:
            verdict = {True: "fits", False: "does not fit", None: "not tested"}[self.goodness.fits]
            lines.append(f"  goodness of fit: {verdict}: {self.goodness.text} ({self.goodness.reason})")
        for flag in self.flags:
            lines.append(f"  FLAG (implausible): {flag}")
        for p in self.params.values():
            held = not p.vary and p.kind != "derived"
            value = param_text(p.value, None if held else p.stderr, p.unit, p.shown)
            err = "held" if held else ("no error bar" if p.stderr is None else "")
            why = f" ({p.fixed_by})" if p.fixed_by else (
                f" (at its {p.at_bound} bound {param_text(p.bound, None, p.unit, p.shown)}: not identifiable)"
                if p.at_bound else "")
            lines.append(f"  {p.name:<28} = {value}{' ' + err if err else ''}{why}")
        for w in self.identifiability.warnings:
            lines.append(f"  warning: {w}")
        for n in self.notes:
            lines.append(f"  note: {n}")
        if self.velstep is not None:  # its notes are the fit's notes, already printed above
            lines += [line for line in self.velstep.lines() if line.strip() not in set(self.notes)]
        return "\n".join(lines)

