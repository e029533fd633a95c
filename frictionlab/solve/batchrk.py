"""The batch engine's Runge-Kutta path: sliding phases by ``vecrk`` (or the compiled kernel), stuck phases and
breakaway per scene, phase after phase until every scene reaches its last output."""
from __future__ import annotations

import numpy as np

from ..core.errors import SolverError
from . import compiled, vecrk
from .batchcore import finish, plan_of, zero_slip
from .batchstick import breakaway, fill_stuck
from .scenebatch import take_params
from .solvers import stick
from .solvers.segments import MAX_SEGMENTS
from .solvers.ode import state_scales


class _RKRun:
    """The state of one ``run_rk`` over the batch: per scene its phase start (t0, y0), slip direction, which
    outputs are filled (done) and stuck (stuck_mask), and the states on the grid Y."""

    def __init__(self, law, batch, p, T, method, rtol, atol, into):
        self.law, self.batch, self.p, self.T, self.method, self.rtol, self.atol, self.into = (
            law, batch, p, T, method, rtol, atol, into)
        nsc, m = T.shape
        full = plan_of(law, batch.view())
        self.d = d = len(full.states)
        self.t_end = T[:, -1].copy()
        self.scale = np.broadcast_to(state_scales(full, self.t_end), (d, nsc))
        self.Y = None  # states on the output grid; the first sliding phase's own array when every scene slides
        self.done = np.zeros((nsc, m), dtype=bool)
        self.stuck_mask = np.zeros((nsc, m), dtype=bool)
        self.stick_time = np.full(nsc, np.nan)
        self.segments = np.zeros(nsc, dtype=int)
        self.nfev = np.zeros(nsc, dtype=np.int64)
        self.iterations = 0
        self.y0 = np.broadcast_to(full.initial_state().reshape(d, -1), (d, nsc)).copy()
        self.direction = np.sign(np.broadcast_to(full.rigid_slip(self.y0), (nsc,)))
        self.t0 = np.zeros(nsc)
        self.last_dir = np.zeros(nsc)
        self.fast = compiled.prepare(law, full, p, nsc)  # the compiled sliding phases, where they serve this batch

    def stuck(self, stuck_ids):
        """Stuck phases of scenes ``stuck_ids`` up to breakaway (or the end); returns the scenes that break away."""
        law, batch, p, T = self.law, self.batch, self.p, self.T
        t0, y0, t_end = self.t0, self.y0, self.t_end
        nsc, m = T.shape
        self.segments[stuck_ids] += 1
        tb, hold, need = breakaway(law, batch, p, stuck_ids, t0[stuck_ids], y0[:, stuck_ids], t_end[stuck_ids],
                                   self.last_dir[stuck_ids])
        end = np.where(np.isnan(tb), t_end[stuck_ids], tb)
        held = ~(tb == t0[stuck_ids])  # breakaway at once: the sliding phase owns the outputs at t0
        if self.Y is None:
            self.Y = np.full((self.d, nsc, m), np.nan) if self.into is None else self.into["states"]
            self.Y.fill(np.nan)
        if held.any():
            h_ids = stuck_ids[held]
            fill_stuck(law, batch, h_ids, t0[h_ids], y0[:, h_ids], t0[h_ids], end[held], T, self.Y, self.done,
                       self.stuck_mask, fast=self.fast)
        go = ~np.isnan(tb) & (tb < t_end[stuck_ids])
        ids = stuck_ids[go]
        if ids.size:
            plan_s = plan_of(law, batch.view(ids, column=True))
            ys, _ = stick.stuck_states(plan_s, tb[go][:, None], t0[ids][:, None], y0[:, ids][:, :, None])
            y0[:, ids] = ys[:, :, 0]
            t0[ids] = tb[go]
            self.direction[ids] = hold[go]
        return ids

    def slide(self, slide_ids):
        """One sliding phase of scenes ``slide_ids``; returns the scenes that stick before their end."""
        nsc = self.T.shape[0]
        segments, scale, done = self.segments, self.scale, self.done
        segments[slide_ids] += 1
        if np.any(segments > MAX_SEGMENTS):
            i = int(np.argmax(segments > MAX_SEGMENTS))
            raise SolverError(f"batch {self.method}: slip changed between sliding and sticking more than {MAX_SEGMENTS} "
                              f"times in scene {i} (chatter); the law is not suited to this scene")
        first_all = self.Y is None and slide_ids.size == nsc and self.into is not None  # straight into the result
        res = slide_rk(self.law, self.batch, self.p, slide_ids, self.t0, self.y0, self.direction, self.T, self.t_end,
                       scale, self.method, self.rtol, self.atol, self.into["states"] if first_all else None, self.fast)
        self.iterations += res.iterations
        self.nfev[slide_ids] += res.nfev
        new = res.reached & ~done[slide_ids]
        if self.Y is None:  # the first phase and every scene slides: its outputs (NaN where not reached) are Y
            self.Y = res.Y
            if res.scaled:
                self.Y *= scale[:, :, None]
            done |= new
        elif slide_ids.size == nsc:  # every scene slides: no gathering
            np.copyto(self.Y, res.Y * scale[:, :, None] if res.scaled else res.Y, where=new[None])
            done |= new
        else:
            r, c = np.nonzero(new)
            self.Y[:, slide_ids[r], c] = res.Y[:, r, c] * scale[:, slide_ids[r]] if res.scaled else res.Y[:, r, c]
            done[slide_ids[r], c] = True
        ev = np.nonzero(~np.isnan(res.t_event))[0]
        ids = slide_ids[ev]
        ts = res.t_event[ev] * self.t_end[ids]
        first = np.isnan(self.stick_time[ids])
        self.stick_time[ids[first]] = ts[first]
        plan_e = plan_of(self.law, self.batch.view(ids))
        self.y0[:, ids] = zero_slip(plan_e, res.y_event[:, ev] * scale[:, ids])
        self.t0[ids] = ts
        self.last_dir[ids] = self.direction[ids]
        return ids[ts < self.t_end[ids]]


