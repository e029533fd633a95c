"""Stuck phases of a batch: breakaway times per scene and the stuck states on the output grid."""
from __future__ import annotations

import numpy as np

from ..physics.scene import HalfSineNormal, HertzNormal, WeightNormal
from . import compiled
from .batchcore import plan_of, root
from .scenebatch import take_params
from .solvers import exact, stick

NONNEGATIVE_N = (HalfSineNormal, HertzNormal, WeightNormal)


def breakaway(law, batch, p, ids, ts, ys, t_end, last_dir):
    """Per stuck scene: (breakaway time or NaN, hold direction), as ``solvers.stick.breakaway``."""
    view = batch.view(ids, column=True)
    plan = plan_of(law, view)
    pc = take_params(p, ids, column=True)
    need = np.broadcast_to(stick.needed_force(plan), (ids.size, 1))[:, 0]
    hold = np.where(need != 0, np.sign(need), np.where(last_dir != 0, np.sign(last_dir), 1.0))
    known = known_capacity(law, plan, pc, ids.size, ts, need)
    if known is not None:
        return known, hold, need
    tiny = hold * np.broadcast_to(stick.vanishing_slip(plan), (ids.size, 1))[:, 0]
    y3 = ys[:, :, None]

    def margin(tt):
        f, _ = plan.force(pc, tt, y3, np.broadcast_to(tiny[:, None], tt.shape))
        return hold[:, None] * f - np.abs(need)[:, None]

    frac = np.linspace(0.0, 1.0, stick.GRID)
    grid = ts[:, None] + (t_end - ts)[:, None] * frac[None, :]
    mg = margin(grid)
    bad = mg < 0
    first = np.argmax(bad, axis=1)
    tb = np.full(ids.size, np.nan)
    anyb = bad.any(axis=1)
    tb[anyb & (first == 0)] = ts[anyb & (first == 0)]
    ref = np.nonzero(anyb & (first > 0))[0]
    if ref.size:

        def make_fn(rows):
            r = ref[rows]
            plan_r = plan_of(law, batch.view(ids[r], column=True))
            p_r = take_params(p, ids[r], column=True)

            def fn(tt):
                f, _ = plan_r.force(p_r, tt[:, None], ys[:, r, None], tiny[r, None])
                return hold[r] * f[:, 0] - np.abs(need[r])

            return fn

        lo = grid[ref, first[ref] - 1]
        hi = grid[ref, first[ref]]
        tb[ref] = root(make_fn, lo, hi, 1e-15 * np.maximum(t_end[ref], 1e-300), 0.0, mg[ref, first[ref] - 1],
                        mg[ref, first[ref]])
    return tb, hold, need


def fill_stuck(law, batch, ids, ts, ys, t_from, t_to, T, Y, done, stuck_mask, block=256, fast=None):
    """Stuck-phase states (``solvers.stick.stuck_states``) at outputs in [t_from, t_to] not yet filled; per
    scene on its whole grid row, ``block`` scenes at a time (working memory bounded, not per output point;
    256 scenes of 101 outputs cost a third less per scene than 2,048, their arrays staying in cache). With
    ``fast`` (numba there) the selection and writing are one compiled pass (``compiled.scatter_stuck``)."""
    assert all(y.flags.c_contiguous for y in Y) and done.flags.c_contiguous  # written through flat views
    m = T.shape[1]
    for b in range(0, ids.size, block):
        bi = slice(b, b + block)
        rows = ids[bi]
        Ts = T[rows]
        if fast is not None:
            plan = plan_of(law, batch.view(rows, column=True))
            Ys, _ = stick.stuck_states(plan, Ts, ts[bi, None], ys[:, bi, None])
            compiled.scatter_stuck(Ys, rows, Ts, t_from[bi], t_to[bi], done, stuck_mask, Y)
            continue
        sel = (Ts >= t_from[bi, None]) & (Ts <= t_to[bi, None]) & ~done[rows]
        r, c = np.nonzero(sel)
        if r.size == 0:
            continue
        plan = plan_of(law, batch.view(rows, column=True))  # per scene, broadcast along its times
        Ys, _ = stick.stuck_states(plan, Ts, ts[bi, None], ys[:, bi, None])
        flat = rows[r] * m + c
        src = r * m + c
        for j in range(Y.shape[0]):  # integer take and put per state: several times faster than 2-d fancy indexing
            np.put(Y[j], flat, np.take(Ys[j], src))
        done.reshape(-1)[flat] = True
        stuck_mask.reshape(-1)[flat] = True


def known_capacity(law, plan, pc, k, ts, need):
    """Breakaway times without a scan, when the law's form makes them obvious, else None.

    Under F = s (a N + c dA/dt) the holding capacity is a N + c dA/dt. With c = 0, a >= 0 and a
    normal-force model that is never negative, the capacity a N >= 0 holds a scene that needs no
    force (no drive: the rolling sphere) for ever, and a constant N needs one comparison.
    """
    form = law.form(pc)
    if not isinstance(form, exact.NormalAreaRateForm) or not isinstance(plan.scene.normal, NONNEGATIVE_N):
        return None
    if not (np.all(np.asarray(form.c) == 0.0) and np.all(np.asarray(form.a) >= 0.0)):
        return None
    if np.all(need == 0.0):
        return np.full(k, np.nan)
    if isinstance(plan.scene.normal, WeightNormal):
        cap = np.broadcast_to(form.a * plan.scene.normal.value, (k, 1))[:, 0]
        return np.where(cap < np.abs(need), ts, np.nan)
    return None
