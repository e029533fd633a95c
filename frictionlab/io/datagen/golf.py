"""Golf-ball impact series reconstructed from the numbers Arakawa (Sci. Rep. 2017) states.

The paper publishes no table of its camera data, only stated values. For each inbound speed
the spin series is rebuilt so that it agrees with every stated number:

  omega(0) = 0 (first contact), omega(t_p) = omega_p with omega'(t_p) = 0 (the stated peak),
  omega(t_c) = omega_c (the stated value just before rebound), and the integral of omega
  over the contact equals the largest stated rotation angle theta_max.

Procedure: a shape-preserving monotone cubic (scipy PchipInterpolator) through the knots
(0, 0), (t_p / 2, f omega_p), (t_p, omega_p), (t_c, omega_c), with the one free value f found
by root finding (brentq) so that the integral matches theta_max. PCHIP keeps the curve
monotone between knots, so the peak is the stated one. Sampled at the camera's 10 us framing
interval from first contact to t_c; theta is the exact integral of the same curve.

The contact-area series at 32 m/s is eq (1) of the paper, A0 sin(pi t / t_c), with A0 = 150 mm^2
and t_c = 440 us (the stated peak time 220 us is t_c / 2 for eq (1)), at the same 10 us interval.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy.interpolate import PchipInterpolator
from scipy.optimize import brentq

from .write import write_pair

RPM = 2.0 * math.pi / 60.0
SOURCE = ("K. Arakawa, 'An analytical model of dynamic sliding friction during impact', Sci. Rep. 7 (2017); "
          "stated values in the text and figure captions of Figs 2-3")
FRAME = 10e-6  # camera framing interval [s]

#: What the paper states for each inbound speed (SI).
STATED = {
    28: dict(t_peak=260e-6, omega_peak=6700 * RPM, t_c=500e-6, omega_c=4300 * RPM, theta_max=math.radians(13),
             u0=12.0, A0=130e-6, lam=1.81e6, b=0.81),
    61: dict(t_peak=240e-6, omega_peak=15400 * RPM, t_c=460e-6, omega_c=9800 * RPM, theta_max=math.radians(26),
             u0=27.0, A0=270e-6, lam=0.96e6, b=0.83),
}
#: Assumed (not stated in the paper): restitution of a golf ball for the half-sine normal-force
#: model, falling with speed as the paper's ref 4 describes.
RESTITUTION = {28: 0.80, 61: 0.70}
#: Precision of each stated number: one unit of its last significant digit (6,700 rpm: 100 rpm;
#: 13 deg: 1 deg), the camera's framing interval for a time. The series has no noise ([noise] kind
#: = 'none'): laws are compared on these numbers ([stated]), the curve is drawn for figures.
PRECISION = dict(omega_peak=100 * RPM, t_peak=FRAME, omega_c=100 * RPM, theta_max=math.radians(1))


def stated_table(s: dict) -> dict:
    """The [stated] table of a golf dataset: [value, precision] of each stated number, in rpm, us, deg."""
    rpm = lambda x: f"{x / RPM:.0f} rpm"  # noqa: E731
    return {"omega_peak": [rpm(s["omega_peak"]), rpm(PRECISION["omega_peak"])],
            "t_peak": [f"{s['t_peak'] * 1e6:g} us", f"{PRECISION['t_peak'] * 1e6:g} us"],
            "omega_end": [rpm(s["omega_c"]), rpm(PRECISION["omega_c"])],
            "theta_max": [f"{math.degrees(s['theta_max']):g} deg", f"{math.degrees(PRECISION['theta_max']):g} deg"]}


def spin_curve(s: dict) -> PchipInterpolator:
    """The reconstructed omega(t) [rad/s] for stated values ``s`` (see module docstring)."""
    def make(f):
        return PchipInterpolator([0.0, s["t_peak"] / 2, s["t_peak"], s["t_c"]],
                                 [0.0, f * s["omega_peak"], s["omega_peak"], s["omega_c"]])

    f = brentq(lambda f: make(f).integrate(0.0, s["t_c"]) - s["theta_max"], 1e-3, 1.0 - 1e-3, xtol=1e-14)
    return make(f)


def build(out_dir: Path) -> list[Path]:
    written = []
    for speed, s in STATED.items():
        curve = spin_curve(s)
        t = np.arange(0, round(s["t_c"] / FRAME) + 1) * FRAME
        cols = {"t": t * 1e6, "omega": curve(t) / RPM, "theta": np.degrees(curve.antiderivative()(t))}
        written += write_pair(out_dir, f"impact-golf-v{speed}", _golf_meta(speed, s), cols, 8, __name__)
    return written + _area_pair(out_dir)


def _golf_meta(speed: int, s: dict) -> dict:
    """The TOML of the golf reconstruction at ``speed`` m/s from its stated values ``s``."""
    vn = speed * math.cos(math.radians(30))
    return {
        "name": f"impact-golf-v{speed}",
        "group": "impact-golf",  # one ball and target at two speeds
        "kind": "impact",
        "observable": "theta",
        "description": (f"Golf ball (46 g, 42.6 mm) in oblique impact on a rigid steel target inclined 30 deg, "
                        f"inbound {speed} m/s: spin and rotation angle during contact, at the 10 us framing "
                        "interval. A reconstruction that agrees with every number the paper states; "
                        "not the camera measurements themselves."),
        "columns": {"t": "us", "omega": "rpm", "theta": "deg"},
        "noise": {"kind": "none"},
        "stated": stated_table(s),
        "scene": {
            "mass": "46 g", "radius": "21.3 mm", "inertia_factor": 0.4,
            "u0": f"{s['u0']:g} m/s",
            "effects": ["spin"],
            "area": {"model": "half-sine", "peak": f"{s['A0'] * 1e6:g} mm^2", "contact_time": f"{s['t_c'] * 1e6:g} us"},
            "normal": {"model": "half-sine", "normal_speed": f"{vn:.4f} m/s", "restitution": RESTITUTION[speed]},
        },
        "provenance": {
            "kind": "reconstructed",
            "source": SOURCE,
            "method": ("PCHIP through (0,0), (t_p/2, f*omega_p), (t_p, omega_p), (t_c, omega_c); f solved so that "
                       "the integral of omega over the contact equals the stated largest rotation angle; "
                       "theta is that integral. Noise-free: laws are compared on the stated numbers at their "
                       "stated precision ([stated]). The restitution of the normal-force model is an "
                       "assumption, not stated in the paper. See frictionlab/io/datagen/golf.py."),
            "command": "frictionlab datasets rebuild",
        },
        "reported": {
            "impact_speed": f"{speed} m/s", "incidence": "30 deg",
            "omega_peak": f"{s['omega_peak'] / RPM:g} rpm", "t_peak": f"{s['t_peak'] * 1e6:g} us",
            "omega_at_contact_end": f"{s['omega_c'] / RPM:g} rpm", "contact_time": f"{s['t_c'] * 1e6:g} us",
            "theta_max": f"{math.degrees(s['theta_max']):g} deg", "u0": f"{s['u0']:g} m/s",
            "A0": f"{s['A0'] * 1e6:g} mm^2", "lam": f"{s['lam']:g} Pa s/m", "b": s["b"],
        },
    }


def _area_pair(out_dir: Path) -> list[Path]:
    """The contact-area series at 32 m/s (eq (1) of the paper): a supporting series, not fitted."""
    t_c = 440e-6
    t = np.arange(0, round(t_c / FRAME) + 1) * FRAME
    A = 150e-6 * np.sin(math.pi * t / t_c)
    meta = {
        "name": "impact-area-v32",
        "kind": "contact-area",
        "observable": "A",
        "description": ("Contact area of a golf ball on a transparent PMMA target at 32 m/s, as eq (1) of the paper "
                        "describes it; a supporting series (scenes may use it as a measured-area column), not fitted."),
        "columns": {"t": "us", "A": "mm^2"},
        "noise": {"kind": "none"},
        "provenance": {
            "kind": "reconstructed",
            "source": SOURCE + "; Fig. 2a: peak 150 mm^2 at 220 us",
            "method": ("eq (1), A = A0 sin(pi t / t_c) with A0 = 150 mm^2 and t_c = 2 x 220 us = 440 us, sampled "
                       "every 10 us; the measured points of Fig. 2a are not published as numbers. Noise-free."),
            "command": "frictionlab datasets rebuild",
        },
        "reported": {"A_peak": "150 mm^2", "t_peak": "220 us", "impact_speed": "32 m/s"},
    }
    return write_pair(out_dir, meta["name"], meta, {"t": t * 1e6, "A": A * 1e6}, 8, __name__)
