"""Prediction across conditions: does one parameter set of a law serve every dataset of a group?

A law is a material statement: the same lambda (or mu, eta') should describe a golf ball at 28
and at 61 m/s. Within a dataset group (``answers.group_of``), for every candidate (law [solver])
that fitted every member:

* Transfer: the law parameters fitted on one member (the source) predict each other member (the
  target) without refitting; scene quantities (u0, A0, t_c, a freed quantity) and the target's
  ``[fixed]`` values stay the target's own. Predictive error: chi2 = sum(((pred - y) / sigma)^2)
  with the target's declared sigma, its RMS in noise sigmas sqrt(chi2 / n), and the predictive
  Gaussian log-likelihood -chi2 / 2 - sum(ln(sigma sqrt(2 pi))). Every ordered pair is predicted
  (28 -> 61 and 61 -> 28); candidates are ranked by their summed predictive chi2.
* Shared against separate: one global fit with a single law parameter set for the whole group
  (``fitting.fit`` on all members; started from each member's own fit, the lowest chi2 kept)
  against the members' separate fits. The likelihood-ratio statistic LR = -2 ln L_shared +
  2 ln L_separate (with known noise: chi2_shared - chi2_separate; with an assumed sigma profiled per
  dataset, from ``Stats.neg2loglik`` when the fit carries it) is asymptotically chi-square with
  dk = k_separate - k_shared degrees of freedom (p-value); delta-AIC = AIC_shared - AIC_separate = LR - 2 dk.
  One parameter set serves the group when p >= ALPHA (the data do not ask for separate values).

``transfer(fits, group_of=answers.group_of)`` returns one ``TransferResult`` per group with at
least two fitted members; ``transfer_group`` does one group (it is what ``compare`` runs on its pool).
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import attrs
import numpy as np

from ...core.errors import FrictionLabError
from ...physics.registry import get_law
from ..fitting.model import held_value
from ..fitting.fit import FitResult, fit, predict
from ..diagnostics.goodness import p_short

ALPHA = 0.05  # level of the likelihood-ratio test of shared against separate parameters


@attrs.frozen
class Prediction:
    """One candidate's parameters from ``source`` predicting ``target`` without refitting."""

    law: str
    solver: str
    source: str
    target: str
    status: str  # ok | failed
    reason: str = ""
    n: int = 0
    chi2: float = math.nan  # predictive chi-square at the target's declared noise
    rms_sigma: float = math.nan  # sqrt(chi2 / n): RMS prediction error in noise sigmas
    loglik: float = math.nan  # predictive Gaussian log-likelihood
    own_chi2: float = math.nan  # the target's own fit of the same candidate, for scale
    params: dict = attrs.field(factory=dict)  # law parameters used (SI)

    @property
    def candidate(self) -> str:
        return f"{self.law} [{self.solver}]"

    def as_dict(self) -> dict:
        return attrs.asdict(self)


@attrs.frozen
class SharedFit:
    """One law parameter set for the whole group against separate fits per member."""

    law: str
    solver: str
    datasets: tuple[str, ...]
    status: str  # ok | failed | skipped
    reason: str = ""
    chi2_shared: float = math.nan  # -2 ln L of the shared fit (chi2 with known noise; see _neg2ll)
    k_shared: int = 0
    chi2_separate: float = math.nan  # sum of the separate fits' -2 ln L
    k_separate: int = 0
    lr: float = math.nan  # chi2_shared - chi2_separate
    dk: int = 0
    p_value: float = math.nan
    delta_aic: float = math.nan  # AIC_shared - AIC_separate = lr - 2 dk (known noise)
    shared: dict = attrs.field(factory=dict)  # param -> SI value of the shared fit (eta/h for a ratio-only pair)
    separate: dict = attrs.field(factory=dict)  # dataset -> {param: SI value}, likewise

    @property
    def candidate(self) -> str:
        return f"{self.law} [{self.solver}]"

    @property
    def serves(self) -> bool | None:
        """Does one parameter set serve every member (LR test at ALPHA)? None when not tested."""
        return None if self.status != "ok" or not math.isfinite(self.p_value) else bool(self.p_value >= ALPHA)

    def as_dict(self) -> dict:
        return {**attrs.asdict(self), "serves": self.serves, "alpha": ALPHA}


