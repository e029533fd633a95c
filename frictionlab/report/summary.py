"""'Summary': when and how the comparison ran, and per dataset its best candidate in one line."""
from __future__ import annotations

import datetime as _dt
import math

from ..inference.resampling.ranking_bootstrap import wilson
from ..inference.equivalence.discrimination import AREA_RATE, WEAR
from ..inference.verdicts.ranking import weight_text
from .doc import Section
from .text import PROVENANCE_WORDS, pct

TITLE = "Summary"


def first_share(rb, best) -> str:
    """'first in 97% of 200 resamples (95% interval 94-99%)' for the rank-1 candidates ``best``."""
    if not rb.n_ranked:
        return "no resample could rank every candidate"
    k = sum(rb.first.get(r.candidate, 0.0) for r in best)
    lo, hi = wilson(k, rb.n_ranked)
    return f"first in {pct(k / rb.n_ranked)} of {rb.n_ranked} resamples, 95% interval {pct(lo)}–{pct(hi)}"


def build(ctx) -> Section:
    c = ctx.c
    sec = Section(TITLE)
    sec.p(_how_it_ran(c))
    warning = _provenance_warning(c)
    if warning:
        sec.warn(warning)
    sec.items(_best_items(c) + _group_items(c) + _series_items(c) + _tolerance_items(c))
    _equivalence_table(sec, c)
    for tr in c.transfer:
        sec.p(f"Across conditions ({tr.group}): {tr.answer()}.")
    return sec


def _how_it_ran(c) -> str:
    """When, by which version, how long, on how many workers, which laws and datasets."""
    jobs = c.settings.get("jobs", 1)
    return (f"Generated {_dt.datetime.now().astimezone().strftime('%Y-%m-%d %H:%M %Z')} by frictionlab "
            f"{c.versions.get('frictionlab')}; the comparison took {c.wall_time:.1f} s"
            + (" (" + ", ".join(f"{k} {v:.1f} s" for k, v in c.timings.items()) + ", partly in parallel)"
               if len(c.timings) > 1 else "")
            + (f" on a {c.settings['cluster']}" if c.settings.get("cluster") else
               f" on {jobs} worker process{'es' * (jobs != 1)}") + f". Laws: {_laws_text(c)}. "
            f"Datasets: {len(c.datasets)} ({len(c.fitted_datasets)} fitted).")


def _laws_text(c) -> str:
    """The laws compared, by dataset kind when they were chosen by kind (the default laws)."""
    from ..pipeline.settings import laws_groups

    groups = laws_groups(c.settings.get("laws_by_kind") or {}, {d.kind for d in c.datasets if d.kind != "contact-area"})
    if not groups:
        return ", ".join(c.laws)
    return "; ".join(f"{', '.join(laws)} on {', '.join(k)} datasets" for laws, k in groups)


def _provenance_warning(c) -> str:
    """A warning when not every dataset is a measurement ('' when all are)."""
    kinds = {}
    for d in c.datasets:
        kinds.setdefault(d.provenance.kind, []).append(d.name)
    if not [n for k, v in kinds.items() if k != "measured" for n in v]:
        return ""
    parts = [f"{len(v)} {PROVENANCE_WORDS.get(k, k)} ({', '.join(v)})" for k, v in kinds.items()]
    return (("No dataset in this report is a measurement. " if "measured" not in kinds else
             "Not every dataset in this report is a measurement. ") + "; ".join(parts) + ". Reconstructed "
            "series are curves rebuilt to agree with numbers stated in a paper; synthetic series were made up "
            "(the built-in ones by a known law plus noise; others as their source says). Rankings on them test the method and the claims' internal "
            "consistency, not nature.")


