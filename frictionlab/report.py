"""The comparison report: one folder, written whole or not at all.

``write_report(comparison, out, force=False)`` writes, through ``io.atomic_dir``:

* ``report.md`` and a self-contained ``report.html`` (figures embedded as base64 PNG): ranking
  tables, equivalence verdicts with their numbers, identifiability warnings, the provenance of
  every dataset (reconstructed and synthetic data are labelled as such, never as measured);
* ``figures/*.png``: per dataset the data with every law's fit and the residuals, the force
  histories, the equivalence forces; the ranking heat map; the theta -> omega derivations;
* ``ranking.csv``: columns ``ranking.COLUMNS`` (per-dataset rows, then the 'ALL' group rows;
  rss and rmse in the observable's SI unit, empty for groups);
* ``results.json``, schema ``frictionlab.compare/1``:
    created, versions{package: version}, settings, wall_time_s,
    datasets[{name, kind, observable, n_points, status: fitted|skipped, reason,
              provenance{kind, source, method, command, seed, truth}}],
    fits[{dataset, law, solver, status: ok|failed|skipped, reason, message, nfev, wall_time_s,
          parameters{name: {value, stderr, unit, kind: law|scene|derived, vary, fixed_by, lower, upper}},
          correlations[{a, b, r}],
          statistics{observable, observable_unit, n_points, n_params, n_free, chisqr, redchi, rss, rmse,
                     aic, aicc, bic},
          identifiability{verdict, warnings[], at_bounds[], missing_stderr{name: reason},
                          high_correlations[{a, b, r}], ratio_only[[a, b]], no_effect[]},
          notes[]}],
    ranking[row], groups[row] (row: the ranking.csv columns plus reason, tied_with),
    equivalence[{dataset, solver, area_rate_solver, status, verdict, explanation, reason, checks{},
                 force_correlation, force_distance, impulse_Ns{}, aic{}, redchi{}, shape{}, fitted{},
                 cross[{law, to, status, rms, rms_sigma, dchi2, params}],
                 decomposition{b, u0, c_area, c_area_rate, mu, eta_prime, r2} | null}],
    derivations{dataset: {method: {rms_vs_omega_column, omega_peak, omega_end, noisy_rms_vs_omega_column,
                                   noisy_omega_peak, noisy_omega_end, noisy_median_sigma}}}
  All numbers SI (rad/s, s, m, N) unless the key says otherwise; non-finite numbers are null.
"""
from __future__ import annotations

import base64
import datetime as _dt
import html
import json
import math
import os
from pathlib import Path

import numpy as np

from . import figures
from .comparison import Comparison
from .display import fmt, param_text, unit
from .equivalence import AREA_RATE, WEAR
from .io import atomic_dir
from .ranking import COLUMNS, TIE_AIC, to_csv

SCHEMA = "frictionlab.compare/1"
DERIVE_SEED = 0


