"""The batch engine's closed forms: the sliding families of ``solvers.exact`` over the whole batch, stick
located per scene by bracketed roots, later phases from breakaway in closed form."""
from __future__ import annotations

import numpy as np

from ..core.errors import SolverError
from .batchcore import finish, plan_of, root, zero_slip
from .batchstick import breakaway
from .scenebatch import take_params
from .solvers import area_slip, exact, stick
from .solvers.segments import MAX_SEGMENTS

SCAN = 1024  # uniform points scanned for the first zero of slip when it is not provably monotone


def run_exact(law, batch, p, T, into=None):
    nsc, m = T.shape
    view = batch.view(column=True)
    plan = plan_of(law, view)
    pc = take_params(p, slice(None), column=True)
    form = law.form(pc)
    d = len(plan.states)
    y0 = np.broadcast_to(plan.initial_state().reshape(d, -1, 1), (d, nsc, 1))
    stick_time = np.full(nsc, np.nan)
    stuck_mask = np.zeros((nsc, m), dtype=bool)
    fallback = np.zeros(nsc, dtype=bool)
    dirs, info = None, {}
    if isinstance(form, exact.AreaSlipForm):
        J, K = area_slip._area_slip(plan, form.k, 0.0, y0, T)
        Y = exact._states(plan, 0.0, y0, T, J, K, out=None if into is None else into["states"])
    else:
        u_s = np.broadcast_to(plan.rigid_slip(y0), (nsc, 1))
        sgn = np.sign(u_s)
        rest = sgn[:, 0] == 0  # at rest at first: a stuck phase from t = 0 (``segments._start``), then as after a stick
        if plan.continuous or "xi" in plan.states:
            fallback |= rest
            rest[:] = False
        sgn = np.where(sgn == 0, 1.0, sgn)
        ts = exact_stop(law, batch, p, None, plan, form, 0.0, y0, u_s[:, 0], sgn[:, 0], T[:, -1])
        hit = ~np.isnan(ts) & ~fallback & ~rest
        segs, tb_first = np.where(hit, 2, 1), np.full(nsc, np.nan)  # phases per scene, first breakaway time [s]
        info = {"segments_per_scene": segs, "breakaway_time": tb_first}
        tcol = np.where(hit, ts, np.inf)[:, None]
        # the sliding closed form at min(t, stick time): frozen at the stick, where the stuck phase continues
        tt = np.minimum(T, tcol) if hit.any() else T
        Y = sliding_states(plan, form, sgn, 0.0, y0, tt, out=None if into is None else into["states"])
        stuck = []  # (scenes, stick time, state there, slip's sign before): each goes on by ``exact_phases``
        if hit.any():
            stick_time[hit] = ts[hit]
            ids = np.nonzero(hit)[0]
            ys = zero_slip(plan_of(law, batch.view(ids)), Y[:, ids, -1])  # the state at the stick, slip exactly zero
            stuck_mask = T > tcol
            v_stick = np.zeros((nsc, 1))
            v_stick[ids, 0] = ys[0]
            np.copyto(Y[0], v_stick, where=stuck_mask)  # zero slip exactly while stuck, as the stick state has it
            stick.stuck_states(plan, T, tt, Y, out=Y)  # dt = 0 before the stick: those states stay
            stuck.append((ids, ts[ids], ys, sgn[ids, 0]))
        still = np.nonzero(rest)[0]
        if still.size:  # stuck from t = 0 in the initial state, slip before it of no sign
            y_rest = np.ascontiguousarray(y0[:, still, 0])
            Y[:, still] = stick.stuck_states(plan_of(law, batch.view(still, column=True)), T[still], 0.0,
                                             y_rest[:, :, None])[0]
            stuck_mask[still] = True
            stuck.append((still, np.zeros(still.size), y_rest, np.zeros(still.size)))
        if stuck:
            ids, ts0, ys, last = (np.concatenate(part, axis=-1) for part in zip(*stuck))
            dirs = exact_phases(law, batch, p, T, Y, stuck_mask, ids, ts0, ys, last, segs, tb_first, stick_time)
            segs[still[tb_first[still] == 0.0]] -= 1  # broke away at once: it slid from the start, no stuck phase
    need = stick.needed_force(plan)
    out = finish(law, batch, p, T, np.nan_to_num(Y, copy=into is None) if fallback.any() else Y, ~stuck_mask, need, into,
                  dirs)
    for i in np.nonzero(fallback)[0]:
        scalar_into(out, stick_time, law, batch, p, T, i, info)
    out["stick_time"] = stick_time
    return out, info | {"nfev": 0, "scalar_fallback": int(fallback.sum())}


