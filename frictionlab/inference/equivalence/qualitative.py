"""The paper's word, "qualitatively": do two laws' fitted curves share the features the data show?

Features of a curve y(t) over the record (spin omega for an impact, velocity v on an incline), read
on a fixed grid of GRID points over [0, t_end] (t_end the contact time of an impact, else the last
sample), with a tolerance ``tol`` in the observable's unit (the noise or stated precision):

* rises: y climbs from its start by more than tol;
* peak: the maximum lies inside the record (at least tol above the end value), and its time;
* falls: y ends more than tol below its maximum (a fall before t_c);
* force keeps its sign: the friction force does not reverse through the contact (on a grid of the
  trajectory, ignoring values below 1e-6 of its largest magnitude).

Two laws are **qualitatively equivalent** on a dataset when their fitted curves agree on every feature;
the first differing feature is named. Where both curves peak inside the record, their peak times are
compared apart, as a **quantitative** difference under its own name: they differ when they lie more than
``dt``, the sampling interval of the data (the camera's 10 us framing for the golf reconstructions), apart.
A timing tolerance is a number, not a feature: two curves that both rise, peak and fall are qualitatively
alike however far apart their peaks are. The data's own features come from the
stated numbers of a reconstruction (peak, its time, the end value) or, for a series with noise, from
the data with a tolerance of (sqrt(2 ln n) + 3) sigma, beyond what the largest of n noise draws reaches
(the force is not observed: not compared with the data).
"""
from __future__ import annotations

import math

import attrs
import numpy as np

GRID = 401
OBSERVABLE = {"impact": "omega", "incline": "v"}


@attrs.frozen
class Features:
    rises: bool
    peak: bool
    t_peak: float  # [s]; nan without an inner peak
    falls: bool
    force_one_sign: bool | None  # None: not observed (data)

    def as_dict(self) -> dict:
        return attrs.asdict(self)


def features_of(t: np.ndarray, y: np.ndarray, tol: float, force: np.ndarray | None = None) -> Features:
    """The features of the curve y(t) with tolerance tol (module docstring)."""
    i = int(np.argmax(y))
    top = float(y[i])
    peak = top - float(y[-1]) > tol and 0 < i < y.size - 1
    one_sign = None
    if force is not None:
        big = np.abs(force) > 1e-6 * max(float(np.max(np.abs(force))), 1e-300)
        one_sign = bool(np.all(force[big] > 0) or np.all(force[big] < 0))
    return Features(rises=top - float(y[0]) > tol, peak=bool(peak), t_peak=float(t[i]) if peak else math.nan,
                    falls=top - float(y[-1]) > tol, force_one_sign=one_sign)


def fit_features(fit, tol: float) -> Features | None:
    """Features of a fit's best curve (None for a dataset without a time series)."""
    d = fit.per_dataset[0]
    obs = OBSERVABLE.get(d.target.dataset.kind)
    if obs is None or d.target.t is None:
        return None
    t_end = d.scene.area.contact_time if d.target.dataset.kind == "impact" else float(d.target.t[-1])
    tr = d.trajectory(fit.law, np.linspace(0.0, t_end, GRID))
    return features_of(tr.t, tr[obs], tol, tr.force)


def data_features(dataset) -> tuple[Features, float] | None:
    """(features the data show, tolerance) from stated numbers or from the noisy series; None if neither."""
    st = dataset.stated
    if {"omega_peak", "t_peak", "omega_end"} <= set(st):
        (wp, pp), (tp, _), (we, pe) = st["omega_peak"], st["t_peak"], st["omega_end"]
        tol = max(pp, pe)
        return Features(rises=wp > tol, peak=wp - we > tol, t_peak=tp, falls=wp - we > tol, force_one_sign=None), tol
    obs = OBSERVABLE.get(dataset.kind)
    if obs is None or obs not in dataset.columns or "t" not in dataset.columns or dataset.noise_kind == "none":
        return None
    y = dataset.columns[obs]
    tol = (math.sqrt(2 * math.log(y.size)) + 3.0) * dataset.noise[obs]  # beyond the largest of n noise draws
    return features_of(dataset.t, y, tol), tol