# --- a tiny document model rendered twice (Markdown and HTML) --------------------------------
class Doc:
    def __init__(self):
        self.blocks: list[tuple] = []

    def h(self, level: int, text: str):
        self.blocks.append(("h", level, text))

    def p(self, text: str):
        self.blocks.append(("p", text))

    def warn(self, text: str):
        self.blocks.append(("warn", text))

    def items(self, items: list[str]):
        if items:
            self.blocks.append(("ul", list(items)))

    def table(self, headers: list[str], rows: list[list]):
        if rows:
            self.blocks.append(("table", headers, [[("" if c is None else str(c)) for c in r] for r in rows]))

    def fig(self, name: str, caption: str):
        self.blocks.append(("fig", name, caption))

    def markdown(self) -> str:
        out = []
        for b in self.blocks:
            if b[0] == "h":
                out.append("#" * b[1] + " " + b[2])
            elif b[0] == "p":
                out.append(b[1])
            elif b[0] == "warn":
                out.append("> **Note.** " + b[1])
            elif b[0] == "ul":
                out.append("\n".join(f"- {x}" for x in b[1]))
            elif b[0] == "table":
                esc = lambda c: c.replace("|", "\\|").replace("\n", " ")  # noqa: E731
                lines = ["| " + " | ".join(esc(h) for h in b[1]) + " |", "|" + "---|" * len(b[1])]
                lines += ["| " + " | ".join(esc(c) for c in r) + " |" for r in b[2]]
                out.append("\n".join(lines))
            elif b[0] == "fig":
                out.append(f"![{b[2]}](figures/{b[1]})\n\n*{b[2]}*")
        return "\n\n".join(out) + "\n"

    def html(self, images: dict[str, bytes], title: str) -> str:
        e = html.escape
        out = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{e(title)}</title>"
               f"<style>{CSS}</style></head><body><main>"]
        toc = [(b[2], _anchor(b[2])) for b in self.blocks if b[0] == "h" and b[1] == 2]
        for b in self.blocks:
            if b[0] == "h":
                out.append(f"<h{b[1]} id='{_anchor(b[2])}'>{e(b[2])}</h{b[1]}>")
                if b[1] == 1 and toc:
                    out.append("<nav><b>Contents:</b> " + " · ".join(f"<a href='#{a}'>{e(t)}</a>" for t, a in toc)
                               + "</nav>")
            elif b[0] == "p":
                out.append(f"<p>{_inline(b[1])}</p>")
            elif b[0] == "warn":
                out.append(f"<div class='warn'><b>Note.</b> {_inline(b[1])}</div>")
            elif b[0] == "ul":
                out.append("<ul>" + "".join(f"<li>{_inline(x)}</li>" for x in b[1]) + "</ul>")
            elif b[0] == "table":
                head = "".join(f"<th>{e(h)}</th>" for h in b[1])
                body = "".join("<tr>" + "".join(f"<td>{_inline(c)}</td>" for c in r) + "</tr>" for r in b[2])
                out.append(f"<div class='tw'><table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table></div>")
            elif b[0] == "fig":
                data = base64.b64encode(images[b[1]]).decode("ascii")
                out.append(f"<figure><img alt='{e(b[2])}' src='data:image/png;base64,{data}'>"
                           f"<figcaption>{e(b[2])}</figcaption></figure>")
        out.append("</main></body></html>")
        return "\n".join(out)


CSS = """body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;line-height:1.45;color:#222;margin:0;
background:#fafafa}main{max-width:1100px;margin:0 auto;padding:1.5em 2em;background:#fff}
h1{border-bottom:2px solid #1b9e77}h2{border-bottom:1px solid #ddd;margin-top:2em}
table{border-collapse:collapse;font-size:.86em;margin:.6em 0}th,td{border:1px solid #ddd;padding:.25em .5em;
text-align:left;vertical-align:top}th{background:#f0f0f0}tr:nth-child(even) td{background:#fafafa}
.tw{overflow-x:auto}figure{margin:1em 0}img{max-width:100%;border:1px solid #eee}
figcaption{font-size:.85em;color:#555}.warn{background:#fff4e5;border-left:4px solid #e6ab02;padding:.6em 1em;
margin:1em 0}nav{font-size:.9em;margin:1em 0}code{background:#f3f3f3;padding:0 .2em}"""


def _anchor(text: str) -> str:
    return "".join(c if c.isalnum() else "-" for c in text.lower()).strip("-")


def _inline(text: str) -> str:
    """Escape, then render **bold** and `code` the way the Markdown does."""
    import re

    s = html.escape(text)
    s = re.sub(r"\*\*(.+?)\*\*", r"<b>\1</b>", s)
    return re.sub(r"`(.+?)`", r"<code>\1</code>", s)


# --- content ---------------------------------------------------------------------------------
PROVENANCE_WORDS = {
    "measured": "measured",
    "reported": "values reported in a publication",
    "reconstructed": "RECONSTRUCTED from published numbers, not measured",
    "synthetic": "SYNTHETIC, generated by a model, not measured",
}


def _fixed(x, digits: int) -> str:
    return "" if x is None or not math.isfinite(x) else f"{x:.{digits}f}"


def _candidate_table(rows, observable: str) -> tuple[list[str], list[list]]:
    uname, uf = unit(observable)
    headers = ["rank", "law [solver]", "n", "k", f"RMSE [{uname}]", "reduced χ²", "AIC", "AICc", "BIC", "ΔAIC",
               "Akaike weight", "status"]
    out = []
    for r in rows:
        status = r.status + (f" (with {', '.join(r.tied_with)})" if r.tied_with else "") + \
            (f": {r.reason}" if r.reason else "")
        out.append([r.rank or "–", r.candidate, r.n_points or "", r.n_params if r.rank else "",
                    fmt(r.rmse * uf) if math.isfinite(r.rmse) else "", fmt(r.redchi), fmt(r.aic), fmt(r.aicc),
                    fmt(r.bic), _fixed(r.delta_aic, 2), _fixed(r.akaike_weight, 3), status])
    return headers, out


