"""Starting points for a dataset of one's own: a commented TOML and a CSV that load as they are.

``template(kind)`` returns (toml_text, csv_text) for 'impact', 'incline' or 'impact-outcome'. The
CSV rows are example numbers computed from a law on the template's scene (say which in the
file), to be replaced by the user's data; the TOML explains every field and the rules the
loader enforces (time column ``t`` from 0 in increasing order, one noise level per fitted
column, units on every dimensional value).
"""
from __future__ import annotations

import tomllib

from ..core.errors import DatasetError
from ..core.names import check_name

KINDS = ("impact", "incline", "impact-outcome")

_COMMON_TAIL = '''
[provenance]
# What these numbers are: measured | reported (values printed in a paper) | reconstructed | synthetic.
# The report labels anything but 'measured' as such. These example rows are synthetic: replace them.
kind = "synthetic"
source = "frictionlab datasets template: example numbers, not a measurement; replace with your source"
method = "{method}"
command = "{command}"      # for synthetic or reconstructed data: the command that regenerates them

[provenance.truth]         # for synthetic data: the generating law and parameters (the report checks them)
{truth}

# [fixed]                  # optional: law parameters held at a value in every fit, with units
# eta = "0.1 Pa s"
# [reported]               # optional: values a publication states, shown beside the fits
# lam = "1.81e6 Pa s/m"
'''

_IMPACT = '''# A frictionlab dataset: this TOML describes the CSV of the same name beside it.
# Load it with  frictionlab datasets show {stem}.toml  and fit it with  frictionlab fit wear {stem}.toml
name = "{name}"
kind = "impact"            # impact | incline | impact-outcome | contact-area
observable = "omega"       # the column that is fitted: omega (spin), theta (rotation angle), v or u
description = "A ball in oblique impact on a rigid target: spin during contact. Say what, where and how."

[columns]                  # every CSV column with its unit; the time column must be called t
t = "us"                   # times from first contact (t = 0), strictly increasing
omega = "rpm"
theta = "deg"

[noise]                    # one standard deviation per fitted column, with its unit
omega = "200 rpm"
theta = "0.5 deg"

[scene]                    # the body and the contact; every dimensional value says its unit
mass = "46 g"
radius = "21.3 mm"
inertia_factor = 0.4       # I = f m r^2 (0.4: solid sphere)
u0 = "12 m/s"              # initial slip of the contact point
effects = ["spin"]

[scene.area]               # contact area A(t): half-sine A0 sin(pi t / t_c), or constant, or a column
model = "half-sine"
peak = "130 mm^2"
contact_time = "500 us"

[scene.normal]             # normal force N(t), for laws that need it (Coulomb, area-rate)
model = "half-sine"
impulse = "2.0 N*s"
'''

_INCLINE = '''# A frictionlab dataset: this TOML describes the CSV of the same name beside it.
# Load it with  frictionlab datasets show {stem}.toml  and fit it with  frictionlab fit couette {stem}.toml
name = "{name}"
kind = "incline"           # impact | incline | impact-outcome | contact-area
observable = "v"           # the column that is fitted: v (velocity along the incline) or u
description = "A block sliding from rest down an incline. Say what, where and how."

[columns]                  # every CSV column with its unit; the time column must be called t
t = "s"                    # times from release (t = 0), strictly increasing
v = "m/s"

[noise]                    # one standard deviation per fitted column, with its unit
v = "3 mm/s"

[scene]
mass = "20 g"
u0 = "0 m/s"               # velocity at t = 0
incline = "20 deg"

[scene.area]               # constant contact area (or model = "growth" with initial and rate)
model = "constant"
area = "100 mm^2"
'''

_OUTCOME = '''# A frictionlab dataset: this TOML describes the CSV of the same name beside it.
# Load it with  frictionlab datasets show {stem}.toml  and fit it with  frictionlab fit coulomb {stem}.toml
name = "{name}"
kind = "impact-outcome"    # one impact per row, no time column
observable = "rebound_spin"  # rebound_spin, tangential_cor or rebound_angle
description = "Oblique impacts of a ball on a plate, one per row. Say what, where and how."

[columns]                  # inputs speed and incidence (from the surface normal), and the outcomes
speed = "m/s"
incidence = "deg"
rebound_spin = "rpm"

[noise]
rebound_spin = "100 rpm"

[scene]
mass = "45.9 g"
radius = "21.35 mm"
inertia_factor = 0.4
effects = ["spin", "slip-coupling"]
angle_reference = "normal"   # incidence measured from the surface normal (or "surface")

[scene.normal]
model = "half-sine"
contact_time = "450 us"
restitution = 0.78

[scene.area]
model = "half-sine"
peak = "150 mm^2"
'''


def template(kind: str, name: str = "my-data") -> tuple[str, str]:
    """(TOML text, CSV text) of a dataset of ``kind`` named ``name`` that loads as it is."""
    import numpy as np  # here, not at the top: the command line names KINDS in its help without numpy

    from ..physics.scene import Scene
    from ..solve.outcome import OutcomeScene, predict_outcomes
    from ..solve.solvers import simulate

    if kind not in KINDS:
        raise DatasetError(f"datasets template: kind {kind!r}; expected one of {', '.join(KINDS)}")
    check_name(name, "datasets template: --name", DatasetError)
    head = {"impact": _IMPACT, "incline": _INCLINE, "impact-outcome": _OUTCOME}[kind]
    law, params, units = {"impact": ("wear", {"lam": 1.8e6}, {"lam": "Pa s/m"}),
                          "incline": ("couette", {"eta": 0.1, "h": 4e-5}, {"eta": "Pa s", "h": "m"}),
                          "impact-outcome": ("coulomb", {"mu": 0.25}, {"mu": ""})}[kind]
    method = f"the {law} law with {', '.join(f'{k} = {v:g}' for k, v in params.items())} (SI), no noise"
    truth = "\n".join([f'law = "{law}"'] + [f'{k} = "{v:g} {units[k]}"' if units[k] else f"{k} = {v:g}"
                                            for k, v in params.items()])
    toml = head.format(name=name, stem=name) + _COMMON_TAIL.format(
        method=method, command=f"frictionlab datasets template {kind} --name {name}", truth=truth)
    spec = tomllib.loads(toml)["scene"]
    rows = [f"# Example rows computed with {method}: replace them with your data (same columns, same units).",
            "# Lines starting with # are comments; the first other line names the columns."]
    if kind == "impact-outcome":
        speed = np.repeat([20.0, 40.0], 4)
        inc = np.tile(np.radians([15.0, 30.0, 45.0, 60.0]), 2)
        out = predict_outcomes(law, OutcomeScene.from_spec(spec, "template"), params, "exact", speed=speed,
                               incidence=inc)
        rows.append("speed,incidence,rebound_spin")
        rows += [f"{s:g},{np.degrees(a):.4g},{w * 60 / (2 * np.pi):.5g}"
                 for s, a, w in zip(speed, inc, out["rebound_spin"])]
    else:
        t = np.linspace(0.0, 500e-6 if kind == "impact" else 0.5, 11)
        scene = Scene.from_spec(spec, kind, "template", {}, t)
        tr = simulate(law, scene, params, solver="exact", t=t)
        if kind == "impact":
            rows.append("t,omega,theta")
            rows += [f"{a * 1e6:.4g},{w * 60 / (2 * np.pi):.5g},{np.degrees(th):.5g}"
                     for a, w, th in zip(t, tr.omega, tr.theta)]
        else:
            rows.append("t,v")
            rows += [f"{a:.4g},{v:.5g}" for a, v in zip(t, tr.v)]
    return toml, "\n".join(rows) + "\n"