def exact_phases(law, batch, p, T, Y, stuck_mask, ids, ts, ys, last_dir, segs, tb_first, stick_time):
    """After the first stick of scenes ``ids`` (at ts [s] in state ys (d, k), slip before of sign last_dir; 0 for
    a scene at rest from the start): breakaway, a sliding phase in closed form from there, perhaps a stick again,
    and so on, as ``solvers.segments.run`` sequences them, with only the scenes still going in each round. A phase
    owns its outputs in (start, end]; they are written into Y and stuck_mask, each scene's number of phases into
    segs, its first breakaway time into tb_first and the first stop of its sliding phases into stick_time where
    that is still NaN. Returns the slip direction of the outputs of the later sliding phases ((n, m), 0
    elsewhere; None if no scene broke away)."""
    dirs = None
    while ids.size:
        t_end = T[ids, -1]
        tb, hold, _ = breakaway(law, batch, p, ids, ts, ys, t_end, last_dir)
        go = ~np.isnan(tb) & (tb < t_end)
        if not go.any():
            break
        at_once = (last_dir[go] == 0) & (tb[go] == ts[go])  # at rest from the start, sliding at once: it owns t = 0
        ids, ts, ys, tb, hold, t_end = ids[go], ts[go], ys[:, go], tb[go], hold[go], t_end[go]
        tb_first[ids] = np.where(np.isnan(tb_first[ids]), tb, tb_first[ids])
        segs[ids] += 2
        if np.any(segs[ids] > MAX_SEGMENTS):
            i = int(ids[np.argmax(segs[ids] > MAX_SEGMENTS)])
            raise SolverError(f"batch exact: slip changed between sliding and sticking more than {MAX_SEGMENTS} "
                              f"times in scene {i} (chatter); the law is not suited to this scene")
        plan = plan_of(law, batch.view(ids, column=True))
        form = law.form(take_params(p, ids, column=True))
        t0, h = tb[:, None], hold[:, None]
        y0 = stick.stuck_states(plan, t0, ts[:, None], ys[:, :, None])[0]  # (d, k, 1): the state at breakaway
        u_s = np.broadcast_to(plan.rigid_slip(y0), (ids.size, 1))[:, 0]
        t_stop = exact_stop(law, batch, p, ids, plan, form, tb, y0, u_s, hold, t_end)
        stops = ~np.isnan(t_stop)
        end = np.where(stops, t_stop, np.inf)[:, None]

        def states(tt):
            return sliding_states(plan, form, h, t0, y0, tt)

        Tr = T[ids]
        Ys = states(np.clip(Tr, t0, end))
        te = np.where(stops, t_stop, tb)[:, None]
        y_stop = zero_slip(plan, states(te))  # the state at the stop, slip exactly zero (d, k, 1)
        after, slide = (Tr > t0) | (at_once[:, None] & (Tr == t0)), Tr <= end
        if stops.any():
            Ys = np.where(slide, Ys, stick.stuck_states(plan, Tr, te, y_stop)[0])
        Y[:, ids] = np.where(after, Ys, Y[:, ids])
        stuck_mask[ids] = np.where(after, ~slide, stuck_mask[ids])
        if dirs is None:
            dirs = np.zeros(T.shape)
        dirs[ids] = np.where(after & slide, h, dirs[ids])
        segs[ids[~stops]] -= 1  # slid to the end: no stuck phase after it
        first = stops & np.isnan(stick_time[ids])
        stick_time[ids[first]] = t_stop[first]
        ids, ts, ys, last_dir = ids[stops], t_stop[stops], y_stop[:, stops, 0], hold[stops]
    return dirs