def _group_table(rows) -> tuple[list[str], list[list]]:
    headers = ["group", "rank", "law [solver]", "n", "k", "reduced χ²", "ΣAIC", "ΣAICc", "ΣBIC", "ΔAIC",
               "Akaike weight", "status"]
    out = [[r.dataset, r.rank or "–", r.candidate, r.n_points or "", r.n_params if r.rank else "", fmt(r.redchi),
            fmt(r.aic), fmt(r.aicc), fmt(r.bic), _fixed(r.delta_aic, 2), _fixed(r.akaike_weight, 3),
            r.status + (f": {r.reason}" if r.reason else "")] for r in rows]
    return headers, out


def _derivations(ds):
    """theta -> omega by each route: on the column as given, and with simulated noise of the stated sigma."""
    from .derive import METHODS, derive_omega

    sigma = ds.noise.get("theta")
    rng = np.random.default_rng(DERIVE_SEED)
    noisy_theta = ds.columns["theta"] + rng.normal(0.0, sigma or 0.0, len(ds))
    given = {m: derive_omega(ds.t, ds.columns["theta"], m, sigma) for m in METHODS}
    noisy = {m: derive_omega(ds.t, noisy_theta, m, sigma) for m in METHODS}
    noisy["_theta"] = noisy_theta
    return given, noisy, sigma


def _derivation_stats(ds, given, noisy) -> dict:
    ref = ds.columns.get("omega")
    out = {}
    for m, d in given.items():
        rms = lambda x: float(np.sqrt(np.mean((x - ref) ** 2))) if ref is not None else math.nan  # noqa: E731
        out[m] = {"rms_vs_omega_column": rms(d.omega), "omega_peak": float(np.max(d.omega)),
                  "omega_end": float(d.omega[-1]), "noisy_median_sigma": float(np.median(noisy[m].sigma)),
                  "noisy_rms_vs_omega_column": rms(noisy[m].omega), "noisy_omega_peak": float(np.max(noisy[m].omega)),
                  "noisy_omega_end": float(noisy[m].omega[-1])}
    return out


def _truth_check(d, c: Comparison) -> str:
    """For data generated with a known law: where that law ranks and how far its fit lands from the truth."""
    from .errors import FrictionLabError
    from .registry import get_law
    from .units import to_si

    truth = dict(d.provenance.truth or {})
    law = truth.pop("law", None)
    if not law or law not in c.laws:
        return ""
    rows = [r for r in c.ranking if r.dataset == d.name and r.law == law and r.rank]
    parts = []
    for r in rows:
        f = c.fit_for(d.name, law, r.solver)
        found = []
        for name, text in truth.items():
            p = f.params.get(name) if f else None
            if p is None or not p.vary:
                continue
            try:
                value = to_si(text, get_law(law).spec(name).unit, f"{d.name}: provenance.truth.{name}")
            except FrictionLabError:
                continue
            dev = f" ({(p.value - value) / p.stderr:+.1f}σ)" if p.stderr else ""
            found.append(f"{name}: true {param_text(value, None, p.unit)}, fitted "
                         f"{param_text(p.value, p.stderr, p.unit)}{dev}")
        parts.append(f"{law} [{r.solver}] ranks #{r.rank}" + (f" ({r.status} with {', '.join(r.tied_with)})"
                                                              if r.tied_with else "")
                     + ("; " + "; ".join(found) if found else ""))
    if not parts:
        return ""
    return f"**Known truth:** generated with {law}. " + ". ".join(parts) + "."


def _reported_check(d, c: Comparison) -> str:
    """Law parameters the source reports for this dataset, beside every fit of a law that has them."""
    from .errors import FrictionLabError
    from .registry import get_law
    from .units import to_si

    parts = []
    for name, text in (d.reported or {}).items():
        for f in c.fits_on(d.name):
            p = f.params.get(name)
            if not f.ok or p is None or p.kind != "law" or not p.vary:
                continue
            try:
                value = to_si(text, get_law(f.law).spec(name).unit, f"{d.name}: reported.{name}")
            except FrictionLabError:
                continue
            parts.append(f"{name} reported {param_text(value, None, p.unit)}, fitted by {f.law} [{f.solver}] "
                         f"{param_text(p.value, p.stderr, p.unit)}")
    return ("**Reported by the source:** " + "; ".join(parts) + ".") if parts else ""


