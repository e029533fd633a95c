"""Starting points for a dataset of one's own: a commented TOML and a CSV that load as they are.

``template(kind, name)`` returns (toml_text, csv_text) for every scene kind (KINDS). The CSV rows
are example numbers computed from a law on the template's scene (the file says which), to be
replaced by the user's data; the TOML explains every field, lists every observable of its kind,
the [noise] kinds (the template's own states kind = "estimated"; its sigma values are commented, for kind =
"known"), and, where they apply, [scene.materials] and [scene.compliance] examples.
"""
from __future__ import annotations

import tomllib

from ..core.errors import DatasetError
from ..core.names import check_name

KINDS = ("impact", "incline", "impact-outcome", "spring-slider")

_HEAD = '''# A frictionlab dataset: this TOML describes the CSV of the same name beside it.
# Check it with  frictionlab datasets show {stem}.toml   fit it with  frictionlab fit {law} {stem}.toml{free}
# and compare laws on it with  frictionlab compare --data {stem}.toml
name = "{name}"            # letters, digits and . _ + - (it becomes part of file names)
kind = "{kind}"{kind_note}
'''

#: The [noise] table, written the same way for every kind (the loader's kinds: known | estimated | none).
_NOISE = '''
[noise]                    # what you know about the noise of the fitted column; a sigma needs its kind:
kind = "estimated"         #   estimated (also what no [noise] table at all means): sigma from the data alone
                           #   (differences of neighbouring points, no law); sigma values here are not used
# kind = "known"           #   known: sigma was measured (repeated runs, the instrument's precision): the values
                           #   below are used as they are, and the chi-square of each fit is tested against them
# kind = "none"            #   noise-free numbers (a reconstruction drawn through stated values)
{noise}
'''

_TAIL = '''
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
# {fixed_example}
# [reported]               # optional: values a publication states, shown beside the fits
# {reported_example}
'''

_MATERIALS = '''
# [scene.materials]        # optional: elastic constants (Mindlin compliance, Maw-Barber-Fawcett Psi1, Psi2)
# ball_young = "70 GPa"
# ball_poisson = 0.3
# surface_young = "200 GPa"
# surface_poisson = 0.3
# friction = 0.2           # a friction coefficient the source states (normalizes Psi1, Psi2 only)

# [scene.compliance]       # optional: tangential compliance of the contact (adds effect "compliance")
# model = "linear"         # linear: stiffness and damping; mindlin: k_t = 8 G* a(t) (shear_modulus or
# stiffness = "2e6 N/m"    # [scene.materials]); mindlin-deresiewicz: microslip (impact outcomes)
# damping = "5 N*s/m"
'''