@attrs.frozen
class TransferResult:
    """Transfer predictions and shared-against-separate fits of one dataset group."""

    group: str
    datasets: tuple[str, ...]
    predictions: tuple[Prediction, ...]
    shared: tuple[SharedFit, ...]
    status: str = "ok"  # ok | skipped
    reason: str = ""  # why skipped

    def ranking(self) -> list[dict]:
        """Candidates by summed predictive chi2 over every ordered pair, best first (only those that
        predicted every pair): candidate, chi2, n, rms_sigma, loglik, rank."""
        by: dict[str, list[Prediction]] = {}
        for p in self.predictions:
            by.setdefault(p.candidate, []).append(p)
        rows = []
        for cand, ps in by.items():
            if all(p.status == "ok" for p in ps):
                chi2, n = sum(p.chi2 for p in ps), sum(p.n for p in ps)
                rows.append({"candidate": cand, "chi2": chi2, "n": n, "rms_sigma": math.sqrt(chi2 / n) if n else math.nan,
                             "loglik": sum(p.loglik for p in ps)})
        rows.sort(key=lambda r: r["chi2"])
        for i, r in enumerate(rows):
            r["rank"] = i + 1
        return rows

    def answer(self) -> str:
        """One sentence for the report's first screen: does one parameter set serve the group, and
        which candidate predicts across conditions best."""
        rank = self.ranking()
        if self.status == "skipped":
            return f"not tested: {self.reason}"
        if not rank:
            return "not tested: no candidate could predict across the group"
        best = rank[0]
        sh = {s.candidate: s for s in self.shared}
        serves = [c for c, s in sh.items() if s.serves]
        members = " and ".join(self.datasets) if len(self.datasets) == 2 else f"all {len(self.datasets)} datasets"
        head = (f"one parameter set serves {members}: " + ("yes for " + ", ".join(serves) if serves else "no, for no law")
                if sh else "")
        s = sh.get(best["candidate"])
        detail = (f" (LR test p = {_p(s.p_value)}, delta-AIC shared - separate = {s.delta_aic:.1f})"
                  if s is not None and s.status == "ok" else "")
        return (f"{head}; best prediction across conditions: {best['candidate']}, {best['rms_sigma']:.3g} noise sigmas "
                f"RMS{detail}").lstrip("; ")

    def short(self, best: str | None = None) -> str:
        """'one wear [series] fit for both: no (p = 1e-8)': does one parameter set of the group's best law
        (``best`` as in Answer.best, 'wear = couette [series]'; default: the best-predicting candidate) serve
        every member, by the shared-against-separate test."""
        if self.status == "skipped":
            return "no transfer: " + ("different observables" if "observables" in self.reason else
                                      "no fitting law" if "no fitting law" in self.reason else self.reason)
        sh = {s.candidate: s for s in self.shared if s.status == "ok"}
        rank = self.ranking()
        mine = _candidates(best) if best else ([rank[0]["candidate"]] if rank else [])
        s = next((sh[c] for c in mine if c in sh), None)
        if s is None:
            return "no transfer tested"
        who = "both" if len(self.datasets) == 2 else "all"
        p = ("" if s.p_value == 0 else "= ") + p_short(s.p_value)
        return f"one {s.candidate} fit for {who}: {'yes' if s.serves else 'no'} (p {p})"

    def as_dict(self) -> dict:
        return {"group": self.group, "datasets": list(self.datasets), "alpha": ALPHA, "status": self.status,
                "reason": self.reason,
                "predictions": [p.as_dict() for p in self.predictions], "shared": [s.as_dict() for s in self.shared],
                "ranking": self.ranking(), "answer": self.answer()}


def _candidates(best: str) -> list[str]:
    """'wear = couette [series]' -> ['wear [series]', 'couette [series]']."""
    laws, _, solver = best.rpartition(" [")
    return [f"{law} [{solver}" for law in laws.split(" = ")] if laws else [best]


def _p(p: float) -> str:
    return f"{p:.2g}" if p >= 1e-3 else f"{p:.1e}"


# --- computations ------------------------------------------------------------------------------------
def _law_params(f: FitResult) -> dict:
    return {p.key: p.value for p in f.params.values() if p.kind == "law"}


def _neg2ll(f: FitResult) -> float:
    """-2 ln L of a fit from the likelihood its datasets' noise calls for (``Stats.neg2loglik``), else its
    chi-square at the declared sigma (the two differ by a constant with known noise)."""
    v = getattr(f.stats, "neg2loglik", math.nan)
    return float(v) if math.isfinite(v) else float(f.stats.chisqr)


def _k(f: FitResult) -> int:
    """Parameters the likelihood counts (``Stats.k_lik``)."""
    return int(getattr(f.stats, "k_lik", 0) or f.stats.n_params)


def _determined(f: FitResult) -> dict:
    """The fitted law values the data determine (SI): ratio-only pairs replaced by their ratio (eta/h)."""
    ratio = {k for pair in (f.identifiability.ratio_only if f.identifiability else ()) for k in pair}
    return {p.name: p.value for p in f.params.values()
            if (p.kind == "law" and p.vary and p.name not in ratio) or p.kind == "derived"}