def build(c: Comparison) -> tuple[Doc, dict[str, bytes], dict]:
    """The document, its figures (name -> PNG bytes) and the derivation statistics."""
    doc, figs, deriv_stats = Doc(), {}, {}
    fitted = c.fitted_datasets
    kinds = {}
    for d in c.datasets:
        kinds.setdefault(d.provenance.kind, []).append(d.name)
    doc.h(1, "frictionlab: friction laws compared")
    doc.p(f"Generated {_dt.datetime.now().astimezone().strftime('%Y-%m-%d %H:%M %Z')} by frictionlab "
          f"{c.versions.get('frictionlab')}; the comparison took {c.wall_time:.1f} s. Laws: {', '.join(c.laws)}. "
          f"Datasets: {len(c.datasets)} ({len(fitted)} fitted).")
    not_measured = [n for k, v in kinds.items() if k != "measured" for n in v]
    if not_measured:
        parts = [f"{len(v)} {PROVENANCE_WORDS.get(k, k)} ({', '.join(v)})" for k, v in kinds.items()]
        doc.warn(("No dataset in this report is a measurement. " if "measured" not in kinds else
                  "Not every dataset in this report is a measurement. ") + "; ".join(parts) + ". Reconstructed "
                 "series are curves rebuilt to agree with numbers stated in a paper; synthetic series were generated "
                 "with a known law plus noise. Rankings on them test the method and the claims' internal "
                 "consistency, not nature.")

    # summary
    doc.h(2, "Summary")
    items = []
    for d in fitted:
        best = [r for r in c.ranking if r.dataset == d.name and r.rank == 1]
        if best:
            items.append(f"**{d.name}** ({d.provenance.kind}): best " + " = ".join(r.candidate for r in best)
                         + f" (Akaike weight {sum(r.akaike_weight for r in best):.2f}"
                         + (" shared by a tie" if len(best) > 1 else "") + ")")
        else:
            items.append(f"**{d.name}**: no law could be fitted")
    for g in dict.fromkeys(r.dataset for r in c.groups):
        best = [r.candidate for r in c.groups if r.dataset == g and r.rank == 1]
        if best:
            items.append(f"**{g}**: best " + " = ".join(best) + " (summed AIC over the group"
                         + ("; a tie" if len(best) > 1 else "") + ")")
    for d in fitted:
        for law in c.laws:
            ser = next((r for r in c.ranking if r.dataset == d.name and r.law == law and r.solver == "series"
                        and r.rank), None)
            full = next((r for r in c.ranking if r.dataset == d.name and r.law == law and r.solver != "series"
                         and r.rank), None)
            if ser and full and abs(ser.aic - full.aic) > 2:
                better = "better" if ser.aic < full.aic else "worse"
                items.append(f"**{d.name}**: the paper's truncated series of {law} fits {better} than the {full.solver} "
                             f"solution of the same law (ΔAIC {abs(ser.aic - full.aic):.1f}): the approximation, not "
                             "the law, makes that difference (see the notes under Fits)")
    doc.items(items)
    if c.equivalence:
        doc.p("Equivalence of λAu and μN + μη′dA/dt: " + "; ".join(
            f"{e.dataset} [wear {e.solver}]: **{e.verdict or e.status}**" for e in c.equivalence) + ".")

    # provenance
    doc.h(2, "Datasets and provenance")
    rows = []
    for d in c.datasets:
        pv = d.provenance
        truth = ", ".join(f"{k} = {v}" for k, v in pv.truth.items()) if pv.truth else ""
        status = "fitted" if d.name not in c.skipped_datasets else f"not fitted: {c.skipped_datasets[d.name]}"
        how = "; ".join(x for x in (pv.method, f"regenerate with `{pv.command}`" if pv.command else "",
                                    f"seed {pv.seed}" if pv.seed is not None else "") if x)
        rows.append([d.name, d.kind, d.observable, len(d), PROVENANCE_WORDS.get(pv.kind, pv.kind), pv.source, how,
                     truth, status])
    doc.table(["dataset", "kind", "observable", "points", "provenance", "source", "how it was made",
               "generating truth", "status"], rows)

    # ranking
    doc.h(2, "Ranking")
    doc.p(f"Each law is fitted separately to each dataset and ranked by AIC; candidates within ΔAIC ≤ {TIE_AIC} "
          "share a rank (their best fits are the same curve). The solver is part of the candidate: where the paper's "
          "truncated series applies it is ranked next to the exact (or numerical) solution of the same law, so the "
          "effect of the approximation is visible. Weights are Akaike weights within each dataset.")
    figs["ranking.png"] = figures.ranking_figure(list(c.ranking))
    doc.fig("ranking.png", "Rank and ΔAIC of every law [solver] on every dataset (grey: not fitted).")
    doc.h(3, "Over groups of datasets")
    doc.p("Sums of the per-dataset AIC (independent fits, so log-likelihoods add). 'exact' and 'ode' solve the "
          "same equations and count as one candidate; a candidate that could not be fitted to every dataset of a "
          "group is 'incomplete' there.")
    doc.table(*_group_table(list(c.groups)))
    for d in fitted:
        rows = [r for r in c.ranking if r.dataset == d.name]
        doc.h(3, f"{d.name}")
        doc.table(*_candidate_table(rows, d.observable))

    # per-dataset fits
    doc.h(2, "Fits")
    for d in fitted:
        fits = c.fits_on(d.name)
        rows = [r for r in c.ranking if r.dataset == d.name]
        doc.h(3, d.name)
        if d.description:
            doc.p(d.description)
        for check in (_truth_check(d, c), _reported_check(d, c)):
            if check:
                doc.p(check)
        if any(f.ok for f in fits):
            name = f"fit-{d.name}.png"
            figs[name] = figures.fit_figure(d, fits, rows)
            doc.fig(name, f"{d.name}: data ({d.provenance.kind}) with each law's best fit, and residuals.")
            if "t" in d.columns:
                name = f"force-{d.name}.png"
                figs[name] = figures.force_figure(d, fits)
                doc.fig(name, f"{d.name}: friction force of each best fit.")
        prow = []
        for f in fits:
            if not f.ok:
                continue
            ratio_keys = {k for pair in f.identifiability.ratio_only for k in pair}
            for p in f.params.values():
                role = "fitted" if p.vary else (p.fixed_by or "held")
                if p.vary and p.kind == "law" and p.key in ratio_keys:
                    role = "arbitrary: only the ratio is determined"
                elif p.vary and p.stderr is None:
                    role = f"fitted; no error bar: {f.identifiability.missing_stderr.get(p.name, 'see warnings')}"
                prow.append([f"{f.law} [{f.solver}]", p.name, param_text(p.value, p.stderr if p.vary or
                                                                         p.kind == "derived" else None, p.unit),
                             role])
        doc.table(["law [solver]", "parameter", "value ± standard error", "role"], prow)
        warns = [f"{f.law} [{f.solver}]: {w}" for f in fits if f.ok for w in f.identifiability.warnings]
        notes = [f"{f.law} [{f.solver}]: {n}" for f in fits if f.ok for n in f.notes]
        bad = [f"{f.law} [{f.solver}]: {f.status}: {f.reason}" for f in fits if not f.ok]
        if warns:
            doc.p("**Identifiability:**")
            doc.items(warns)
        if notes:
            doc.p("**Notes:**")
            doc.items(notes)
        if bad:
            doc.p("**Not fitted:**")
            doc.items(bad)

    _equivalence_section(doc, figs, c)

    # theta -> omega
    with_theta = [d for d in fitted if "theta" in d.columns and "t" in d.columns]
    if with_theta:
        doc.h(2, "Spin from rotation angle")
        doc.p("Cameras record the rotation angle θ(t), not the spin ω(t). frictionlab can fit θ directly "
              "(`frictionlab fit LAW DATASET --observable theta`), or derive ω first: by the paper's route, a "
              "9th-order polynomial of θ differentiated (`--derive poly9`), or by a cubic smoothing spline with a "
              "penalty chosen by generalized cross-validation (`--derive spline`). The figures show each route on "
              "the θ column as given, and on the same column with simulated camera noise of the dataset's stated "
              f"σθ (seed {DERIVE_SEED}), which is what real frames carry; the shaded bands are the ±1σ that each "
              "route passes on to ω.")
        for d in with_theta:
            given, noisy, sigma = _derivations(d)
            stats = _derivation_stats(d, given, noisy)
            deriv_stats[d.name] = stats
            name = f"derive-{d.name}.png"
            figs[name] = figures.derivation_figure(d, given, noisy, sigma or 0.0, DERIVE_SEED)
            doc.h(3, d.name)
            doc.fig(name, f"{d.name}: ω derived from θ by poly9 and spline, without and with simulated noise.")
            uname, uf = unit("omega")
            doc.table(["route", f"RMS vs ω column [{uname}]", f"peak [{uname}]", f"end [{uname}]",
                       f"with noise: RMS vs ω column [{uname}]", f"with noise: peak [{uname}]",
                       f"with noise: end [{uname}]", f"with noise: median ±1σ passed on [{uname}]"],
                      [[m, fmt(s["rms_vs_omega_column"] * uf), fmt(s["omega_peak"] * uf), fmt(s["omega_end"] * uf),
                        fmt(s["noisy_rms_vs_omega_column"] * uf), fmt(s["noisy_omega_peak"] * uf),
                        fmt(s["noisy_omega_end"] * uf), fmt(s["noisy_median_sigma"] * uf)] for m, s in stats.items()])
            ref = d.reported
            if ref:
                doc.p("Reported in the paper for this impact: " + ", ".join(f"{k} = {v}" for k, v in ref.items()
                                                                           if "omega" in k or k == "t_peak") + ".")

    # identifiability roll-up
    doc.h(2, "Identifiability warnings")
    allw = [f"{f.datasets[0]} — {f.law} [{f.solver}]: {f.identifiability.verdict}" for f in c.fits
            if f.ok and f.identifiability.warnings]
    doc.items(allw) if allw else doc.p("None: every fitted parameter is determined by its data.")
    failed = [f"{f.datasets[0]} — {f.law} [{f.solver}]: {f.status}: {f.reason}" for f in c.fits if not f.ok]
    if failed:
        doc.h(3, "Fits not made or failed")
        doc.items(failed)

    _method_section(doc, c)
    return doc, figs, deriv_stats


