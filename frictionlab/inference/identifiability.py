"""What the data determine: parameters at bounds, ratio-only pairs, parameters without effect,
strong correlations, and error bars from the identifiable directions when lmfit's are missing or
unreliable. Works on the central-difference Jacobian of the weighted residual at the best fit.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

CORRELATION_LIMIT = 0.95


@attrs.frozen
class Identifiability:
    verdict: str
    warnings: tuple[str, ...] = ()
    at_bounds: tuple[str, ...] = ()
    missing_stderr: dict = attrs.field(factory=dict)  # name -> reason
    high_correlations: tuple[tuple[str, str, float], ...] = ()
    ratio_only: tuple[tuple[str, str], ...] = ()
    no_effect: tuple[str, ...] = ()


#: A parameter is at a bound when within this fraction of its typical size (scale) of it: lam = 1655 with
#: scale 1e6 is 1.7e-3 scales from 0 and not at the bound; an optimizer pressed against 0 ends far closer.
AT_BOUND = 1e-4

def jacobian(model, slots, values) -> np.ndarray:
    """Central-difference Jacobian of the weighted residual in scaled units of the free parameters."""
    cols = []
    for s in (s for s in slots if s.vary):
        x = values[s.pname] / s.scale
        h = 1e-4 * max(abs(x), 1e-2)
        lo, hi = dict(values), dict(values)
        lo[s.pname] = (x - h) * s.scale
        hi[s.pname] = (x + h) * s.scale
        cols.append((model.residual(hi) - model.residual(lo)) / (2 * h))
    return np.array(cols).T if cols else np.zeros((model.residual(values).size, 0))  # points x free parameters


def find_structure(law, slots, values, J) -> dict:
    """What the data can determine: free parameters at (or running into) a bound, ratio-only pairs
    that are both free, parameters with no effect, and the number of identifiable directions
    (rank of the column-normalized Jacobian)."""
    varying = [s for s in slots if s.vary]
    at_bounds = tuple(s.display for s in varying
                      if any(math.isfinite(b) and abs(values[s.pname] - b) <= AT_BOUND * max(abs(b) * 1e-3, s.scale)
                             for b in (s.lower, s.upper)))
    ratios = []
    for a, b in law.ratio_only:
        for sa in (s for s in varying if s.kind == "law" and s.key == a):
            sb = [s for s in varying if s.kind == "law" and s.key == b and set(s.targets) & set(sa.targets)]
            if sb and (a, b) not in ratios:
                ratios.append((a, b))
    norms = np.linalg.norm(J, axis=0) if J.size else np.zeros(len(varying))
    top = norms.max() if norms.size else 0.0
    effect = norms > 1e-9 * max(top, 1e-300)
    no_effect = tuple(s.display for s, e in zip(varying, effect) if not e)
    k_eff = 0
    if effect.any():
        sv = np.linalg.svd(J[:, effect] / norms[effect], compute_uv=False)
        k_eff = int(np.sum(sv > 1e-6 * sv[0]))
    return {"at_bounds": at_bounds, "ratios": tuple(ratios), "no_effect": no_effect, "k_eff": k_eff,
            "n_free": len(varying)}


def in_ratio(s, structure) -> bool:
    return s.kind == "law" and any(s.key in pair for pair in structure["ratios"])


def jacobian_errors(slots, values, J, structure, redchi) -> dict:
    """Standard errors [SI] from the Jacobian of the identifiable directions, scaled by the reduced
    chi-square as lmfit's are: free parameters that have an effect and are not in a ratio-only pair,
    plus each such pair as its ratio. Returns {"errors": {display: err}, "derived": {label: (value, err,
    unit, slot)}, "correl": {(a, b): r}}."""
    cols, entries = [], []
    for k, s in enumerate(s for s in slots if s.vary):
        if s.display in structure["no_effect"]:
            continue
        if not in_ratio(s, structure):
            cols.append(J[:, k])
            entries.append((s.display, s.scale, None))
            continue
        pair = next(pr for pr in structure["ratios"] if s.key in pr)
        if s.key != pair[0]:
            continue
        b = next(x for x in slots if x.kind == "law" and x.key == pair[1] and set(x.targets) & set(s.targets))
        cols.append(J[:, k] * values[b.pname] / s.scale)  # d res / d(a/b) = J_a b / scale_a
        label = f"{pair[0]}/{pair[1]}" + s.display[len(s.key):]
        unit = f"{s.unit}/{b.unit}" if b.unit else s.unit
        entries.append((label, 1.0, (values[s.pname] / values[b.pname], unit, s)))
    errors, derived = {}, {}
    cov = None
    if cols and np.isfinite(redchi):
        A = np.array(cols).T
        An = A / np.maximum(np.linalg.norm(A, axis=0), 1e-300)
        if np.linalg.matrix_rank(An, tol=1e-8) == A.shape[1]:
            cov = np.linalg.inv(A.T @ A) * redchi
    correl = {}
    for i, (name, conv, extra) in enumerate(entries):
        err = float(np.sqrt(max(cov[i, i], 0.0))) * conv if cov is not None else None
        if extra is None:
            if err is not None:
                errors[name] = err
        else:
            derived[name] = (extra[0], err, extra[1], extra[2])
        if cov is not None:
            for j in range(i + 1, len(entries)):
                denom = math.sqrt(max(cov[i, i] * cov[j, j], 1e-300))
                a, b = sorted((name, entries[j][0]))
                correl[(a, b)] = float(cov[i, j] / denom)
    return {"errors": errors, "derived": derived, "correl": correl}


def make_verdict(structure, presults, correl) -> Identifiability:
    """Warnings a reader can act on, and a one-line verdict."""
    if not structure["n_free"]:
        return Identifiability("nothing fitted: every parameter is held")
    warn, missing = [], {}
    for name in structure["at_bounds"]:
        warn.append(f"{name} is at (or running into) a bound of its allowed range")
        missing[name] = "at a bound, where the error is not defined"
    for a, b in structure["ratios"]:
        warn.append(f"{a} and {b} enter only as {a}/{b}: their separate values mean nothing and get no error "
                    f"bars; fix one (a dataset's [fixed] table) to determine the other; {a}/{b} is reported")
    for name in structure["no_effect"]:
        warn.append(f"{name} has no effect on the prediction near the best fit (a term multiplied by dA/dt = 0, "
                    "or a body stuck throughout)")
    ratio_keys = {k for pair in structure["ratios"] for k in pair}
    for p in presults.values():
        if not p.vary or p.stderr is not None:
            continue
        if p.name in structure["no_effect"]:
            missing.setdefault(p.name, "has no effect on the prediction")
        elif p.kind == "law" and p.key in ratio_keys:
            missing.setdefault(p.name, "enters only through a ratio")
        else:
            missing.setdefault(p.name, "the covariance matrix is singular: parameters not separately determined")
            warn.append(f"{p.name} has no error bar: {missing[p.name]}")
    high = []
    for (a, b), r in correl.items():
        ka, kb = presults[a].key, presults[b].key
        if abs(r) > CORRELATION_LIMIT and not (ka in ratio_keys and kb in ratio_keys):
            high.append((a, b, r))
            warn.append(f"{a} and {b} are correlated (r = {r:+.3f}): the data determine a combination of them "
                        "better than either")
    problems = [label for label, flag in (("parameter at a bound", structure["at_bounds"]),
                                          ("ratio-only pair", structure["ratios"]),
                                          ("parameter without effect", structure["no_effect"]),
                                          ("strong correlation", high), ("missing error bars", missing)) if flag]
    verdict = "identifiable" if not problems else "not fully identifiable: " + ", ".join(problems)
    return Identifiability(verdict, tuple(warn), structure["at_bounds"], missing, tuple(high), structure["ratios"],
                           structure["no_effect"])