def _best_items(c) -> list[str]:
    """Per fitted dataset its rank-1 candidates, their Akaike weight and bootstrap share."""
    items = []
    boot = {rb.datasets[0]: rb for rb in c.bootstrap}
    for d in c.fitted_datasets:
        best = [r for r in c.ranking if r.dataset == d.name and r.rank == 1]
        if best:
            fits = all(r.fits and not r.flags for r in best)
            weights = [r.akaike_weight for r in best if math.isfinite(r.akaike_weight)]
            weight = weight_text(sum(weights) if weights else math.nan, best[0].weight_among,
                                 False if any(r.fits is False for r in best) else best[0].fits)
            items.append(f"**{d.name}** ({d.provenance.kind}): {'best' if fits else 'top-ranked (does not fit)'} "
                         + " = ".join(r.candidate for r in best)
                         + f" ({weight}" + (", shared by a tie" if len(best) > 1 and weights else "")
                         + (f"; {first_share(boot[d.name], best)}" if d.name in boot else
                            "; not bootstrapped" if d.name in c.bootstrap_skipped else "") + ")")
        else:
            items.append(f"**{d.name}**: no law could be fitted")
    return items


def _group_items(c) -> list[str]:
    """Per dataset group its rank-1 candidates by summed AIC."""
    items = []
    for g in dict.fromkeys(r.dataset for r in c.groups):
        best = [r.candidate for r in c.groups if r.dataset == g and r.rank == 1]
        fits = all(r.fits and not r.flags for r in c.groups if r.dataset == g and r.rank == 1)
        if best:
            items.append(f"**{g}**: {'best' if fits else 'top-ranked (does not fit)'} " + " = ".join(best)
                         + " (summed AIC over the group"
                         + ("; a tie" if len(best) > 1 else "") + ")")
    return items


def _series_items(c) -> list[str]:
    """Where the paper's truncated series and the exact solution of one law differ by more than 2 in AIC."""
    from .ranking import curve_labels

    items = []
    for d in c.fitted_datasets:
        labels, said = curve_labels(c, d.name), set()
        for law in c.laws:
            label = labels.get((law, "series"), law)
            if label in said:  # one functional form (wear = couette): one sentence
                continue
            said.add(label)
            ser = next((r for r in c.ranking if r.dataset == d.name and r.law == law and r.solver == "series"
                        and r.rank), None)
            full = next((r for r in c.ranking if r.dataset == d.name and r.law == law and r.solver != "series"
                         and r.rank), None)
            if ser and full and abs(ser.aic - full.aic) > 2:
                better = "better" if ser.aic < full.aic else "worse"
                items.append(f"**{d.name}**: the truncated series of {label} fits {better} than the {full.solver} "
                             f"solution of the same law (ΔAIC {abs(ser.aic - full.aic):.1f}): the approximation, not "
                             "the law, makes that difference (see the notes under Fits)")
    return items


def _tolerance_items(c) -> list[str]:
    from .tolerance import tolerance_verdicts

    if not c.settings.get("tolerance"):
        return ["**Solver tolerance**: the fits were not refitted at other tolerances in this run (on demand: "
                "`frictionlab compare --tolerance`; see 'What solver tolerance does to a fit'); what each solver's "
                "accuracy costs is on the first screen"]
    verdicts = tolerance_verdicts(c)
    if not verdicts:
        return []
    return [f"**Solver tolerance** ({c.tolerance[0]['dataset']}): refitted at " + verdicts[0]
            + " (see 'What solver tolerance does to a fit')"]


def _equivalence_table(sec: Section, c):
    """The paper's equivalence verdict per dataset, exact (or ODE) and series."""
    paper = [e for e in c.equivalence if (e.law_a, e.law_b) == (WEAR, AREA_RATE)]
    if not paper:
        return
    sec.p("Equivalence of λAu and μN + μη′dA/dt per dataset (the discrimination test; details under "
          "'Equivalence test'):")
    verdicts: dict[str, dict[str, str]] = {}
    for e in paper:
        key = "series" if e.solver_a == "series" else "full"
        verdicts.setdefault(e.dataset, {})[key] = (e.verdict or e.status) + ("" if key == "series" else
                                                                              f" [{e.solver_a}]")
    sec.table(["dataset", "wear solved exactly or numerically", "wear by the paper's series"],
              [[d, v.get("full", ""), v.get("series", "–")] for d, v in verdicts.items()])
