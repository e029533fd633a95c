"""'What solver tolerance does to a fit': the ODE laws of one dataset refitted at other tolerances."""
from __future__ import annotations

import math

from ..core.display import fmt, param_text
from ..inference.fitting.predict import FIT_RTOL
from .doc import Section
from .text import rtol_text

TITLE = "What solver tolerance does to a fit"
#: The section when the check was not asked for (it is on demand: a robustness check beside the answer).
NOT_RUN = ("**Not run.** What each solver's accuracy costs at the fitted parameters (its error against the most "
           "accurate solver, and its time) is on the first screen, for every law and dataset where that is cheap. "
           "This further check refits the ODE laws of one dataset at a looser and a tighter solver tolerance to "
           "show that the default tolerance does not move the fits; it changes no fit, ranking or verdict above, so "
           "it runs only on demand: `frictionlab compare --tolerance` (API: `compare(..., tolerance=(1e-3, "
           "1e-10))`), which also runs the accuracy study where it is not cheap. `frictionlab bench` measures it "
           "in full.")


def build(ctx) -> Section:
    c = ctx.c
    sec = Section(TITLE)
    rtols = c.settings.get("tolerance") or []
    if not rtols:
        sec.p(NOT_RUN)
        return sec
    if not c.tolerance:
        sec.p("No law needs the ODE solver on these datasets: every fit is closed-form or the paper's series, which "
              "have no tolerance. `frictionlab bench` measures what tolerance costs and buys.")
        return sec
    rows = list(c.tolerance)
    ds = rows[0]["dataset"]
    method = next((r["solver"].partition(":")[2] for r in rows if ":" in r["solver"]), "LSODA")
    laws = list(dict.fromkeys(r["law"] for r in rows))
    held = [g for g in rows[0]["ranking"].replace(" = ", " > ").split(" > ") if g not in laws]
    held_text = (f"; {', '.join(held)} (closed form) {'keeps its fit' if len(held) == 1 else 'keep their fits'} "
                 "and joins the ranking") if held else ""
    sec.p(f"Every ODE fit in this report solves to rtol {FIT_RTOL:g} (atol equal, on a problem scaled to order one): "
          f"finite-difference Jacobians need a smooth model. How much does that matter? On **{ds}**, the laws that "
          f"need the ODE there ({', '.join(laws)}; {method}) were refitted from scratch at rtol "
          f"{' and '.join(rtol_text(r) for r in rtols)}{held_text}. Shift = (value − value at "
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
            table.append([law, rtol_text(rtol), r0["status"]] + [""] * 5)
            continue
        shifts = [abs(r["shift_in_stderr"]) for r in rs if math.isfinite(r["shift_in_stderr"])]
        table.append([law, rtol_text(rtol) + (" (default)" if rtol == FIT_RTOL else ""),
                      "; ".join(f"{r['parameter']} = {param_text(r['value'], r['stderr'], r['unit'], r.get('shown', ''))}" for r in rs),
                      fmt(max(shifts), 2) if shifts else "", fmt(r0["fit_time_s"], 2), fmt(r0["aic"]),
                      r0["rank"], "yes" if r0["ranking_as_reference"] else "**no**"])
    sec.table(["law", "rtol", "parameters (value ± standard error)", "largest shift [σ]", "fit time [CPU s]", "AIC",
               "rank", f"ranking as at {FIT_RTOL:g}"], table)
    verdicts = tolerance_verdicts(c)
    sec.items([v + "." for v in verdicts])
    return sec


def tolerance_verdicts(c: Comparison) -> list[str]:
    """Per other tolerance: whether the ranking changes, the largest parameter shift and AIC change,
    and the fit time against the default tolerance's."""
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
        out.append(f"rtol {rtol_text(rtol)}: the ranking is " + ("unchanged" if at[0]["ranking_as_reference"] else
                                                              f"**different** ({at[0]['ranking']})")
                   + (f"; the largest shift is {shift[0]:.2g}σ ({shift[1]['law']} {shift[1]['parameter']})"
                      if shift else "")
                   + (f", the largest AIC change {daic[0]:.2g} ({daic[1]})" if daic else "")
                   + f"; the fits took {t:.1f} CPU s against {t0:.1f} s at {rtol_text(FIT_RTOL)}")
    return out

