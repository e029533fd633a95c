"""results.json, schema ``frictionlab.compare/1``, and ranking.csv.

ranking.csv: columns ``ranking.COLUMNS`` then ``UNIT_COLUMNS`` (observable, rss_unit, rmse_unit); per-dataset
  rows, then the rows of each declared group of two or more datasets; rss and rmse in the observable's SI unit, empty for groups.
results.json:
    created, versions{package: version}, settings, wall_time_s,
    datasets[{name, kind, observable, n_points, status: fitted|skipped, reason,
              provenance{kind, source, method, command, seed, truth}}],
    fits[{dataset, law, solver, status: ok|failed|skipped, reason, message, nfev, wall_time_s, cpu_time_s,
          parameters{name: {value, stderr, unit, kind: law|scene|derived, vary, fixed_by, lower, upper,
                            at_bound: lower|upper|null}},
          correlations[{a, b, r}],
          statistics{observable, observable_unit, n_points, n_params, n_free, chisqr, redchi, rss, rmse,
                     aic, aicc, bic, likelihood: known|estimated|mixed|none, likelihood_reason, neg2loglik, k_lik},
          goodness{likelihood, chi2_p, runs_p, runs, runs_expected, lag1, lag1_p, fits, reason, members},
          flags[] (plausibility), plausibility{max_slip_ratio, max_spin_ratio, work_fraction, effect_dchi2{}},
          identifiability{verdict, warnings[], at_bounds[], bounds[{name, side, bound, value, unit, meaning}],
                          missing_stderr{name: reason},
                          high_correlations[{a, b, r}], ratio_only[[a, b]], no_effect[]},
          notes[]}],
    ranking[row], groups[row] (row: the ranking.csv columns plus reason, tied_with, flags[], members[],
                               parameterizations),
    answers[Answer.as_dict()] (answers.py; filled by verdicts.py, equivalence.py, transfer.py; short{best, goodness,
            equivalence, threshold, series, transfer}: the first screen's cells),
    series_slip_zero_s{dataset: time the fitted truncated series' slip crosses zero, null if never},
    equivalence[EquivalenceResult.as_dict(): {dataset, law_a, law_b, solver_a, solver_b, status,
                 verdict: different|equivalent within δ|cannot tell at this noise|both fail their fit tests,
                 explanation, reason, replicates, seed, n_points, chi2{}, k{}, t_obs, t_a[], t_b[], p_a, p_b, q_a, q_b,
                 p (two-sided; null when both laws fail their fit tests), p_adjusted (Holm over the family),
                 p_within (distance of delta or more), p_within_adjusted, family, within,
                 margin (delta, SI or stated precisions), margin_text, rms (the curves' RMS distance), upper (its
                 upper 95% bound), x_a[], x_b[] (replicate distances / delta), x_null_a, x_null_b,
                 p_a_mc_error, p_b_mc_error, power_a, power_b, failed, d_ab, d_ba, sigma, sigma_varies,
                 observable, threshold, threshold_text, alpha, critical_dchi2, fitted{}, fits{}, goodness{},
                 qualitative{verdict, differs, data_differs{}, peak_time{a, b, shift, dt, differs}, features{}, dt},
                 decomposition{b, u0, c_area, c_area_rate, mu, eta_prime, r2} | null}],
    transfer[TransferResult.as_dict(): {group, datasets[], alpha, status (ok|skipped), reason, predictions[{law, solver, source, target,
             status, reason, n, chi2, rms_sigma, loglik, own_chi2, params{}}], shared[{law, solver, datasets,
             status, reason, chi2_shared, k_shared, chi2_separate, k_separate, lr, dk, p_value, delta_aic,
             shared{}, separate{}, serves, alpha}], ranking[{candidate, chi2, n, rms_sigma, loglik, rank}], answer}],
    derivations{dataset: {method: {rms_vs_omega_column, omega_peak, omega_end, noisy_rms_vs_omega_column,
                                   noisy_omega_peak, noisy_omega_end, noisy_median_sigma}}},
    timings_s{stage: wall-clock seconds} (fit, rank, equivalence, transfer, tolerance, accuracy, bootstrap, answer:
              the stages run),
    bootstrap{n (0: not run), seed, method: parametric, level: 0.95, interval: percentile,
              first_place_interval: wilson, all (slow datasets included),
              datasets[{dataset, n_ranked,
                        first_place[{datasets, candidate, law, solver, first_fraction, ci_low, ci_high, level,
                                     first_count, n_ranked, method, seed}],
                        parameters[{law, solver, datasets, parameter, unit, value, stderr, boot_median, boot_std,
                                    ci_low, ci_high, level, n_ok, n_failed, method, seed}]}],
              not_bootstrapped{dataset: reason}},
    tolerance{default_rtol, rtols[],
              rows[{dataset, law, solver, rtol, fit_time_s (CPU), reference, ranking, ranking_as_reference,
                    status, parameter, value, stderr, unit, shift_in_stderr, aic, rank}]},
    accuracy[{dataset, law, solver, rtol, label, reference, error (RMS against the reference solver: observable SI,
              'stated': stated precisions), error_sigma, time_s (CPU per prediction), time_ratio, observable, status
              (ok|not run|failed), reason}] (inference/cost/accuracy.py: what accuracy costs)
  All numbers SI (rad/s, s, m, N) unless the key says otherwise; non-finite numbers are null.
"""
from __future__ import annotations

