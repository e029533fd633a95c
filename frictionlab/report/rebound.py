"""'Rebound predicted from material data': impact-outcome datasets that state their materials and
friction coefficient, predicted (not fitted) by a rigid sphere and by Mindlin-Deresiewicz compliance
with microslip (frictionlab.physics.mdr), with residuals, and the Psi2-Psi1 diagram of Maw, Barber and Fawcett (frictionlab.solve.rebound)."""
from __future__ import annotations

import math

import numpy as np

from ..solve import rebound
from .doc import Section

TITLE = "Rebound predicted from material data"

#: Display unit and factor from SI per observable.
SHOWN = {"rebound_spin": ("rad/s", 1.0), "contact_rebound_angle": ("deg", 180.0 / math.pi),
         "rebound_angle": ("deg", 180.0 / math.pi)}


def _stated(c) -> list:
    return [d for d in c.datasets if d.kind == "impact-outcome" and getattr(d.scene, "materials", None) is not None
            and d.scene.friction is not None]


def build(ctx):
    sets = _stated(ctx.c)
    if not sets:
        return None
    sec = Section(TITLE)
    sec.p("Coulomb friction at the friction coefficient the source states, Hertz normal contact and (for "
          "Mindlin-Deresiewicz) tangential stiffness 8 G* a(t) from the stated elastic constants, with microslip and "
          "the loading history solved by the Method of Dimensionality Reduction (Popov and Hess 2015); nothing is "
          "fitted. Relative residual = (predicted - measured) / measured; for angles, predicted - measured in degrees.")
    md = "mindlin-deresiewicz"
    summary = {}
    for d in sets:
        unit, f = SHOWN.get(d.observable, ("", 1.0))
        rows = rebound.comparison_rows(d)
        sec.h3(f"{d.name}: {d.observable}" + (f" [{unit}]" if unit else "") + f", μ = {d.scene.friction:g}")
        angle = unit == "deg"  # residuals of an angle near zero are shown absolute, not relative

        def res(r, m):
            return f"{r[m + '_residual'] * f:+.2f}" if angle else f"{100 * r[m + '_relative']:+.1f} %"

        sec.table(["incidence [deg]", "measured", "rigid", "rigid residual", "Mindlin-Deresiewicz", "M-D residual"],
                  [[f"{r['incidence_deg']:.1f}", f"{r['measured'] * f:.4g}", f"{r['rigid'] * f:.4g}", res(r, "rigid"),
                    f"{r[md] * f:.4g}", res(r, md)] for r in rows])
        summary[d.name] = rows
        if d.observable == "rebound_spin":
            low = [r for r in rows if r["incidence_deg"] < 30]
            mid = [r for r in rows if 30 <= r["incidence_deg"] <= 60]
            ok_low = sum(abs(r[md + "_relative"]) < 0.15 for r in low)
            ok_mid = sum(abs(r["rigid_relative"]) < 0.10 for r in mid)
            cors = [c for c in sets if c.observable == "cm_tangential_cor"]
            implied = next((w for w in (rebound.consistency(d, c) for c in cors) if w is not None), None)
            if implied is not None:
                low_i = [i for i, r in enumerate(rows) if r["incidence_deg"] < 30]
                sec.p("Consistency of the measurements: by momentum balance (omega_2 = (1 - e_t) v_t1 / (f r)) the "
                      "same experiment's tangential restitution implies " +
                      ", ".join(f"{implied[i]:.4g} rad/s at {rows[i]['incidence_deg']:.1f} deg "
                                f"({100 * (implied[i] / rows[i]['measured'] - 1):+.1f} % from the measured spin)"
                                for i in low_i) + ": no model can match both figures closer than that.")
            sec.p(f"Below 30 deg the Mindlin-Deresiewicz model is within 15 % of the measured spin at {ok_low} of {len(low)} "
                  f"impact angles; from 30 to 60 deg the rigid model is within 10 % at {ok_mid} of {len(mid)}.")
    ctx.json["rebound_predictions"] = summary
    first = next((d for d in sets if rebound.measured_psi(d) is not None), sets[0])
    speed = float(np.median(first.columns["speed"]))

    def draw():
        curves = rebound.psi_curves(first.scene, speed, np.linspace(1.0, 50.0, 22))
        return rebound.psi_figure(curves, rebound.measured_psi(first),
                                  f"{first.name}: Ψ2 against Ψ1, μ = {first.scene.friction:g}, {speed:g} m/s")

    sec.fig("psi2-psi1.png", "Normalized rebound angle of the contact point against the normalized incidence "
            "(Maw, Barber and Fawcett 1976): rigid closed form, rigid and Mindlin-Deresiewicz simulations, and the measured "
            "points where the dataset is the contact-point rebound angle.", draw)
    return sec