_BODY = {
    "impact": ('''observable = "omega"       # the fitted column: omega (spin), theta (rotation angle), v (body velocity along
                           # the surface), u (contact slip), A (contact area: needs [scene.area]) or N (needs
                           # [scene.normal]); the other columns are shown beside it
description = "A ball in oblique impact on a rigid target: spin during contact. Say what, where and how."
# time_zero = "0 us"       # only if t does not start at first contact: the file's time of first contact
                           # (subtracted from t); without it, t must start at 0 (a later start is an error)

[columns]                  # every CSV column with its unit; the time column must be called t
t = "us"                   # times from first contact, strictly increasing
omega = "rpm"
theta = "deg"
''', '''# omega = "200 rpm"        # with kind = "known": one standard deviation per column, with its unit
# theta = "0.5 deg"''', '''
[scene]                    # the body and the contact; every dimensional value says its unit
mass = "46 g"
radius = "21.3 mm"
inertia_factor = 0.4       # I = f m r^2 (0.4: solid sphere)
u0 = "12 m/s"              # initial slip of the contact point
effects = ["spin"]         # spin, slip-coupling (u = v - r omega), compliance, gravity

[scene.area]               # contact area A(t): half-sine A0 sin(pi t / t_c), or constant, growth, column
model = "half-sine"
peak = "130 mm^2"
contact_time = "500 us"

[scene.normal]             # normal force N(t), for laws that need it (Coulomb, area-rate): half-sine, hertz,
model = "half-sine"        # column, constant
impulse = "2.0 N*s"
''' + _MATERIALS),
    "incline": ('''observable = "v"           # the fitted column: v (velocity along the incline) or u (slip; equal to v here)
description = "A block sliding from rest down an incline. Say what, where and how."
# time_zero = "0 s"        # only if t does not start at release: the file's time of release (subtracted
                           # from t); without it, t must start at 0 (a later start is an error)

[columns]                  # every CSV column with its unit; the time column must be called t
t = "s"                    # times from release, strictly increasing
v = "m/s"
''', '''# v = "3 mm/s"             # with kind = "known": one standard deviation per column, with its unit''', '''
[scene]
mass = "20 g"
u0 = "0 m/s"               # velocity at t = 0
incline = "20 deg"         # gravity along the incline and N = m g cos(incline) are added for you

[scene.area]               # constant contact area (or model = "growth" with initial and rate: wear)
model = "constant"
area = "100 mm^2"
'''),
    "impact-outcome": ('''observable = "rebound_spin"  # the fitted column, one impact per row: rebound_spin, tangential_cor (contact
                           # point), cm_tangential_cor (centre of mass), normal_cor, rebound_angle,
                           # contact_rebound_angle, psi1 or psi2 (Maw-Barber-Fawcett; need [scene.materials])
description = "Oblique impacts of a ball on a plate, one per row. Say what, where and how."

[columns]                  # inputs speed and incidence, and the measured outcome(s); no time column
speed = "m/s"
incidence = "deg"          # from the surface normal (angle_reference below)
rebound_spin = "rpm"
''', '''# rebound_spin = "100 rpm" # with kind = "known": one standard deviation per column, with its unit''', '''
[scene]
mass = "45.9 g"
radius = "21.35 mm"
inertia_factor = 0.4
effects = ["spin", "slip-coupling"]
angle_reference = "normal"   # incidence measured from the surface normal (or "surface")

[scene.normal]             # a half-sine pulse per impact: contact time and restitution (both may vary with speed)
model = "half-sine"
contact_time = "450 us"
restitution = 0.78

[scene.area]
model = "half-sine"
peak = "150 mm^2"
''' + _MATERIALS),
    "spring-slider": ('''observable = "mu"          # the fitted column: mu, shear stress / effective normal stress (the spring's load)
description = "A velocity-step test: friction of a layer driven through a spring. Say what, where and how."
# time_zero = "0 s"        # only if t does not start with the load-point schedule: the file's time of its
                           # start (subtracted from t); without it, t must start at 0 (a later start is an error)

[columns]                  # every CSV column with its unit; the time column must be called t
t = "s"                    # strictly increasing
mu = ""                    # friction coefficient (no unit)
''', '''# mu = 0.0005             # with kind = "known": one standard deviation per column (no unit for mu)''', '''
[scene]
mass = "1 kg"              # not used by the spring-slider (its inertia is [scene.spring] mass)

[scene.normal]             # the normal load; rate-and-state stiffness is per unit normal stress
model = "constant"
value = "1 kN"

[scene.spring]             # the machine: stiffness k per unit normal stress, and the load-point schedule
stiffness = "0.01 1/um"    # k (fit it with --free spring.stiffness='0.001 1/um:1 1/um')
times = ["0 s", "10 s"]    # load-point velocity steps: from each time on, the velocity beside it
velocities = ["1 um/s", "10 um/s"]
# mass = "1 kg"            # optional slider mass: m dv/dt = N (load - mu); absent or 0: quasi-static
'''),
}