def _equivalence_section(doc: Doc, figs: dict, c: Comparison):
    doc.h(2, "Equivalence test: λAu versus μN + μη′dA/dt")
    doc.p("The paper claims that the wear law λAu is 'qualitatively equivalent' to the empirical μN + μη′dA/dt, "
          "because with the truncated slip u ≈ u0(1 − b + b cos φt) (eq 7) the wear force becomes "
          "F ≈ λu0(1 − b)A + (λu0b/(φA0)) A dA/dt. The paper prints the second factor as φ/A0 (from "
          "'cos φt = (φ/A0) dA/dt'); differentiating A = A0 sin φt gives cos φt = (dA/dt)/(φA0), so the factor is "
          "1/(φA0), as used here. Per dataset and wear solver: both laws' best fits; each law refitted to the other's "
          "best curve, with the misfit Δχ² = Σ((refit − curve)/σ)², the penalty that law would pay on noisy data "
          "generated by the other; the correlation r and normalized RMS distance d of the two force "
          "histories; and, on the half-sine impact, the decomposition of the wear fit projected by least squares "
          "onto μN + μη′dA/dt, compared with the fitted area-rate μ and η′. Verdict: **equivalent at this noise** if "
          "both refits stay within Δχ² ≤ 2 (the scale of one AIC parameter); else **qualitatively similar** if the curves have the same shape (both fall "
          "after their peak, or neither does), r ≥ 0.8 and the implied μ, η′ are within a factor 2 of the fitted "
          "ones; else **not equivalent**, with the failed checks named.")
    if not c.equivalence:
        doc.p("Not run: it needs both the wear and the area-rate law in the comparison.")
        return
    rows = []
    for e in c.equivalence:
        if e.status != "ok":
            rows.append([e.dataset, e.solver, e.area_rate_solver, f"skipped: {e.reason}"] + [""] * 6)
            continue
        cr = {x.law: x for x in e.cross}
        dec = e.decomposition
        rows.append([e.dataset, e.solver, e.area_rate_solver, e.verdict, fmt(e.force_correlation, 3),
                     fmt(e.force_distance, 3),
                     fmt(cr[AREA_RATE].dchi2, 3) if AREA_RATE in cr else "",
                     fmt(cr[WEAR].dchi2, 3) if WEAR in cr else "",
                     f"μ {fmt(dec.mu, 3)}, η′ {fmt(dec.eta_prime, 3)}" if dec else "n/a",
                     f"μ {fmt(e.fitted[AREA_RATE].get('mu'), 3)}, η′ {fmt(e.fitted[AREA_RATE].get('eta_prime'), 3)}"])
    doc.table(["dataset", "wear solver", "area-rate solver", "verdict", "force r", "force d",
               "area-rate refit to wear curve, Δχ²", "wear refit to area-rate curve, Δχ²", "implied by decomposition",
               "fitted area-rate"], rows)
    doc.items([f"**{e.dataset} [wear {e.solver}] — {e.verdict}**: {e.explanation}" for e in c.equivalence
               if e.status == "ok"])
    for d in c.fitted_datasets:
        mine = [e for e in c.equivalence if e.dataset == d.name and e.status == "ok"]
        if not mine:
            continue
        fa = c.fit_for(d.name, AREA_RATE, mine[0].area_rate_solver)
        fws = [c.fit_for(d.name, WEAR, e.solver) for e in mine]
        name = f"equivalence-{d.name}.png"
        figs[name] = figures.equivalence_figure(d, fws, fa, [e.decomposition for e in mine])
        doc.fig(name, f"{d.name}: friction force of the wear and area-rate fits"
                + (", and the paper's decomposition of each wear fit with its projection onto μN + μη′dA/dt."
                   if any(e.decomposition for e in mine) else "."))