def sliding_states(plan, form, sgn, t0, y0, tt, out=None):
    """States at times tt (k, q) of sliding phases under F = s (a N + c dA/dt) from t0 in states y0, slip of sign
    sgn (k, 1). The slip's sign goes into the form (no pass over the grid), except on a growth area, where the
    area term c rate u does not carry it."""
    if area_slip.growth_slip(plan, form, sgn, 0.0) is not None:
        J, K, _ = exact._normal_area_rate(plan, form, t0, y0, sgn, tt, find_stop=False)
    else:
        signed = exact.NormalAreaRateForm(a=sgn * form.a, c=sgn * form.c)
        J, K, _ = exact._normal_area_rate(plan, signed, t0, y0, 1.0, tt, find_stop=False)
    return exact._states(plan, t0, y0, tt, J, K, out=out, direction=sgn)


def exact_stop(law, batch, p, ids, plan, form, t0, y0, u_s, sgn, t_end):
    """First time after t0 each scene's slip reaches zero under F = s (a N + c dA/dt), NaN if not before t_end.

    ids: the batch's scenes these rows are (None: all, plan and form theirs); t0: 0.0 (first contact) or
    per row [s], a restart from rest: there, as in ``exact._normal_area_rate``, slip must pass zero by
    SLIP_MARGIN of its scale to count (round-off an ulp after t0 is not a stop), and the stop is the zero
    of slip after the last scanned time at which slip was strictly of the phase's sign."""
    k = t_end.shape[0]
    restart = np.ndim(t0) > 0
    t0c = t0[:, None] if restart else 0.0

    def make_g(rows):  # sgn * slip at times tt (k, q) for rows (None: all)
        sub = plan if rows is None else plan_of(law, batch.view(rows if ids is None else ids[rows], column=True))
        f = form if rows is None else law.form(take_params(p, rows if ids is None else ids[rows], column=True))
        s, us, y0s, t0s = ((sgn[:, None], u_s[:, None], y0, t0c) if rows is None else
                           (sgn[rows, None], u_s[rows, None], y0[:, rows], t0c[rows] if restart else t0c))

        def g(tt):
            J1 = exact._normal_area_rate(sub, f, t0s, y0s, 1.0, tt, find_stop=False)[0]
            return s * (us + sub.drive * (tt - t0s)) - sub.kappa * J1

        return g

    relaxing = area_slip.growth_slip(plan, form, sgn[:, None], u_s[:, None])
    if relaxing is not None:  # in closed form (area_slip.relax_stop), by the scalar solver's rule and margin
        margin = exact.SLIP_MARGIN * np.maximum(_slip_scale(plan, t_end), 1e-300)[:, None]
        ts = area_slip.relax_stop(*relaxing, t0c, t_end[:, None], margin)
        ts = np.broadcast_to(ts, (k, 1))[:, 0]
        return np.where(ts < t_end, ts, np.nan)
    noise = 8 * np.finfo(float).eps * np.abs(u_s)  # slip is u_s minus terms of its size
    c_zero = exact.form_branch(form)[0]
    monotone = not restart and c_zero and (isinstance(batch.template.normal, exact.WeightNormal)
                                           or np.all(sgn * np.broadcast_to(plan.drive, (k, 1))[:, 0] <= 0.0))
    wave = None if restart or monotone else exact._pulse_slip(plan, form, sgn[:, None], u_s[:, None])
    if wave is not None:  # in closed form (exact.pulse_stop): where slip, falling, first reaches zero
        C0, B, S, phi = (np.broadcast_to(x, (k, 1))[:, 0] for x in wave)
        tc = np.broadcast_to(plan.scene.normal.contact_time, (k, 1))[:, 0]
        ts = exact.pulse_stop(C0, B, S, phi, np.minimum(t_end, tc), 0.0)
        return np.where(ts < t_end, ts, np.nan)
    if monotone:
        g_end = make_g(None)(t_end[:, None])[:, 0]
        rows = np.nonzero(g_end <= 0.0)[0]
        lo, hi = np.zeros(rows.size), t_end[rows]
        glo = ghi = None
        offset = np.zeros(k)
    else:
        rows, lo, hi, glo, ghi, offset, noise = _scan_bracket(make_g(None), plan, t0, t0c, t_end, restart, noise)
    ts = np.full(k, np.nan)
    if rows.size and monotone and exact.closed_stop_applies(plan, form, 0.0):
        ts[rows] = np.minimum(np.broadcast_to(exact.half_sine_stop(plan, form, u_s[:, None]), (k, 1))[rows, 0],
                              t_end[rows])
        ts[rows[ts[rows] >= t_end[rows]]] = np.nan
    elif rows.size:
        def make_fn(r):
            g, o = make_g(rows[r]), offset[rows[r]]
            return lambda x: g(x[:, None])[:, 0] + o

        ts[rows] = root(make_fn, lo, hi, 1e-15 * np.maximum(t_end[rows], 1e-300), noise[rows], glo, ghi)
        ts[rows[ts[rows] >= t_end[rows]]] = np.nan
    return ts


