"""Where a record is at steady state: the first new steady-state point after each velocity step, from the data.

The idea is the steadystate routine's (Giacomel, Faulkner, Lambert and Allen 2024, Geosphere 20(3)): the slope
S2 = d mu / d x of a straight line fitted to friction over an evaluation slip window of length LS2, moved along
the slip after the step, approaches the steady slope S1 (the background trend) once the transient has decayed;
the first window start where it does is the first new steady-state point, and [point, point + LS2] the window
of the linear detrend. Here, for each sliding piece of the load-point history (between two steps):

* S1 is the piece's own steady slope: the line through its second half but its last EDGE samples (the background
  trend at this velocity, which on a real gouge differs from one velocity to the next; a sample at the piece's
  edge may already show the next step, and one such sample tilts a line);
* the threshold is not the routine's fixed 5e-7 1/um but the scatter the data show: three times the robust
  spread (1.4826 MAD) of S2 over the windows of the piece's second half, so that a record is judged by its own
  noise and wander (a fixed threshold is crossed by chance on a noisy record and never met on a wandering one);
* the point is the first window start from which S2 stays within the threshold of S1 for every window starting
  within the next LS2 of slip (a sustained, not a momentary, return);
* LS2 runs over 50, 100, 200, ... um (from a 16th of the piece's slip on a piece shorter than 800 um) up to an
  eighth of the piece's slip, so that the second half holds at least four windows that do not overlap and its
  spread is measured (the routine's scan of window lengths);
  the point reported is the latest any length finds, with that length: a window that starts late loses a few
  steady samples, one that starts early fits a transient as if it were steady.

A piece where no length finds a sustained return, a hold (V = 0) and a piece of fewer than 32 samples have no
steady state: a window cannot start there, and the steps after it are fitted with the ones before
(simulated through) in one window. Displacement in um, friction dimensionless.
"""
from __future__ import annotations

import attrs
import numpy as np

#: The routine's default shortest evaluation window [um].
MIN_WINDOW = 50.0
#: Multiples of the robust spread of S2 that set the threshold on a wandering record.
SPREAD = 3.0
#: Samples at a piece's end left out of its steady slope.
EDGE = 3
#: A threshold below this [1/um] is friction flat to its last digits: said so, not quoted.
FLAT = 1e-9


@attrs.frozen
class SteadyPoint:
    """The first new steady-state point of one piece: sample ``index`` (None: not reached), the detrend window
    length ``window`` [um], the steady slope S1 and threshold [1/um], the slip from the piece's start [um]."""

    piece: int
    index: int | None
    window: float = float("nan")
    slope: float = float("nan")
    threshold: float = float("nan")
    slip: float = float("nan")
    why: str = ""  # why there is none

    @property
    def found(self) -> bool:
        return self.index is not None


def _slopes(x, mu, starts, length):
    """OLS slopes d mu / d x over [x[s], x[s] + length) for each start s, and each window's end index."""
    X = x - x[0]
    sums = [np.concatenate([[0.0], np.cumsum(v)]) for v in (np.ones_like(X), X, mu, X * X, X * mu)]
    ends = np.searchsorted(x, x[starts] + length)
    n, sx, sy, sxx, sxy = (s[ends] - s[starts] for s in sums)
    sxx_c = sxx - sx * sx / n
    return (sxy - sx * sy / n) / np.where(sxx_c > 0, sxx_c, np.inf), ends


def steady_point(x_um, mu, a: int, e: int, piece: int) -> SteadyPoint:
    """The first new steady-state point of the sliding piece [a, e) (module docstring)."""
    x, y = np.asarray(x_um[a:e], dtype=float), np.asarray(mu[a:e], dtype=float)
    slip = float(x[-1] - x[0]) if x.size else 0.0
    if x.size < 32 or not slip > 0:
        return SteadyPoint(piece, None, why=f"{x.size} samples, {slip:.4g} um of slip: too short for a steady-state "
                                            "window")
    half = x.size // 2
    edge = x.size - EDGE  # the piece's last samples may already show the next step (a kink between two samples)
    s1 = float(np.polyfit(x[half:edge] - x[half], y[half:edge], 1)[0])
    found = []
    length = min(MIN_WINDOW, slip / 16)
    while length <= slip / 8:
        last = int(np.searchsorted(x, x[-1] - length))
        starts = np.arange(0, max(last, 1))
        s2, _ = _slopes(x, y, starts, length)
        tail = s2[starts >= half]
        if tail.size >= 3:
            steady = s1
            spread = 1.4826 * float(np.median(np.abs(tail - np.median(tail))))
            thr = SPREAD * spread
            out = np.abs(s2 - steady) > thr
            # sustained: no window starting within the next `length` of slip is out
            reach = np.searchsorted(x[starts], x[starts] + length)
            bad = np.concatenate([[0], np.cumsum(out)])
            ok = (bad[np.minimum(reach, starts.size)] - bad[starts]) == 0
            if ok.any():
                i = int(np.argmax(ok))
                found.append((float(x[i] - x[0]), length, thr, a + i, steady))
        length *= 2
    if not found:
        return SteadyPoint(piece, None, slope=s1, slip=slip,
                           why="the slope of friction never settles to the piece's own steady slope")
    at, length, thr, index, steady = max(found)
    return SteadyPoint(piece, index, length, steady, thr, at)