def _method_section(doc: Doc, c: Comparison):
    doc.h(2, "Method")
    doc.items([
        "Fits: lmfit Levenberg-Marquardt on residuals (model − data)/σ, σ the dataset's stated noise; parameters "
        "scaled by their typical size so the optimizer sees order-one numbers; a grid of starts is scored first "
        "and the best few distinct ones are refined; dataset `[fixed]` values are held.",
        "Standard errors: from the covariance scaled by the reduced χ² (lmfit's default), i.e. they assume the "
        "model is right and the noise level is as estimated by the residuals.",
        "Statistics: χ² = Σ((model − data)/σ)², reduced χ² = χ²/(n − k), AIC = n ln(χ²/n) + 2k, "
        "AICc = AIC + 2k(k+1)/(n − k − 1), BIC = n ln(χ²/n) + k ln n (lmfit's convention). k counts the "
        "identifiable directions (rank of the Jacobian): a pair entering only as a ratio counts once, a "
        "parameter without effect not at all.",
        f"Ties: candidates within ΔAIC ≤ {TIE_AIC} share a rank. Akaike weight w = exp(−Δ/2)/Σexp(−Δ/2).",
        "Solvers: 'exact' where the law and scene admit a closed form, else 'ode' (LSODA, rtol 1e-10); "
        "'series' (the paper's first-order expansion, eqs 7-11) in addition wherever it is defined.",
        f"Settings: {json.dumps(c.settings)}.",
    ])
    doc.h(2, "Files")
    doc.items([
        "`ranking.csv`: " + ", ".join(COLUMNS) + " — per-dataset rows, then group rows (ALL, ALL[kind]); rss and "
        "rmse in the observable's SI unit (rad/s, m/s), empty for groups.",
        f"`results.json`: schema `{SCHEMA}` — every fit with parameters, errors, correlations, statistics, "
        "identifiability and notes; the rankings; the equivalence results; dataset provenance; versions. The "
        "schema is documented in `frictionlab/report.py`.",
        "`figures/`: the PNG figures of this report; `report.html` embeds them.",
    ])
    doc.h(2, "Versions")
    doc.table(["component", "version"], [[k, v] for k, v in c.versions.items()])