def predict_from(source: FitResult, target: FitResult) -> Prediction:
    """``source``'s law parameters predicting ``target``'s data (same law and solver), on the
    target's own scene and with its ``[fixed]`` values."""
    d = target.per_dataset[0]
    tg = d.target
    params = _law_params(source)
    base = dict(law=source.law, solver=source.solver, source=source.datasets[0], target=target.datasets[0],
                params=params, own_chi2=float(d.chisqr))
    try:
        law = get_law(source.law)
        params.update({k: held_value(law, k, tg.dataset) for k in tg.dataset.fixed if k in params})
        m = predict(source.law, tg, params, d.solver, d.scene)
    except FrictionLabError as exc:
        return Prediction(**base, status="failed", reason=str(exc))
    if m.shape != tg.y.shape or not np.all(np.isfinite(m)):
        return Prediction(**base, status="failed", reason="the prediction is not finite")
    z = (m - tg.y) / tg.sigma
    chi2 = float(z @ z)
    loglik = -0.5 * chi2 - float(np.sum(np.log(tg.sigma * math.sqrt(2 * math.pi))))
    return Prediction(**base, status="ok", n=int(z.size), chi2=chi2, rms_sigma=math.sqrt(chi2 / z.size), loglik=loglik)


def shared_fit(fits: Sequence[FitResult], free: dict | None = None, timeout: float | None = None,
               likelihood=None) -> SharedFit:
    """One parameter set for every member of ``fits`` (one candidate's separate fits) against them; ``likelihood``:
    -2 ln L of a FitResult under one noise model for both (default: each fit's own, ``Stats.neg2loglik``)."""
    from scipy.stats import chi2 as chi2_dist

    _neg2ll_of = likelihood or _neg2ll

    law, solver = fits[0].law, fits[0].solver
    names = tuple(f.datasets[0] for f in fits)
    base = dict(law=law, solver=solver, datasets=names,
                separate={f.datasets[0]: _determined(f) for f in fits})
    targets = [f.per_dataset[0].target for f in fits]
    if any(getattr(f.stats, "likelihood", "known") == "none" for f in fits):
        return SharedFit(**base, status="skipped", reason="a member's fit has no likelihood (a derived series)")
    chi2_sep, k_sep = sum(_neg2ll_of(f) for f in fits), sum(_k(f) for f in fits)
    best = None
    for f in sorted(fits, key=lambda f: f.stats.chisqr):
        start = {p.key: p.value for p in f.params.values() if p.kind == "law" and p.vary}
        r = fit(law, targets, solver=f.per_dataset[0].solver, initial=start, scan=0, n_starts=1, free=free or None,
                checks=False, timeout=timeout)
        if r.ok and (best is None or r.stats.chisqr < best.stats.chisqr):
            best = r
    if best is None:
        return SharedFit(**base, status="failed", reason="the shared fit did not succeed from any member's parameters")
    lr, dk = _neg2ll_of(best) - chi2_sep, k_sep - _k(best)
    if dk <= 0:
        return SharedFit(**base, status="skipped", reason="no law parameter is fitted per dataset: nothing to share",
                         chi2_shared=_neg2ll_of(best), k_shared=_k(best), chi2_separate=chi2_sep, k_separate=k_sep)
    p = float(chi2_dist.sf(max(lr, 0.0), dk))
    return SharedFit(**base, status="ok", chi2_shared=_neg2ll_of(best), k_shared=_k(best),
                     chi2_separate=chi2_sep, k_separate=k_sep, lr=lr, dk=dk, p_value=p, delta_aic=lr - 2 * dk,
                     shared=_determined(best))


def transfer_candidate(fits: Sequence[FitResult], free: dict | None = None,
                       timeout: float | None = None) -> tuple[list[Prediction], SharedFit]:
    """Every ordered transfer prediction among one candidate's fits of a group, and its shared fit
    (each of its fits within ``timeout`` seconds, None: no limit)."""
    preds = [predict_from(s, t) for s in fits for t in fits if s is not t]
    return preds, shared_fit(fits, free, timeout)


def failed_candidate(fits: Sequence[FitResult], reason: str) -> tuple[list[Prediction], SharedFit]:
    """``transfer_candidate``'s answer when its run was ended (``inference.fitting.guard``): everything failed, with ``reason``."""
    f0 = fits[0]
    preds = [Prediction(law=f0.law, solver=f0.solver, source=s.datasets[0], target=t.datasets[0], status="failed",
                        reason=reason) for s in fits for t in fits if s is not t]
    return preds, SharedFit(law=f0.law, solver=f0.solver, datasets=tuple(f.datasets[0] for f in fits),
                            status="failed", reason=reason, separate={f.datasets[0]: _determined(f) for f in fits})