#: kind -> (law, parameters SI, parameter units, fit hint, [fixed] example, [reported] example).
_LAW = {
    "impact": ("wear", {"lam": 1.8e6}, {"lam": "Pa s/m"}, "", 'lam = "1.8e6 Pa s/m"', 'lam = "1.81e6 Pa s/m"'),
    "incline": ("couette", {"eta": 0.1, "h": 4e-5}, {"eta": "Pa s", "h": "m"}, "", 'eta = "0.1 Pa s"',
                'eta = "0.1 Pa s"'),
    "impact-outcome": ("coulomb", {"mu": 0.25}, {"mu": ""}, "", "mu = 0.25", "mu = 0.25"),
    "spring-slider": ("rate-state-aging", {"mu0": 0.6, "a": 0.01, "b": 0.012, "Dc": 2e-5},
                      {"mu0": "", "a": "", "b": "", "Dc": "m"},
                      " --free spring.stiffness='0.001 1/um:1 1/um'", 'mu0 = 0.6', 'Dc = "20 um"'),
}
_KIND_NOTE = {"impact": "            # impact | incline | impact-outcome | spring-slider | contact-area",
              "incline": "           # impact | incline | impact-outcome | spring-slider | contact-area",
              "impact-outcome": "    # one impact per row, no time column",
              "spring-slider": "     # a slider pulled through a spring: velocity steps, slide-hold-slide"}


def template_toml(kind: str, name: str) -> str:
    """The commented TOML of a ``kind`` dataset named ``name``."""
    law, params, units, free, fixed, reported = _LAW[kind]
    body, noise, scene = _BODY[kind]
    method = f"the {law} law with {', '.join(f'{k} = {v:g}' for k, v in params.items())} (SI), no noise"
    truth = "\n".join([f'law = "{law}"'] + [f'{k} = "{v:g} {units[k]}"' if units[k] else f"{k} = {v:g}"
                                            for k, v in params.items()])
    head = _HEAD.format(name=name, stem=name, kind=kind, kind_note=_KIND_NOTE[kind], law=law, free=free)
    tail = _TAIL.format(method=method, command=f"frictionlab datasets template {kind} --name {name}", truth=truth,
                        fixed_example=fixed, reported_example=reported)
    return head + body + _NOISE.format(noise=noise) + scene + tail


def template(kind: str, name: str = "my-data") -> tuple[str, str]:
    """(TOML text, CSV text) of a dataset of ``kind`` named ``name`` that loads as it is."""
    import numpy as np  # here, not at the top: the command line names KINDS in its help without numpy

    if kind not in KINDS:
        raise DatasetError(f"datasets template: kind {kind!r}; expected one of {', '.join(KINDS)}")
    check_name(name, "datasets template: --name", DatasetError)
    toml = template_toml(kind, name)
    law, params = _LAW[kind][:2]
    method = tomllib.loads(toml)["provenance"]["method"]
    spec = tomllib.loads(toml)["scene"]
    rows = [f"# Example rows computed with {method}: replace them with your data (same columns, same units).",
            "# Lines starting with # are comments; the first other line names the columns."]
    if kind == "impact-outcome":
        from ..solve.outcome import OutcomeScene, predict_outcomes

        speed = np.repeat([20.0, 40.0], 4)
        inc = np.tile(np.radians([15.0, 30.0, 45.0, 60.0]), 2)
        out = predict_outcomes(law, OutcomeScene.from_spec(spec, "template"), params, "exact", speed=speed,
                               incidence=inc)
        rows.append("speed,incidence,rebound_spin")
        rows += [f"{s:g},{np.degrees(a):.4g},{w * 60 / (2 * np.pi):.5g}"
                 for s, a, w in zip(speed, inc, out["rebound_spin"])]
        return toml, "\n".join(rows) + "\n"
    from ..physics.scene import Scene
    from ..solve.solvers import simulate

    t = {"impact": np.linspace(0.0, 500e-6, 11), "incline": np.linspace(0.0, 0.5, 11),
         "spring-slider": np.linspace(0.0, 30.0, 61)}[kind]
    scene = Scene.from_spec(spec, kind, "template", {}, t)
    tr = simulate(law, scene, params, solver="ode" if kind == "spring-slider" else "exact", t=t)
    if kind == "impact":
        rows.append("t,omega,theta")
        rows += [f"{a * 1e6:.4g},{w * 60 / (2 * np.pi):.5g},{np.degrees(th):.5g}"
                 for a, w, th in zip(t, tr.omega, tr.theta)]
    elif kind == "incline":
        rows.append("t,v")
        rows += [f"{a:.4g},{v:.5g}" for a, v in zip(t, tr.v)]
    else:
        rows.append("t,mu")
        rows += [f"{a:.4g},{m:.7g}" for a, m in zip(t, tr.load)]
    return toml, "\n".join(rows) + "\n"