# --- results.json ----------------------------------------------------------------------------
def _num(x):
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    return x


def _clean(obj):
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    return _num(obj)


def _fit_json(f) -> dict:
    out = {"dataset": f.datasets[0] if len(f.datasets) == 1 else list(f.datasets), "law": f.law, "solver": f.solver,
           "status": f.status, "reason": f.reason, "message": f.message, "nfev": f.nfev, "wall_time_s": f.wall_time,
           "notes": list(f.notes)}
    if f.ok:
        obs = f.per_dataset[0].target.observable
        out["parameters"] = {n: {"value": p.value, "stderr": p.stderr, "unit": p.unit, "kind": p.kind, "vary": p.vary,
                                 "fixed_by": p.fixed_by, "lower": p.lower, "upper": p.upper}
                             for n, p in f.params.items()}
        out["correlations"] = [{"a": a, "b": b, "r": r} for (a, b), r in f.correlations.items()]
        s = f.stats
        out["statistics"] = {"observable": obs, "observable_unit": _SI_UNITS.get(obs, "SI"), "n_points": s.n_points,
                             "n_params": s.n_params, "n_free": s.n_free, "chisqr": s.chisqr, "redchi": s.redchi,
                             "rss": s.rss, "rmse": s.rmse, "aic": s.aic, "aicc": s.aicc, "bic": s.bic}
        i = f.identifiability
        out["identifiability"] = {"verdict": i.verdict, "warnings": list(i.warnings), "at_bounds": list(i.at_bounds),
                                  "missing_stderr": dict(i.missing_stderr),
                                  "high_correlations": [{"a": a, "b": b, "r": r} for a, b, r in i.high_correlations],
                                  "ratio_only": [list(p) for p in i.ratio_only], "no_effect": list(i.no_effect)}
    return out


