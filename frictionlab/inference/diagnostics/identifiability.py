"""What the data determine: parameters at bounds, ratio-only pairs, parameters without effect,
strong correlations, and error bars from the identifiable directions when lmfit's are missing or
unreliable. Works on the central-difference Jacobian of the weighted residual at the best fit.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

CORRELATION_LIMIT = 0.95
#: |r| at or beyond which two parameters are one direction of the fit: one of them may take any value in range
SEPARABLE_LIMIT = 0.999


@attrs.frozen
class Identifiability:
    verdict: str
    warnings: tuple[str, ...] = ()
    at_bounds: tuple[str, ...] = ()
    missing_stderr: dict = attrs.field(factory=dict)  # name -> reason
    high_correlations: tuple[tuple[str, str, float], ...] = ()
    ratio_only: tuple[tuple[str, str], ...] = ()
    no_effect: tuple[str, ...] = ()
    bound_sides: dict = attrs.field(factory=dict)  # name in at_bounds -> 'lower' | 'upper'


#: A parameter is at a nonzero bound when within this fraction of the bound's size of it (k = 997,389 1/m
#: against an upper bound of 1e6 1/m is 0.26% away: at the bound).
AT_BOUND_REL = 0.01
#: ... and at a bound of 0 when within this fraction of its typical size (scale): lam = 1655 with scale 1e6
#: is 1.7e-3 scales from 0 and not at the bound; an optimizer pressed against 0 ends far closer.
AT_BOUND = 1e-4
#: What a parameter at its bound means, for every view that shows one.
AT_BOUND_MEANING = ("the best fit presses against the edge of the parameter's allowed range, so its value is the "
                    "bound's, not an estimate the data determine (no error bar, not identifiable); widen the bound "
                    "or hold the parameter")


def bound_side(value: float, lower: float, upper: float, scale: float) -> str:
    """'lower' or 'upper' when ``value`` lies within AT_BOUND_REL of a nonzero bound (relative to the bound)
    or within AT_BOUND scales of a zero bound; '' otherwise."""
    for side, b in (("lower", lower), ("upper", upper)):
        if not math.isfinite(b):
            continue
        room = AT_BOUND_REL * abs(b) if b != 0 else AT_BOUND * abs(scale)
        if abs(value - b) <= room:
            return side
    return ""


@attrs.frozen
class BoundHit:
    """A fitted parameter at a bound of its allowed range (SI)."""

    name: str  # display name
    side: str  # 'lower' | 'upper'
    bound: float
    value: float
    unit: str

    def text(self) -> str:
        """'k = 997,389 1/m is at its upper bound 1e+06 1/m'."""
        from ...core.display import param_text

        return (f"{self.name} = {param_text(self.value, None, self.unit)} is at its {self.side} bound "
                f"{param_text(self.bound, None, self.unit)}")


def at_bounds(fit) -> tuple[BoundHit, ...]:
    """The fitted parameters of ``fit`` (a FitResult) at a bound, with the side and the bound: the one list
    every view reads (report, results.json, ranking.csv, reprs)."""
    ident = getattr(fit, "identifiability", None)
    if ident is None:
        return ()
    out = []
    for name in ident.at_bounds:
        p = fit.params.get(name)
        if p is None:
            continue
        side = ident.bound_sides.get(name) or ("lower" if abs(p.value - p.lower) <= abs(p.value - p.upper) else "upper")
        out.append(BoundHit(name, side, p.lower if side == "lower" else p.upper, p.value, p.unit))
    return tuple(out)


def bounds_text(fit) -> str:
    """'k = 997,389 1/m is at its upper bound 1e+06 1/m (meaning)' for every parameter of ``fit`` at a bound;
    '' when none is."""
    hits = at_bounds(fit)
    if not hits:
        return ""
    return "; ".join(h.text() for h in hits) + f": {AT_BOUND_MEANING}"


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
    sides = {s.display: bound_side(values[s.pname], s.lower, s.upper, s.scale) for s in varying}
    sides = {k: v for k, v in sides.items() if v}
    at_bounds = tuple(sides)
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
    return {"at_bounds": at_bounds, "sides": sides, "ratios": tuple(ratios), "no_effect": no_effect, "k_eff": k_eff,
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
    sides = structure.get("sides", {})
    for name in structure["at_bounds"]:
        p = presults.get(name)
        side = sides.get(name, "")
        bound = (p.lower if side == "lower" else p.upper) if p is not None else math.nan
        where = (f"at its {side} bound ({bound:.6g}{' ' + p.unit if p.unit else ''})" if side and p is not None
                 else "at a bound of its allowed range")
        warn.append(f"{name} is {where}: {AT_BOUND_MEANING}")
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
            warn.append(f"{a} and {b} are correlated (r = {r:+.3f}): " + (
                "the data determine only a combination of them, not each: they are not separately identifiable "
                "from these data (hold one of them, or fit data that separate them)" if abs(r) >= SEPARABLE_LIMIT
                else "the data determine a combination of them better than either"))
    problems = [label for label, flag in (("parameter at a bound", structure["at_bounds"]),
                                          ("ratio-only pair", structure["ratios"]),
                                          ("parameter without effect", structure["no_effect"]),
                                          ("strong correlation", high), ("missing error bars", missing)) if flag]
    verdict = "identifiable" if not problems else "not fully identifiable: " + ", ".join(problems)
    return Identifiability(verdict, tuple(warn), structure["at_bounds"], missing, tuple(high), structure["ratios"],
                           structure["no_effect"], dict(sides))
