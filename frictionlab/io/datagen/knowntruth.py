"""Known-truth impact datasets for checking the verdicts: ``frictionlab datasets rebuild --known-truth``.

Each dataset is a golf-ball-like impact (the paper's scene: 46 g, r = 21.3 mm, u0 = 12 m/s,
half-sine contact area of 130 mm^2 over 500 us, half-sine normal force from a 24.2 m/s normal
speed and restitution 0.8) simulated with a stated law and parameters, plus Gaussian noise on the
spin from numpy default_rng(seed), 26 samples over the contact. The truth is recorded in each
TOML's [provenance.truth], with the verdicts a correct analysis must reach:

- kt-coulomb-impact: Coulomb, mu = 0.2, noise 1% of the peak spin. Coulomb and wear differ by far
  more than the noise: Coulomb against wear must be "not equivalent", rejecting wear.
- kt-wear-impact: wear, lambda = 1.2e6 Pa s/m; kt-couette-impact: Couette, eta = 0.1 Pa s,
  h = 62.5 nm (eta/h = 1.6e6 Pa s/m). Wear against Couette must be "equivalent" (one form,
  F = k A u); Coulomb against wear "not equivalent", rejecting Coulomb.
- kt-drag-impact: quadratic drag F = c A u |u|, c = 1.5e5 Pa s^2/m^2, a law that is not registered
  (and must stay so): no registered law may describe these data.
- kt-stribeck-incline: a 20 g block sliding from rest down a 30 deg incline (contact area 100 mm^2) with
  Stribeck friction, mu_c = 0.2, mu_s = 0.5, vs = 0.05 m/s, sigma2 = 2 s/m, noise 2 mm/s, 101 samples over
  0.5 s: the velocity rises in an S and levels off, which none of the four laws compared by default (Coulomb,
  area-rate, wear, Couette) can follow: each fails its fit tests, and no pair of them may get a p-value.
- kt-speeds-v20 / kt-speeds-v40: one wear law (lambda = 1.2e6 Pa s/m) at two impact speeds (u0 = 8
  and 16 m/s, A0 = 100 and 180 mm^2, t_c = 520 and 460 us): one lambda must serve both (transfer);
  kt-twolam-v20 / kt-twolam-v40: the same two scenes with lambda = 1.8e6 and 0.9e6 Pa s/m (the
  paper's situation): one lambda must not serve both.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...physics.law import FrictionLaw, ParamSpec
from ...physics.scene import Scene
from ...solve.solvers import simulate
from .write import write_pair

RPM = 2.0 * math.pi / 60.0
MASS, RADIUS, VN, E = 0.046, 0.0213, 24.2, 0.8
N_POINTS = 26
COMMAND = "frictionlab datasets rebuild --known-truth"


class QuadraticDrag(FrictionLaw):
    """F = c A u |u|: a velocity-strengthening drag. Deliberately NOT registered (no @register_law, no entry
    point): the datasets it generates test that the analysis says when no registered law fits."""

    name = "quadratic-drag (unregistered)"
    formula = "F = c A u |u|"
    citation = "known-truth generator, frictionlab/io/datagen/knowntruth.py"
    params = (ParamSpec("c", "Pa s^2/m^2", 1e5, 0.0, 1e9, 1e5, "drag coefficient per unit area"),)
    requires = frozenset({"u", "A"})

    def force(self, p, c):
        return p["c"] * c.A * c.u * np.abs(c.u)


#: name -> (law, parameters SI, scene (u0, A0, t_c), noise as a fraction of the peak spin, seed, truth table)
CASES = {
    "kt-coulomb-impact": ("coulomb", {"mu": 0.2}, (12.0, 130e-6, 500e-6), 0.01, 3101,
                          {"law": "coulomb", "mu": "0.2", "expect": "coulomb vs wear: not equivalent (rejects wear)"}),
    "kt-wear-impact": ("wear", {"lam": 1.2e6}, (12.0, 130e-6, 500e-6), 0.01, 3102,
                       {"law": "wear", "lam": "1.2e6 Pa s/m",
                        "expect": "wear vs couette: equivalent; coulomb vs wear: not equivalent (rejects coulomb)"}),
    "kt-couette-impact": ("couette", {"eta": 0.1, "h": 62.5e-9}, (12.0, 130e-6, 500e-6), 0.01, 3103,
                          {"law": "couette", "eta": "0.1 Pa s", "h": "62.5 nm",
                           "expect": "wear vs couette: equivalent; coulomb vs wear: not equivalent (rejects coulomb)"}),
    "kt-drag-impact": (QuadraticDrag(), {"c": 1.5e5}, (12.0, 130e-6, 500e-6), 0.005, 3104,
                       {"law": "quadratic drag F = c A u |u| (not registered)", "c": "1.5e5 Pa s^2/m^2",
                        "expect": "no registered law describes these data"}),
    "kt-speeds-v20": ("wear", {"lam": 1.2e6}, (8.0, 100e-6, 520e-6), 0.01, 3105,
                      {"law": "wear", "lam": "1.2e6 Pa s/m", "expect": "one lambda serves kt-speeds-v20 and -v40"}),
    "kt-speeds-v40": ("wear", {"lam": 1.2e6}, (16.0, 180e-6, 460e-6), 0.01, 3106,
                      {"law": "wear", "lam": "1.2e6 Pa s/m", "expect": "one lambda serves kt-speeds-v20 and -v40"}),
    "kt-twolam-v20": ("wear", {"lam": 1.8e6}, (8.0, 100e-6, 520e-6), 0.01, 3107,
                      {"law": "wear", "lam": "1.8e6 Pa s/m", "expect": "one lambda does not serve both speeds"}),
    "kt-twolam-v40": ("wear", {"lam": 0.9e6}, (16.0, 180e-6, 460e-6), 0.01, 3108,
                      {"law": "wear", "lam": "0.9e6 Pa s/m", "expect": "one lambda does not serve both speeds"}),
}


#: The incline case: (parameters SI, incline [deg], mass [kg], area [m^2], noise [m/s], samples, duration [s], seed)
STRIBECK = ({"mu_c": 0.2, "mu_s": 0.5, "vs": 0.05, "sigma2": 2.0}, 30.0, 0.020, 100e-6, 0.002, 101, 0.5, 3109)


def scene_spec(u0: float, A0: float, tc: float) -> dict:
    """The [scene] table (quantity strings) of a known-truth impact."""
    return {"mass": f"{MASS * 1e3:g} g", "radius": f"{RADIUS * 1e3:g} mm", "u0": f"{u0:g} m/s", "effects": ["spin"],
            "area": {"model": "half-sine", "peak": f"{A0 * 1e6:g} mm^2", "contact_time": f"{tc * 1e6:g} us"},
            "normal": {"model": "half-sine", "normal_speed": f"{VN:g} m/s", "restitution": E}}


def build(out_dir: Path) -> list[Path]:
    written = []
    for name, (law, params, (u0, A0, tc), rel, seed, truth) in CASES.items():
        spec = scene_spec(u0, A0, tc)
        s = Scene.from_spec(spec, "impact", name)  # the very scene the TOML describes
        t = np.linspace(0.0, tc, N_POINTS)
        solver = "exact" if isinstance(law, str) else "ode:DOP853"
        omega = simulate(law, s, params, solver=solver, t=t, rtol=1e-12).omega / RPM
        sigma = float(f"{rel * np.max(np.abs(omega)):.2g}")  # rpm, two digits
        omega = omega + np.random.default_rng(seed).normal(0.0, sigma, t.size)
        law_name = law if isinstance(law, str) else law.name
        meta = {
            "name": name,
            **({"group": name.rsplit("-", 1)[0]} if name.startswith(("kt-speeds", "kt-twolam")) else {}),
            "kind": "impact",
            "observable": "omega",
            "description": (f"Known-truth impact: golf-ball-like scene, u0 = {u0:g} m/s, A0 = {A0 * 1e6:g} mm^2, "
                            f"t_c = {tc * 1e6:g} us; spin generated with {law_name}. SYNTHETIC, not measured."),
            "columns": {"t": "us", "omega": "rpm"},
            "noise": {"kind": "known", "omega": f"{sigma:g} rpm"},
            "scene": spec,
            "provenance": {
                "kind": "synthetic",
                "source": "known-truth dataset for testing frictionlab's verdicts",
                "method": (f"frictionlab.simulate({law_name!r}, {solver}, rtol 1e-12) on this scene at {N_POINTS} "
                           f"times, plus Gaussian noise of the stated sigma ({rel:.1%} of the peak spin) from numpy "
                           "default_rng(seed); 8 significant digits. See frictionlab/io/datagen/knowntruth.py."),
                "command": COMMAND,
                "seed": seed,
                "truth": {**truth, "noise": f"{sigma:g} rpm"},
            },
        }
        written += write_pair(out_dir, name, meta, {"t": t * 1e6, "omega": omega}, 8, __name__)
    return written + _stribeck_incline(out_dir)


def _stribeck_incline(out_dir: Path) -> list[Path]:
    """kt-stribeck-incline (module docstring)."""
    params, deg, mass, area, sigma, n, t_end, seed = STRIBECK
    spec = {"mass": f"{mass * 1e3:g} g", "u0": "0 m/s", "incline": f"{deg:g} deg",
            "area": {"model": "constant", "area": f"{area * 1e6:g} mm^2"}}
    s = Scene.from_spec(spec, "incline", "kt-stribeck-incline", {}, np.linspace(0.0, t_end, n))
    t = np.linspace(0.0, t_end, n)
    v = simulate("stribeck", s, params, solver="ode:DOP853", t=t, rtol=1e-12).v
    v = v + np.random.default_rng(seed).normal(0.0, sigma, t.size)
    name = "kt-stribeck-incline"
    meta = {
        "name": name,
        "kind": "incline",
        "observable": "v",
        "description": (f"Known-truth incline: a {mass * 1e3:g} g block sliding from rest down a {deg:g} deg incline, "
                        f"contact area {area * 1e6:g} mm^2; velocity generated with Stribeck friction. SYNTHETIC, not "
                        "measured."),
        "columns": {"t": "s", "v": "m/s"},
        "noise": {"kind": "known", "v": f"{sigma * 1e3:g} mm/s"},
        "scene": spec,
        "fixed": {"eta": "0.1 Pa s"},
        "provenance": {
            "kind": "synthetic",
            "source": "known-truth dataset for testing frictionlab's verdicts",
            "method": (f"frictionlab.simulate('stribeck', ode:DOP853, rtol 1e-12) on this scene at {n} times, plus "
                       "Gaussian noise of the stated sigma from numpy default_rng(seed); 8 significant digits. See "
                       "frictionlab/io/datagen/knowntruth.py."),
            "command": COMMAND,
            "seed": seed,
            "truth": {"law": "stribeck", "mu_c": f"{params['mu_c']:g}", "mu_s": f"{params['mu_s']:g}",
                      "vs": f"{params['vs']:g} m/s", "sigma2": f"{params['sigma2']:g} s/m",
                      "noise": f"{sigma * 1e3:g} mm/s",
                      "expect": "coulomb, area-rate, wear and couette each fail their fit tests; no pair of them "
                                "gets a p-value"},
        },
    }
    return write_pair(out_dir, name, meta, {"t": t, "v": v}, 8, __name__)
