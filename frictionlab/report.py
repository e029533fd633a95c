"""The comparison report: one folder, written whole or not at all.

``write_report(comparison, out, force=False)`` writes, through ``io.atomic_dir``:

* ``report.md`` and a self-contained ``report.html`` (figures embedded as base64 PNG): ranking
  tables, bootstrap intervals and first-place shares, equivalence verdicts with their numbers,
  what solver tolerance does to a fit, identifiability warnings, the provenance of every dataset
  (reconstructed and synthetic data are labelled as such, never as measured);
* ``figures/*.png``: per dataset the data with every law's fit and the residuals, the force
  histories, the equivalence forces; the ranking heat map; the theta -> omega derivations;
* ``ranking.csv``: columns ``ranking.COLUMNS`` (per-dataset rows, then the 'ALL' group rows;
  rss and rmse in the observable's SI unit, empty for groups);
* ``results.json``, schema ``frictionlab.compare/1``:
    created, versions{package: version}, settings, wall_time_s,
    datasets[{name, kind, observable, n_points, status: fitted|skipped, reason,
              provenance{kind, source, method, command, seed, truth}}],
    fits[{dataset, law, solver, status: ok|failed|skipped, reason, message, nfev, wall_time_s, cpu_time_s,
          parameters{name: {value, stderr, unit, kind: law|scene|derived, vary, fixed_by, lower, upper}},
          correlations[{a, b, r}],
          statistics{observable, observable_unit, n_points, n_params, n_free, chisqr, redchi, rss, rmse,
                     aic, aicc, bic},
          identifiability{verdict, warnings[], at_bounds[], missing_stderr{name: reason},
                          high_correlations[{a, b, r}], ratio_only[[a, b]], no_effect[]},
          notes[]}],
    ranking[row], groups[row] (row: the ranking.csv columns plus reason, tied_with),
    equivalence[EquivalenceResult.as_dict(): {dataset, law_a, law_b, solver_a, solver_b, status, verdict,
                 explanation, reason, replicates, seed, n_points, chi2{}, k{}, t_obs, t_a[], t_b[], p_a, p_b,
                 p_a_mc_error, p_b_mc_error, power_a, power_b, failed, d_ab, d_ba, sigma, sigma_varies,
                 observable, threshold, threshold_text, alpha, power_level, critical_dchi2, fitted{},
                 decomposition{b, u0, c_area, c_area_rate, mu, eta_prime, r2} | null}],
    transfer[TransferResult.as_dict(): {group, datasets[], alpha, predictions[{law, solver, source, target,
             status, reason, n, chi2, rms_sigma, loglik, own_chi2, params{}}], shared[{law, solver, datasets,
             status, reason, chi2_shared, k_shared, chi2_separate, k_separate, lr, dk, p_value, delta_aic,
             shared{}, separate{}, serves}], ranking[{candidate, chi2, n, rms_sigma, loglik, rank}], answer}],
    derivations{dataset: {method: {rms_vs_omega_column, omega_peak, omega_end, noisy_rms_vs_omega_column,
                                   noisy_omega_peak, noisy_omega_end, noisy_median_sigma}}},
    timings_s{stage: wall-clock seconds} (fits, equivalence, tolerance, bootstrap),
    bootstrap{n (0: not run), seed, method: case, level: 0.95, interval: percentile,
              first_place_interval: wilson, all (slow datasets included),
              datasets[{dataset, n_ranked,
                        first_place[{datasets, candidate, law, solver, first_fraction, ci_low, ci_high, level,
                                     first_count, n_ranked, method, seed}],
                        parameters[{law, solver, datasets, parameter, unit, value, stderr, boot_median, boot_std,
                                    ci_low, ci_high, level, n_ok, n_failed, method, seed}]}],
              not_bootstrapped{dataset: reason}},
    tolerance{default_rtol, rtols[],
              rows[{dataset, law, solver, rtol, fit_time_s (CPU), reference, ranking, ranking_as_reference,
                    status, parameter, value, stderr, unit, shift_in_stderr, aic, rank}]}
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
from .bootstrap import parameter_table, ranking_table, wilson
from .display import fmt, interval_text, param_text, unit
from .equivalence import ALPHA, AREA_RATE, CRITICAL, POWER, WEAR
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
          f"{c.versions.get('frictionlab')}; the comparison took {c.wall_time:.1f} s"
          + (" (" + ", ".join(f"{k} {v:.1f} s" for k, v in c.timings.items()) + ", partly in parallel)"
             if len(c.timings) > 1 else "")
          + f" on {c.settings.get('jobs', 1)} worker process{'es' * (c.settings.get('jobs', 1) != 1)}. "
          f"Laws: {', '.join(c.laws)}. "
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
    boot = {rb.datasets[0]: rb for rb in c.bootstrap}
    for d in fitted:
        best = [r for r in c.ranking if r.dataset == d.name and r.rank == 1]
        if best:
            items.append(f"**{d.name}** ({d.provenance.kind}): best " + " = ".join(r.candidate for r in best)
                         + f" (Akaike weight {sum(r.akaike_weight for r in best):.2f}"
                         + (" shared by a tie" if len(best) > 1 else "")
                         + (f"; {_first_share(boot[d.name], best)}" if d.name in boot else
                            "; not bootstrapped" if d.name in c.bootstrap_skipped else "") + ")")
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
    verdicts = tolerance_verdicts(c)
    if verdicts:
        items.append(f"**Solver tolerance** ({c.tolerance[0]['dataset']}): refitted at " + verdicts[0]
                     + " (see 'What solver tolerance does to a fit')")
    doc.items(items)
    paper = [e for e in c.equivalence if (e.law_a, e.law_b) == (WEAR, AREA_RATE)]
    if paper:
        doc.p("Equivalence of λAu and μN + μη′dA/dt: " + "; ".join(
            f"{e.dataset} [wear {e.solver_a}]: **{e.verdict or e.status}**" for e in paper) + ".")
    for tr in c.transfer:
        doc.p(f"Across conditions ({tr.group}): {tr.answer()}.")

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

    _bootstrap_section(doc, c)

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

    _tolerance_section(doc, c)

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
    doc.h(2, "Equivalence test: can the data tell two laws apart?")
    R = c.settings.get("replicates", 0)
    doc.p("The paper claims that the wear law λAu is 'qualitatively equivalent' to the empirical μN + μη′dA/dt. "
          "Per dataset, each pair of laws is put to a Cox-type discrimination test: the statistic is "
          "T = χ²(A) − χ²(B) at the dataset's declared noise (−2 ln of the likelihood ratio); "
          f"{R} replicate datasets are simulated from each law's best fit with that noise, both laws are refitted "
          "to each, and the observed T is compared with its distribution under A (large T rejects A) and under B "
          f"(small T rejects B) at level {ALPHA:g}, with the Monte-Carlo error of each p-value. Verdict: **not "
          "equivalent** if T rejects a law (the text says which); **equivalent** if T is consistent with both and "
          f"the two null distributions overlap (each law's replicates reject the other less than {POWER:.0%} of the "
          "time): data of this noise cannot tell them apart; **cannot tell at this noise** if T is consistent with "
          "both although the test has power. T compares the two laws only: whether either fits is the "
          "goodness-of-fit question. The noise threshold: each law refitted to the other's noise-free best curve "
          f"leaves a χ² that scales as 1/σ²; the laws differ by more than the noise below the σ at which the larger "
          f"reaches {CRITICAL:g} (χ², one degree of freedom, 95%). The paper's decomposition "
          "F ≈ λu0(1 − b)A + (λu0b/(φA0)) A dA/dt rests on its truncated slip (eq 7), so it is shown for the "
          "series fit only; the paper prints the second factor as φ/A0, dimensionally it is 1/(φA0).")
    if not c.equivalence:
        doc.p("Not run: it needs two laws of a pair in the comparison (see --no-equivalence).")
        return
    rows = []
    for e in c.equivalence:
        if e.status != "ok":
            rows.append([e.dataset, f"{e.law_a} [{e.solver_a}]", f"{e.law_b} [{e.solver_b}]",
                         f"{e.status}: {e.reason}"] + [""] * 5)
            continue
        rows.append([e.dataset, f"{e.law_a} [{e.solver_a}]", f"{e.law_b} [{e.solver_b}]", e.verdict,
                     fmt(e.t_obs, 4), f"{e.p_a:.2g} ± {e.mc_error(e.p_a):.1g}", f"{e.p_b:.2g} ± {e.mc_error(e.p_b):.1g}",
                     f"{e.power_a:.0%} / {e.power_b:.0%}", e.threshold_text()])
    doc.table(["dataset", "law A", "law B", "verdict", "T = χ²A − χ²B", "p under A", "p under B",
               "power (reject A | B / reject B | A)", "noise threshold"], rows)
    doc.items([f"**{e.dataset}: {e.label} — {e.verdict}**: {e.explanation}" for e in c.equivalence if e.ok])
    for d in c.fitted_datasets:
        tested = [e for e in c.equivalence if e.dataset == d.name and e.ok]
        if tested:
            name = f"discrimination-{d.name}.png"
            figs[name] = figures.discrimination_figure(d.name, tested)
            doc.fig(name, f"{d.name}: T under each law's fit (histograms) and on the data (line); a law is rejected "
                          "when the line lies in the far tail of its histogram.")
    for e in c.equivalence:
        if e.decomposition is not None:
            d = e.decomposition
            fa = c.fit_for(e.dataset, AREA_RATE)
            fitted = (f" against fitted μ = {fmt(fa.value('mu'), 3)}, η′ = {fmt(fa.value('eta_prime'), 3)} N s/m²"
                      if fa is not None and fa.ok else "")
            doc.p(f"{e.dataset}: the paper's decomposition of the wear series fit (b = {d.b:.3g}) implies "
                  f"μ = {d.mu:.3g}, η′ = {d.eta_prime:.4g} N s/m²{fitted} (projection R² = {d.r2:.2f}).")
    for d in c.fitted_datasets:
        mine = [e for e in c.equivalence if e.dataset == d.name and e.ok and (e.law_a, e.law_b) == (WEAR, AREA_RATE)]
        if not mine:
            continue
        fa = c.fit_for(d.name, AREA_RATE, mine[0].solver_b)
        fws = [c.fit_for(d.name, WEAR, e.solver_a) for e in mine]
        name = f"equivalence-{d.name}.png"
        figs[name] = figures.equivalence_figure(d, fws, fa, [e.decomposition for e in mine])
        doc.fig(name, f"{d.name}: friction force of the wear and area-rate fits"
                + (", and the paper's decomposition of the series fit with its projection onto μN + μη′dA/dt."
                   if any(e.decomposition for e in mine) else "."))
    _transfer_section(doc, c)


def _transfer_section(doc: Doc, c: Comparison):
    if not c.transfer:
        return
    doc.h(2, "Prediction across conditions")
    doc.p("A law is a material statement: one parameter set should serve every member of a dataset group. "
          "Transfer: the law parameters fitted on one member predict each other member without refitting (scene "
          "quantities and [fixed] values stay the target's own); the error is given in noise sigmas (RMS) and as "
          "predictive χ². Shared against separate: one global fit for the whole group against separate fits; "
          "LR = χ²shared − χ²separate with the chi-square p-value for the extra parameters, and "
          "ΔAIC = AIC shared − AIC separate (negative: one parameter set is preferred).")
    for tr in c.transfer:
        doc.p(f"**{tr.group}** ({', '.join(tr.datasets)}): {tr.answer()}.")
        rows = []
        for r in tr.ranking():
            preds = [p for p in tr.predictions if p.candidate == r["candidate"]]
            sh = next((s for s in tr.shared if s.candidate == r["candidate"]), None)
            rows.append([r["rank"], r["candidate"], fmt(r["rms_sigma"], 3),
                         "; ".join(f"{p.source}→{p.target} {p.rms_sigma:.3g}σ" for p in preds),
                         "" if sh is None or sh.status != "ok" else
                         f"LR {fmt(sh.lr, 4)} (dk {sh.dk}), p {sh.p_value:.2g}, ΔAIC {sh.delta_aic:.1f}",
                         "" if sh is None else ("yes" if sh.serves else "no" if sh.serves is False else sh.reason)])
        doc.table(["rank", "law [solver]", "RMS error [σ]", "per direction", "shared vs separate",
                   "one parameter set serves"], rows)


def _pct(x: float) -> str:
    return f"{100 * x:.0f}%" if math.isfinite(x) else ""


def _first_share(rb, best) -> str:
    """'first in 97% of 200 resamples (95% interval 94-99%)' for the rank-1 candidates ``best``."""
    if not rb.n_ranked:
        return "no resample could rank every candidate"
    k = sum(rb.first.get(r.candidate, 0.0) for r in best)
    lo, hi = wilson(k, rb.n_ranked)
    return f"first in {_pct(k / rb.n_ranked)} of {rb.n_ranked} resamples, 95% interval {_pct(lo)}–{_pct(hi)}"


def _rtol(r: float) -> str:
    return f"{r:.0e}".replace("e-0", "e-")


def _bootstrap_section(doc: Doc, c: Comparison):
    n, seed = c.settings.get("bootstrap", 0), c.settings.get("seed", 0)
    doc.h(2, "Bootstrap: how firm are the parameters and the ranking")
    if not n:
        doc.p("Not run: this comparison was made with `--bootstrap 0`, so it has no confidence intervals from "
              "resampling; the error bars under Fits are lmfit's standard errors only. Run `frictionlab compare "
              "--bootstrap N` to add them.")
        return
    doc.p(f"Each candidate (law [solver]) was refitted to the same {n} **case resamples** of its dataset: rows drawn "
          "with replacement and kept in time order, so no law's model is assumed. Each refit starts from the "
          "candidate's best fit on the original data (no grid scan, one Levenberg-Marquardt run). Parameter "
          "intervals are 95% **percentile intervals** (2.5th to 97.5th percentile of the refitted values). "
          "**First place** is the share of resamples in which a candidate has the lowest AIC (candidates within "
          f"ΔAIC ≤ {TIE_AIC} share first place and split the count), with a 95% **Wilson score interval**. "
          f"Seed {seed} (`--seed`), the same for every dataset, so a dataset's numbers do not depend on which "
          "others are compared, nor on the number of worker processes.")
    if c.bootstrap_skipped:
        doc.p("**Not bootstrapped:**")
        doc.items([f"**{d}**: {why.replace('--bootstrap-all', '`--bootstrap-all`')}"
                   for d, why in c.bootstrap_skipped.items()])
    if not c.bootstrap:
        return
    rows = []
    for rb in c.bootstrap:
        best = [r for r in c.ranking if r.dataset == rb.datasets[0] and r.rank == 1]
        labels = {r.candidate for r in best}
        table = ranking_table(rb)
        others = [f"{r['candidate']} {_pct(r['first_fraction'])} ({_pct(r['ci_low'])}–{_pct(r['ci_high'])})"
                  for r in table if r["first_count"] > 0 and r["candidate"] not in labels]
        never = [r["candidate"] for r in table if r["first_count"] == 0 and r["candidate"] not in labels]
        rows.append([rb.datasets[0], " = ".join(r.candidate for r in best), _first_share(rb, best),
                     "; ".join(others) or "none", ", ".join(never)])
    doc.h(3, "First place under resampling")
    doc.p("Candidates tied on the original data (the same curve, such as wear and Couette on a given area history) "
          "split each first place between them; their shares are summed here. results.json has each one's share.")
    doc.table(["dataset", "best on the original data", "its first places", "others ever first: share (95% interval)",
               "never first"], rows)
    doc.h(3, "Parameter intervals")
    doc.p("Beside each fitted value and its lmfit standard error: the bootstrap median and 95% interval, and the "
          "interval's width relative to ±1.96 standard errors. Near 1 the two agree; well above 1 the standard "
          "error is too optimistic (it assumes the model is right and the residuals are independent noise); well "
          "below 1 the resamples barely move the fit.")
    prow, undetermined = [], {}
    for rb in c.bootstrap:
        for r in parameter_table(rb):
            width = (r["ci_high"] - r["ci_low"]) / (2 * 1.96 * r["stderr"]) if r["stderr"] else math.nan
            prow.append([r["datasets"], f"{r['law']} [{r['solver']}]", r["parameter"],
                         param_text(r["value"], r["stderr"], r["unit"]),
                         param_text(r["boot_median"], None, r["unit"]) if r["n_ok"] else "",
                         interval_text(r["ci_low"], r["ci_high"], r["unit"], r["value"]), fmt(width, 2),
                         f"{r['n_ok']} of {r['n_ok'] + r['n_failed']}"])
        for b in rb.results.values():
            missing = b.base.identifiability.missing_stderr
            left = [p.name for p in b.base.params.values() if p.vary and p.name not in b.names]
            if left:
                why = "; ".join(dict.fromkeys(missing.get(k, "not determined") for k in left))
                cands, dss = undetermined.setdefault((", ".join(left), why), ({}, {}))
                cands[f"{b.law} [{b.base.solver}]"] = dss[rb.datasets[0]] = None
    doc.table(["dataset", "law [solver]", "parameter", "fit ± standard error", "bootstrap median",
               "95% interval", "width vs ±1.96σ", "refits ok"], prow)
    if undetermined:
        doc.p("Not bootstrapped, because the data do not determine them (the combination that is determined, such "
              "as eta/h, is in the table):")
        doc.items([f"{params} ({', '.join(cands)} on {', '.join(dss)}): {'each ' if ',' in params else ''}{why}"
                   for (params, why), (cands, dss) in undetermined.items()])


def _tolerance_section(doc: Doc, c: Comparison):
    from .predict import FIT_RTOL

    rtols = c.settings.get("tolerance") or []
    doc.h(2, "What solver tolerance does to a fit")
    if not rtols:
        doc.p("Not run (`--no-tolerance`). `frictionlab bench` measures it in full.")
        return
    if not c.tolerance:
        doc.p("No law needs the ODE solver on these datasets: every fit is closed-form or the paper's series, which "
              "have no tolerance. `frictionlab bench` measures what tolerance costs and buys.")
        return
    rows = list(c.tolerance)
    ds = rows[0]["dataset"]
    method = next((r["solver"].partition(":")[2] for r in rows if ":" in r["solver"]), "LSODA")
    laws = list(dict.fromkeys(r["law"] for r in rows))
    held = [g for g in rows[0]["ranking"].replace(" = ", " > ").split(" > ") if g not in laws]
    held_text = (f"; {', '.join(held)} (closed form) {'keeps its fit' if len(held) == 1 else 'keep their fits'} "
                 "and joins the ranking") if held else ""
    doc.p(f"Every ODE fit in this report solves to rtol {FIT_RTOL:g} (atol equal, on a problem scaled to order one): "
          f"finite-difference Jacobians need a smooth model. How much does that matter? On **{ds}**, the laws that "
          f"need the ODE there ({', '.join(laws)}; {method}) were refitted from scratch at rtol "
          f"{' and '.join(_rtol(r) for r in rtols)}{held_text}. Shift = (value − value at "
          f"{FIT_RTOL:g}) / its standard error, the largest over the law's parameters; fit time is the CPU seconds "
          "of one whole fit (grid of starts and Levenberg-Marquardt) on this machine under its current load. "
          "`frictionlab bench` runs the full study: more methods and tolerances, and work-precision diagrams.")
    groups = {}
    for r in rows:
        groups.setdefault((r["rtol"], r["law"]), []).append(r)
    table = []
    for (rtol, law), rs in sorted(groups.items(), key=lambda kv: (kv[0][0], laws.index(kv[0][1]))):
        r0 = rs[0]
        if r0["status"] != "ok":
            table.append([law, _rtol(rtol), r0["status"]] + [""] * 5)
            continue
        shifts = [abs(r["shift_in_stderr"]) for r in rs if math.isfinite(r["shift_in_stderr"])]
        table.append([law, _rtol(rtol) + (" (default)" if rtol == FIT_RTOL else ""),
                      "; ".join(f"{r['parameter']} = {param_text(r['value'], r['stderr'], r['unit'])}" for r in rs),
                      fmt(max(shifts), 2) if shifts else "", fmt(r0["fit_time_s"], 2), fmt(r0["aic"]),
                      r0["rank"], "yes" if r0["ranking_as_reference"] else "**no**"])
    doc.table(["law", "rtol", "parameters (value ± standard error)", "largest shift [σ]", "fit time [CPU s]", "AIC",
               "rank", f"ranking as at {FIT_RTOL:g}"], table)
    verdicts = tolerance_verdicts(c)
    doc.items([v + "." for v in verdicts])


def tolerance_verdicts(c: Comparison) -> list[str]:
    """Per looser tolerance: whether the ranking changes, the largest parameter shift and AIC change,
    and the fit time against the default tolerance's."""
    from .predict import FIT_RTOL

    rows = list(c.tolerance)
    ref = {r["law"]: r for r in rows if r["rtol"] == FIT_RTOL}
    out = []
    for rtol in c.settings.get("tolerance") or []:
        at = [r for r in rows if r["rtol"] == rtol]
        if not at:
            continue
        shift = max(((abs(r["shift_in_stderr"]), r) for r in at if math.isfinite(r["shift_in_stderr"])),
                    key=lambda x: x[0], default=None)
        daic = max(((abs(r["aic"] - ref[r["law"]]["aic"]), r["law"]) for r in at
                    if r["law"] in ref and math.isfinite(r["aic"]) and math.isfinite(ref[r["law"]]["aic"])),
                   default=None)
        t = sum({r["law"]: r["fit_time_s"] for r in at}.values())
        t0 = sum({r["law"]: r["fit_time_s"] for r in ref.values()}.values())
        out.append(f"rtol {_rtol(rtol)}: the ranking is " + ("unchanged" if at[0]["ranking_as_reference"] else
                                                              f"**different** ({at[0]['ranking']})")
                   + (f"; the largest shift is {shift[0]:.2g}σ ({shift[1]['law']} {shift[1]['parameter']})"
                      if shift else "")
                   + (f", the largest AIC change {daic[0]:.2g} ({daic[1]})" if daic else "")
                   + f"; the fits took {t:.1f} CPU s against {t0:.1f} s at {_rtol(FIT_RTOL)}")
    return out


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
        "Solvers: 'exact' where the law and scene admit a closed form, else 'ode' (LSODA, rtol 1e-10; what a "
        "looser tolerance changes is under 'What solver tolerance does to a fit'); 'series' (the paper's first-order "
        "expansion, eqs 7-11) in addition wherever it is defined.",
        "Bootstrap (`--bootstrap N`, `--seed`): case resampling, every candidate refitted to the same resamples; "
        "95% percentile intervals for parameters, 95% Wilson intervals for first-place shares (see 'Bootstrap').",
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
           "cpu_time_s": f.cpu_time, "notes": list(f.notes)}
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


def _bootstrap_json(c: Comparison) -> dict:
    per = [{"dataset": rb.datasets[0], "n_ranked": rb.n_ranked, "first_place": ranking_table(rb),
            "parameters": parameter_table(rb)} for rb in c.bootstrap]
    return {"n": c.settings.get("bootstrap", 0), "seed": c.settings.get("seed", 0), "method": "case",
            "level": 0.95, "interval": "percentile", "first_place_interval": "wilson",
            "all": c.settings.get("bootstrap_all", False), "datasets": per,
            "not_bootstrapped": dict(c.bootstrap_skipped)}


def _tolerance_json(c: Comparison) -> dict:
    from .predict import FIT_RTOL

    return {"default_rtol": FIT_RTOL, "rtols": c.settings.get("tolerance", []), "rows": list(c.tolerance)}


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
                   "equivalence": [e.as_dict() for e in c.equivalence],
                   "transfer": [t.as_dict() for t in c.transfer],
                   "derivations": deriv_stats or {}, "timings_s": c.timings,
                   "bootstrap": _bootstrap_json(c), "tolerance": _tolerance_json(c)})


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