_SI_UNITS = {"omega": "rad/s", "theta": "rad", "v": "m/s", "u": "m/s"}


def _row_json(r) -> dict:
    return {**{k: getattr(r, k) for k in COLUMNS}, "reason": r.reason, "tied_with": list(r.tied_with)}


def _equivalence_json(e) -> dict:
    d = e.decomposition
    return {"dataset": e.dataset, "solver": e.solver, "area_rate_solver": e.area_rate_solver, "status": e.status,
            "verdict": e.verdict, "explanation": e.explanation, "reason": e.reason, "checks": e.checks,
            "force_correlation": e.force_correlation, "force_distance": e.force_distance, "impulse_Ns": e.impulse,
            "aic": e.aic, "redchi": e.redchi, "shape": e.shape, "fitted": e.fitted,
            "cross": [{"law": x.law, "to": x.to, "status": x.status, "rms": x.rms, "rms_sigma": x.rms_sigma, "dchi2": x.dchi2,
                       "params": x.params} for x in e.cross],
            "decomposition": None if d is None else {"b": d.b, "u0": d.u0, "c_area": d.c_area,
                                                      "c_area_rate": d.c_area_rate, "mu": d.mu,
                                                      "eta_prime": d.eta_prime, "r2": d.r2}}


def results_json(c: Comparison, deriv_stats: dict | None = None) -> dict:
    datasets = []
    for d in c.datasets:
        pv = d.provenance
        datasets.append({"name": d.name, "kind": d.kind, "observable": d.observable, "n_points": len(d),
                         "status": "skipped" if d.name in c.skipped_datasets else "fitted",
                         "reason": c.skipped_datasets.get(d.name, ""),
                         "provenance": {"kind": pv.kind, "source": pv.source, "method": pv.method,
                                        "command": pv.command, "seed": pv.seed, "truth": dict(pv.truth)}})
    return _clean({"schema": SCHEMA, "created": _dt.datetime.now().astimezone().isoformat(timespec="seconds"),
                   "versions": c.versions, "settings": c.settings, "wall_time_s": c.wall_time, "datasets": datasets,
                   "fits": [_fit_json(f) for f in c.fits], "ranking": [_row_json(r) for r in c.ranking],
                   "groups": [_row_json(r) for r in c.groups],
                   "equivalence": [_equivalence_json(e) for e in c.equivalence],
                   "derivations": deriv_stats or {}})


def write_report(c: Comparison, out, force: bool = False) -> Path:
    """Write the report folder ``out`` whole or not at all; refuse an existing folder unless force."""
    out = Path(out)
    with atomic_dir(out, force=force) as tmp:
        umask = os.umask(0)
        os.umask(umask)
        tmp.chmod(0o777 & ~umask)  # mkdtemp makes it private; the report is meant to be read
        doc, figs, deriv = build(c)
        (tmp / "figures").mkdir()
        for name, data in figs.items():
            (tmp / "figures" / name).write_bytes(data)
        (tmp / "report.md").write_text(doc.markdown(), encoding="utf-8")
        (tmp / "report.html").write_text(doc.html(figs, "frictionlab comparison report"), encoding="utf-8")
        (tmp / "ranking.csv").write_text(to_csv(list(c.ranking) + list(c.groups)), encoding="utf-8")
        (tmp / "results.json").write_text(json.dumps(results_json(c, deriv), indent=1, allow_nan=False),
                                          encoding="utf-8")
    return out