def _members(datasets, group_of=None) -> dict[str, list]:
    if group_of is None:
        from ..verdicts.answers import group_of
    out: dict[str, list] = {}
    for ds in datasets:
        out.setdefault(group_of(ds), []).append(ds)
    return out


def untransferable(datasets) -> str:
    """Why the members of one group cannot predict each other ("" if they can): a parameter set fitted
    to one observable is not a prediction of a different observable under other conditions."""
    obs = dict.fromkeys(d.observable for d in datasets)
    if len(datasets) > 1 and len(obs) > 1:
        return (f"its datasets measure different observables ({', '.join(obs)}), so no dataset predicts "
                "another under other conditions")
    return ""


def skipped(datasets, group_of=None, fits: Sequence[FitResult] = ()) -> list[TransferResult]:
    """A skipped TransferResult, with its reason, for each group of ``datasets`` that cannot be transferred:
    different observables, or (given ``fits``) no law that passes its fit tests on every member."""
    out = [TransferResult(group=g, datasets=tuple(d.name for d in dss), predictions=(), shared=(),
                          status="skipped", reason=why)
           for g, dss in _members(datasets, group_of).items() if (why := untransferable(dss))]
    if fits:
        fitting = candidates_by_group(fits, datasets, group_of)
        tried = candidates_by_group(fits, datasets, group_of, only_fitting=False)
        out += [TransferResult(group=g, datasets=tuple(f.datasets[0] for f in next(iter(c.values()))), predictions=(),
                               shared=(), status="skipped", reason="no fitting law was available to transfer (no "
                               "candidate passes its fit tests on every member)")
                for g, c in tried.items() if g not in fitting]
    return out


def _fits_all(fs: Sequence[FitResult]) -> bool:
    """Whether every fit passes its own fit tests (a law that misfits has nothing to transfer)."""
    return all(f.goodness is not None and f.goodness.fits is True and not f.flags for f in fs)


def candidates_by_group(fits: Sequence[FitResult], datasets: Sequence | None = None,
                        group_of=None, only_fitting: bool = True) -> dict[str, dict[str, list[FitResult]]]:
    """group -> candidate label -> its single-dataset fits, for every group of ``datasets`` (default:
    those the successful fits are of) with at least two members, and candidates that fitted all of them
    (only_fitting: and pass their fit tests on every member)."""
    if group_of is None:
        from ..verdicts.answers import group_of
    ok = [f for f in fits if f.ok and len(f.datasets) == 1]
    if datasets is None:
        datasets = list({f.datasets[0]: f.per_dataset[0].target.dataset for f in ok}.values())
    members = {g: [d.name for d in dss] for g, dss in _members(datasets, group_of).items()
               if not untransferable(dss)}
    by: dict[tuple[str, str], dict[str, FitResult]] = {}
    for f in ok:
        by.setdefault(f"{f.law} [{f.solver}]", {})[f.datasets[0]] = f
    out: dict[str, dict[str, list[FitResult]]] = {}
    for g, names in members.items():
        if len(names) < 2:
            continue
        for cand, d in by.items():
            if all(n in d for n in names) and (not only_fitting or _fits_all([d[n] for n in names])):
                out.setdefault(g, {})[cand] = [d[n] for n in names]
    return out


def transfer(fits: Sequence[FitResult], datasets: Sequence | None = None, free: dict | None = None,
             group_of=None) -> list[TransferResult]:
    """Transfer predictions and shared fits for every group (serially; ``compare`` runs them on its pool)."""
    out = []
    for g, cands in candidates_by_group(fits, datasets, group_of).items():
        parts = {c: transfer_candidate(fs, free) for c, fs in cands.items()}
        out.append(assemble(g, cands, parts))
    if datasets is not None:
        out += [r for r in skipped(datasets, group_of, fits) if r.group not in {o.group for o in out}]
    return out


def assemble(group: str, cands: dict, parts: dict) -> TransferResult:
    names = tuple(f.datasets[0] for f in next(iter(cands.values())))
    preds = tuple(p for c in cands for p in parts[c][0])
    return TransferResult(group=group, datasets=names, predictions=preds, shared=tuple(parts[c][1] for c in cands))


def fill_answers(answers, results: Sequence[TransferResult]) -> tuple:
    """``answers`` (answers.Answer rows) with the transfer field of each group that has a transfer result."""
    by = {t.group: t for t in results}
    out = []
    for a in answers:
        t = by.get(a.group)
        if t is None:
            out.append(a)
            continue
        d = t.as_dict()
        out.append(attrs.evolve(a, transfer=t.answer(), short={**a.short, "transfer": t.short(a.best)},
                                details={**a.details, "transfer": {k: d[k] for k in ("ranking", "shared", "alpha")}}))
    return tuple(out)