def text(q: dict, a: str, b: str) -> str:
    """One sentence: 'qualitatively different: a peak inside the record (...); the data: ...', and the peak times'
    quantitative difference beside it where there is one."""
    if q["verdict"] == "not applicable":
        return ""
    head = q["verdict"] + (f" ({q['differs']})" if q["differs"] else "")
    misses = [f"{law} misses {what}" for law, what in q["data_differs"].items() if what]
    out = head + ("; against the data: " + "; ".join(misses) if misses else
                  "; both share the data's features" if q["data_differs"] else "")
    peak = q.get("peak_time") or {}
    if peak.get("differs"):
        out += f"; quantitatively, {peak_text(peak, a, b)}"
    return out


def peak_text(peak: dict, a: str, b: str) -> str:
    """'the peak times differ: 290 µs (a) vs 323 µs (b), 33 µs apart, more than the 10 µs sampling interval'."""
    return (f"the peak times differ: {peak['a'] * 1e6:.0f} µs ({a}) vs {peak['b'] * 1e6:.0f} µs ({b}), "
            f"{peak['shift'] * 1e6:.0f} µs apart, more than the {peak['dt'] * 1e6:.0f} µs sampling interval")


def qualitative(fit_a, fit_b) -> dict:
    """{'verdict': 'qualitatively equivalent' | 'qualitatively different', 'differs': the first feature in
    which the two curves differ ('' if none), 'data_differs': {law: the first feature in which its curve
    misses the data's}, 'peak_time': the two curves' peak times and whether they differ by more than the
    sampling interval (a quantitative difference: {} unless both peak inside the record), 'features': {law:
    Features as dict, 'data': ...}, 'dt': the sampling interval}."""
    ds = fit_a.per_dataset[0].target.dataset
    data = data_features(ds)
    tol = data[1] if data else 0.0
    fa, fb = fit_features(fit_a, tol), fit_features(fit_b, tol)
    if fa is None or fb is None:
        return {"verdict": "not applicable", "differs": "", "data_differs": {}, "features": {}, "dt": math.nan,
                "peak_time": {}}
    t = ds.columns.get("t")
    dt = float(np.min(np.diff(t))) if t is not None and t.size > 1 else 0.0
    differs = _first_difference(fa, fb)
    data_differs = {f.law: _first_difference(data[0], ff) for f, ff in ((fit_a, fa), (fit_b, fb))} if data else {}
    peak = {}
    if fa.peak and fb.peak:
        shift = abs(fa.t_peak - fb.t_peak)
        peak = {"a": fa.t_peak, "b": fb.t_peak, "shift": shift, "dt": dt, "differs": bool(shift > dt)}
    return {"verdict": "qualitatively different" if differs else "qualitatively equivalent", "differs": differs,
            "data_differs": data_differs, "dt": dt, "peak_time": peak,
            "features": {fit_a.law: fa.as_dict(), fit_b.law: fb.as_dict(), **({"data": data[0].as_dict()} if data else {})}}


#: The features compared, in order, and how a difference is named.
FEATURES = {"rises": "a monotone rise", "peak": "a peak inside the record", "falls": "a fall before the end"}


def _first_difference(a: Features, b: Features) -> str:
    """The first feature in which b differs from a ('' if none); a's force sign None is not compared. Peak
    times are not a feature (``qualitative``: a quantitative difference)."""
    for key, text in FEATURES.items():
        if getattr(a, key) != getattr(b, key):
            return f"{text} ({'one has it, the other not'})"
    if a.force_one_sign is not None and b.force_one_sign is not None and a.force_one_sign != b.force_one_sign:
        return "the sign of the friction force (one reverses through the contact, the other does not)"
    return ""
