"""Check of the Mindlin history simplification: the same Kharaz impacts with each contact annulus
remembering the tangential displacement at which it entered the contact (Mindlin-Deresiewicz with no
microslip, gross slip capped at mu N), integrated by small explicit steps.

Not used by frictionlab (the plan's 'mindlin' model keeps Thornton's one-state simplification);
it measures what the simplification costs. Run: python tools/mindlin_annuli.py
"""
from __future__ import annotations

import math

import numpy as np

from frictionlab.contact import Material, Pair
from frictionlab.dataset import load_dataset
from frictionlab.outcome import hertz_shape
from frictionlab.rebound import stated_predictions

R, MU, E, V = 2.5e-3, 0.092, 0.98, 3.9
M = 4000.0 * 4.0 / 3.0 * math.pi * R**3
PAIR = Pair(Material(380e9, 0.23), Material(70e9, 0.25))


def impact(incidence_deg: float, annuli: int = 400, steps: int = 20000) -> tuple[float, float]:
    """(rebound spin [rad/s], contact-point rebound angle [deg]) of one impact."""
    inertia = 0.4 * M * R**2
    K = 4.0 / 3.0 * PAIR.modulus * math.sqrt(R)
    vt, vn = V * math.sin(math.radians(incidence_deg)), V * math.cos(math.radians(incidence_deg))
    dmax = (5.0 * M * vn**2 / (4.0 * K)) ** 0.4
    s_end, y, _ = hertz_shape()
    tc = s_end * dmax / vn
    edges = np.linspace(0.0, 1.0001 * math.sqrt(R * dmax), annuli + 1)
    width = np.diff(edges)
    s = np.zeros(annuli)  # elastic tangential displacement carried by each annulus [m]
    v, w, dt = vt, 0.0, tc / steps
    for k in range(steps):
        d = dmax * float(y(np.array([(k + 0.5) * dt * vn / dmax]))[0])
        a, N = math.sqrt(R * d), (1.0 + E) / 2.0 * K * d**1.5
        frac = np.clip((a - edges[:-1]) / width, 0.0, 1.0)
        s[frac == 0] = 0.0  # out of contact: carries nothing, enters again at zero
        s += (v - R * w) * dt * (frac > 0)
        T = 8.0 * PAIR.shear * np.sum(width * frac * s)
        if abs(T) > MU * N:  # gross slip: the whole patch slides, every annulus gives up the same amount
            s -= (T - math.copysign(MU * N, T)) / (8.0 * PAIR.shear * np.sum(width * frac)) * (frac > 0)
            T = math.copysign(MU * N, T)
        v -= T / M * dt
        w += T * R / inertia * dt
    return w, math.degrees(math.atan2(v - R * w, E * vn))


if __name__ == "__main__":
    ds = load_dataset("kharaz2001-spin")
    pred = stated_predictions(ds)
    print("incidence  measured  annuli  (rel)   one-state Mindlin (rel)   [rebound spin, rad/s]")
    for inc, y, m1 in zip(np.degrees(ds.columns["incidence"]), ds.columns["rebound_spin"], pred["mindlin"]):
        if inc < 35:
            w, _ = impact(float(inc))
            print(f"{inc:8.2f}  {y:8.1f}  {w:6.1f} ({w / y - 1:+.1%})  {m1:6.1f} ({m1 / y - 1:+.1%})")
    ca = load_dataset("kharaz2001-contact-angle")
    print("incidence  measured  annuli   [contact-point rebound angle, deg]")
    for inc, y in zip(np.degrees(ca.columns["incidence"]), np.degrees(ca.columns["contact_rebound_angle"])):
        if inc < 35:
            print(f"{inc:8.2f}  {y:8.2f}  {impact(float(inc))[1]:7.2f}")