def run_rk(law, batch, p, T, method, rtol, atol, into=None):
    """Every scene phase by phase (sliding by Runge-Kutta, stuck until breakaway) to its last output:
    (outputs as ``finish`` gives them, with stick_time; info)."""
    run = _RKRun(law, batch, p, T, method, rtol, atol, into)
    # scenes starting at zero slip begin stuck (they may break away at once)
    slide_ids = np.nonzero(run.direction != 0)[0]
    stuck_ids = np.nonzero(run.direction == 0)[0]
    while slide_ids.size or stuck_ids.size:
        if stuck_ids.size:
            slide_ids = np.union1d(slide_ids, run.stuck(stuck_ids))
            stuck_ids = np.array([], dtype=int)
        if slide_ids.size == 0:
            break
        stuck_ids = run.slide(slide_ids)
        slide_ids = np.array([], dtype=int)
    if not run.done.all():
        i = int(np.argmax(~run.done.all(axis=1)))
        raise SolverError(f"batch {method}: scene {i} ended before its last requested time")
    need = stick.needed_force(plan_of(law, batch.view(column=True)))
    out = finish(law, batch, p, T, run.Y, ~run.stuck_mask, need, into)
    out["stick_time"] = run.stick_time
    return out, {"nfev": int(run.nfev.sum()), "nfev_per_scene": run.nfev, "iterations": run.iterations,
                 "segments": int(run.segments.max(initial=0)), "method": method,
                 "engine": "numpy" if run.fast is None else "compiled"}


def slide_rk(law, batch, p, ids, t0, y0, direction, T, t_end, scale, method, rtol, atol, out=None, fast=None):
    """One sliding phase for scenes ``ids`` on the scaled problem (time / span, states / scale); with
    ``fast`` (``compiled.prepare``) by the compiled kernel, else by ``vecrk.integrate``: the same steps."""
    span = t_end[ids]
    if fast is not None:
        return fast.integrate(ids, t0, y0, direction, t_end, scale, T, method, rtol, atol, out)
    sc = scale[:, ids]

    def make_rhs(k):
        g_ids = ids[k]
        plan = plan_of(law, batch.view(g_ids))
        pv = take_params(p, g_ids)
        tsc, ssc = span[k], sc[:, k]
        fac = tsc / ssc
        dirs = direction[g_ids]

        def rhs(s, z):
            dy = plan.derivatives(pv, s * tsc, z * ssc, dirs)
            dy *= fac  # a fresh array: scaled in place
            return dy

        return rhs

    def make_event(k):
        g_ids = ids[k]
        plan = plan_of(law, batch.view(g_ids))
        dsc = direction[g_ids] / sc[0, k]

        def g(s, z):
            return plan.rigid_slip(z * sc[:, k]) * dsc

        return g

    return vecrk.integrate(make_rhs, t0[ids] / span, y0[:, ids] / sc, 1.0, scaled_grid(T, ids, span), method=method,
                           rtol=rtol, atol=atol, make_event=make_event, breaks=breaks(batch, ids, span), out=out)


def scaled_grid(T, ids, span):
    """Output times of scenes ids in units of their spans: one (m,) grid when they share it, else (k, m).

    The default grid, m points over each scene's span, is one grid in scaled time: its rows are taken as
    exactly linspace(0, 1, m), row by row (so a scene's outputs do not depend on its batch or chunk)."""
    m = T.shape[1]
    if T.strides[0] == 0 and np.all(span == span[0]):  # one grid and one span for all
        return T[0] / span[0]
    Tid = T if ids.size == T.shape[0] else T[ids]  # ids are sorted: all of them is every row in order
    rel = np.linspace(0.0, 1.0, m)
    on = np.all(Tid == span[:, None] * rel, axis=1)
    if on.all():
        return rel
    s_out = Tid / span[:, None]
    s_out[on] = rel
    return s_out


def breaks(batch, ids, span):
    """End of contact of half-sine area and normal-force models, in units of each scene's span."""
    view = batch.view(ids)
    cols = [np.broadcast_to(np.asarray(m.contact_time, dtype=float), ids.shape) / span
            for m in (view.area, view.normal) if hasattr(m, "contact_time")]
    return np.column_stack(cols) if cols else None