def steady_points(x_um, mu, bounds, velocities) -> list[SteadyPoint]:
    """The steady point of every piece of the segmentation (``bounds``: each piece's first sample, then the
    end); a hold (velocity 0) has none."""
    out = []
    for k in range(len(bounds) - 1):
        if velocities[k] == 0:
            out.append(SteadyPoint(k, None, why="a hold (the load point at rest)"))
        else:
            out.append(steady_point(x_um, mu, bounds[k], bounds[k + 1], k))
    return out


def step_windows(points: list[SteadyPoint], bounds) -> list[tuple[int, int, tuple]]:
    """Disjoint per-step windows (first sample, end, steps held), each starting at a steady point: from the steady
    point of a piece to the middle of the steady part of the next piece that has one (the record's end for the
    last), holding every step between them. Steps before the first steady point get no window."""
    anchors = [p for p in points if p.found]
    out = []
    for p, q in zip(anchors, anchors[1:] + [None]):
        start = p.index if not out else out[-1][1]
        if q is None:
            end = bounds[-1]
            steps = tuple(range(p.piece, len(bounds) - 2))
        else:
            end = (q.index + bounds[q.piece + 1]) // 2
            steps = tuple(range(p.piece, q.piece))
        if steps:
            out.append((start, end, steps))
        elif out:  # a last steady piece with no step after it: its samples close the window before it
            out[-1] = (out[-1][0], end, out[-1][2])
    return out


def _at(raw, i: int) -> str:
    return f"{raw.where(i)} (t = {raw.t[i]:.10g} s)"


def start_note(raw, points: list[SteadyPoint], a: int, held: tuple | None) -> str:
    """Where a window starting at sample ``a`` starts and why, and (``held``: its steps; None for the whole
    record) which steps it simulates through."""
    p = max((q for q in points if q.found and q.index <= a), key=lambda q: q.index, default=None)
    if p is None:
        return f"starts at the record's first sample, {_at(raw, a)}: no steady state found before it"
    settles = (f"stays within {p.threshold:.2g} 1/um of its steady slope {p.slope:.2g} 1/um" if p.threshold >= FLAT
               else "stays at its steady slope, friction flat to its last digits")  # no slope of 1e-18 1/um quoted
    test = (f"the first new steady-state point of the piece at {_at(raw, p.index)}, {p.slip:.4g} um into it: friction's "
            f"slope over {p.window:g} um windows {settles} from there on")
    text = f"starts at {_at(raw, a)}, at steady state: " + (test if a == p.index else
                                                            f"in the steady part after {test}")
    if held is not None and len(held) > 1:
        why = "; ".join(f"piece {q.piece + 1}: {q.why}" for q in points[held[0] + 1:held[-1] + 1] if not q.found)
        text += (f"; holds steps {held[0] + 1} to {held[-1] + 1}, simulated through, as the pieces between them show "
                 f"no steady state ({why})")
    return text


def left_out(points: list[SteadyPoint], m: int) -> list[tuple[int, str]]:
    """(step, why) of the ``m`` steps that no per-step window holds: those before the first steady state."""
    first = next((p.piece for p in points if p.found), None)
    if first is None:
        why = "; ".join(f"piece {p.piece + 1}: {p.why}" for p in points)
        return [(i, f"no piece of the record shows a steady state ({why}); fit the record as a whole (--joint)")
                for i in range(m)]
    why = (f"the record shows no steady state before it ({points[0].why}); the whole-record fit (--joint) "
           "simulates it from the record's start")
    return [(i, why) for i in range(first)]