import datetime as _dt
import math

import numpy as np

from ..inference.resampling.ranking_bootstrap import parameter_table, ranking_table
from ..inference.fitting.predict import FIT_RTOL
from ..inference.verdicts.ranking import COLUMNS, to_csv
from ..inference.diagnostics.identifiability import AT_BOUND_MEANING, at_bounds
from ..io.dataset import COLUMN_SI

#: Columns ranking.csv adds after ``ranking.COLUMNS``: what rss and rmse are measured in.
UNIT_COLUMNS = ("observable", "rss_unit", "rmse_unit")

SCHEMA = "frictionlab.compare/1"


def _num(x):
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    return x


def clean(obj):
    if isinstance(obj, dict):
        return {str(k): clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [clean(v) for v in obj]
    return _num(obj)


def fit_json(f) -> dict:
    out = {"dataset": f.datasets[0] if len(f.datasets) == 1 else list(f.datasets), "law": f.law, "solver": f.solver,
           "status": f.status, "reason": f.reason, "message": f.message, "nfev": f.nfev, "wall_time_s": f.wall_time,
           "cpu_time_s": f.cpu_time, "notes": list(f.notes)}
    if f.ok:
        obs = f.per_dataset[0].target.observable
        out["parameters"] = {n: {"value": p.value, "stderr": p.stderr, "unit": p.unit, "kind": p.kind, "vary": p.vary,
                                 "fixed_by": p.fixed_by, "lower": p.lower, "upper": p.upper,
                                 "at_bound": p.at_bound or None}
                             for n, p in f.params.items()}
        out["correlations"] = [{"a": a, "b": b, "r": r} for (a, b), r in f.correlations.items()]
        s = f.stats
        out["statistics"] = {"observable": obs, "observable_unit": COLUMN_SI.get(obs, "SI"), "n_points": s.n_points,
                             "n_params": s.n_params, "n_free": s.n_free, "chisqr": s.chisqr, "redchi": s.redchi,
                             "rss": s.rss, "rmse": s.rmse, "aic": s.aic, "aicc": s.aicc, "bic": s.bic,
                             "likelihood": s.likelihood, "likelihood_reason": s.likelihood_reason,
                             "neg2loglik": s.neg2loglik, "k_lik": s.k_lik}
        out["goodness"] = f.goodness.as_dict() if f.goodness is not None else None
        out["flags"] = list(f.flags)
        out["plausibility"] = f.plausibility
        i = f.identifiability
        out["identifiability"] = {"verdict": i.verdict, "warnings": list(i.warnings), "at_bounds": list(i.at_bounds),
                                  "bounds": [{"name": h.name, "side": h.side, "bound": h.bound, "value": h.value,
                                              "unit": h.unit, "meaning": AT_BOUND_MEANING} for h in at_bounds(f)],
                                  "missing_stderr": dict(i.missing_stderr),
                                  "high_correlations": [{"a": a, "b": b, "r": r} for a, b, r in i.high_correlations],
                                  "ratio_only": [list(p) for p in i.ratio_only], "no_effect": list(i.no_effect)}
    return out




def _row_json(r) -> dict:
    return {**r.as_dict(), "reason": r.reason, "tied_with": list(r.tied_with), "flags": list(r.flags),
            "members": list(r.members), "parameterizations": r.parameterizations}


def _bootstrap_json(c) -> dict:
    per = [{"dataset": rb.datasets[0], "n_ranked": rb.n_ranked, "first_place": ranking_table(rb),
            "parameters": parameter_table(rb)} for rb in c.bootstrap]
    return {"n": c.settings.get("bootstrap", 0), "seed": c.settings.get("seed", 0), "method": "parametric",
            "level": 0.95, "interval": "percentile", "first_place_interval": "wilson",
            "all": c.settings.get("bootstrap_all", False), "datasets": per,
            "not_bootstrapped": dict(c.bootstrap_skipped)}


def _tolerance_json(c) -> dict:
    return {"default_rtol": FIT_RTOL, "rtols": c.settings.get("tolerance", []), "rows": list(c.tolerance)}


def results_json(c, extra: dict | None = None) -> dict:
    """The whole of results.json; ``extra`` holds numbers the report's sections computed (derivations, ...)."""
    extra = extra or {}
    datasets = []
    for d in c.datasets:
        pv = d.provenance
        datasets.append({"name": d.name, "kind": d.kind, "observable": d.observable, "n_points": len(d),
                         "status": "skipped" if d.name in c.skipped_datasets else "fitted",
                         "reason": c.skipped_datasets.get(d.name, ""),
                         "provenance": {"kind": pv.kind, "source": pv.source, "method": pv.method,
                                        "command": pv.command, "seed": pv.seed, "truth": dict(pv.truth)}})
    return clean({"schema": SCHEMA, "created": _dt.datetime.now().astimezone().isoformat(timespec="seconds"),
                   "versions": c.versions, "settings": c.settings, "wall_time_s": c.wall_time, "datasets": datasets,
                   "fits": [fit_json(f) for f in c.fits], "ranking": [_row_json(r) for r in c.ranking],
                   "groups": [_row_json(r) for r in c.groups],
                   "equivalence": [e.as_dict() for e in c.equivalence],
                   "transfer": [t.as_dict() for t in c.transfer],
                   "derivations": extra.get("derivations", {}), "timings_s": c.timings,
                   "series_slip_zero_s": extra.get("series_slip_zero_s", {}),
                   "answers": [a.as_dict() for a in c.answers],
                   "bootstrap": _bootstrap_json(c), "tolerance": _tolerance_json(c),
                   "accuracy": [r.as_dict() for r in getattr(c, "accuracy", ())]})


def ranking_csv(c) -> str:
    """ranking.csv: ``ranking.to_csv`` with the unit columns appended (empty for group rows)."""
    rows = list(c.ranking) + list(c.groups)
    obs = {d.name: d.observable for d in c.datasets}
    lines = to_csv(rows).rstrip("\n").split("\n")
    out = [lines[0] + "," + ",".join(UNIT_COLUMNS)]
    for r, line in zip(rows, lines[1:]):
        o = obs.get(r.dataset, "")
        u = (COLUMN_SI.get(o, "") or "1") if o and r.dataset in obs and r.rank is not None else ""
        rss_unit = f"({u})^2" if "/" in u else (f"{u}^2" if u not in ("", "1") else u)
        out.append(line + "," + ",".join((o, rss_unit, u)))
    return "\n".join(out) + "\n"