def _slip_scale(plan, t_end):
    """Per scene (k,), the slip's scale over a phase ending at t_end (k,) [s]: the largest of the initial slip, the
    drive's and the spin's (``exact._slip_margin`` of one scene)."""
    sc = plan.scene
    k = t_end.shape[0]
    terms = (sc.u0, plan.drive * t_end[:, None], sc.omega0 * (0.0 if sc.radius is None else sc.radius))
    return np.maximum.reduce([np.broadcast_to(np.abs(np.asarray(x, dtype=float)), (k, 1))[:, 0] for x in terms])


def _scan_bracket(g, plan, t0, t0c, t_end, restart, noise):
    """Brackets of the first zero of slip ``g`` (sgn * slip at times (k, q)) from SCAN points over each
    row's phase: (rows with a zero, lo, hi, g at lo and hi, offset of g per scene, noise per scene)."""
    k = t_end.shape[0]
    offset = np.zeros(k)
    frac = np.linspace(0.0, 1.0, SCAN)[None, :]
    grid = t0c + (t_end - t0)[:, None] * frac if restart else t_end[:, None] * frac
    gg = g(grid)
    if restart:
        scale = _slip_scale(plan, t_end)
        margin = exact.SLIP_MARGIN * np.maximum(scale, 1e-300)
        noise = 8 * np.finfo(float).eps * scale
    else:
        margin = np.zeros(k)
    bad = gg[:, 1:] + margin[:, None] <= 0.0
    rows = np.nonzero(bad.any(axis=1))[0]
    ihi = np.argmax(bad[rows], axis=1) + 1
    if restart and rows.size:  # the zero of slip after the last time it was of the phase's sign, if any
        ahead = (gg[rows] > 0.0) & (np.arange(SCAN)[None, :] < ihi[:, None])
        has = ahead.any(axis=1)
        ihi = np.where(has, SCAN - np.argmax(ahead[:, ::-1], axis=1), ihi)
        offset[rows] = np.where(has, 0.0, margin[rows])
    lo, hi = grid[rows, ihi - 1], grid[rows, ihi]
    glo, ghi = gg[rows, ihi - 1] + offset[rows], gg[rows, ihi] + offset[rows]  # fn at the bracket, from the scan
    return rows, lo, hi, glo, ghi, offset, noise


def scalar_into(out, stick_time, law, batch, p, T, i, info):
    """Re-run scene i with the scalar exact solver (it starts at zero slip)."""
    from .solvers import simulate

    pi = {k: v if isinstance(v, float) else float(v[i]) for k, v in p.items()}
    tr = simulate(law, batch.scene(i), pi, solver="exact", t=T[i])
    for k in ("u", "v", "omega", "theta", "force", "A", "N"):
        if out.get(k) is not None and getattr(tr, k) is not None:
            out[k][i] = getattr(tr, k)
    stick_time[i] = np.nan if tr.stick_time is None else tr.stick_time
    if "segments_per_scene" in info:
        info["segments_per_scene"][i] = tr.info["segments"]
