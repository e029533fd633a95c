"""The numba kernel of ``frictionlab.solve.compiled`` (imported only when a batch uses it; needs numba).

Module-level functions, so numba's on-disk cache (``cache=True``) serves later processes. The
right-hand side ``_rhs`` is the built-in forms' derivatives (see ``frictionlab.solve.compiled``).
"""
import math

import numba
import numpy as np

from .compiled_codes import (
    A_OR_K,
    AREA_CONST,
    AREA_PEAK,
    AREA_PHI,
    AREA_TC,
    BREAK_AREA,
    BREAK_NORMAL,
    CONSTANT,
    DRIVE,
    FORM_NAR,
    HALF_SINE,
    INERTIA,
    MASS,
    NORMAL_CONST,
    NORMAL_PEAK,
    NORMAL_PHI,
    NORMAL_TC,
    NOT_FINITE,
    RADIUS,
    TOO_MANY,
    UNDERFLOW,
    VANISH,
    C,
)
from .vecrk import BISECTIONS

jit = numba.njit(cache=True, fastmath=False, error_model="numpy")
#: The small helpers are inlined into the kernel by numba (they run in its innermost loops); the right-hand side,
#: large and called from five places, is compiled once and left to LLVM (numba inlining it five times made the
#: kernel's first compilation cost 20 CPU s instead of 13, for no gain at run time).
inline = numba.njit(cache=True, fastmath=False, error_model="numpy", inline="always")


@jit
def _rhs(s, z0, z1, sp, cd, tsc, fac0, fac1, fac2, ssc0, ssc1, direction):
    """THE BUILT-IN FORMS' DERIVATIVES, scaled, for one scene, as ``Plan.derivatives`` computes them
    (tests/test_compiled.py checks them against it): slip u = v, or v - r omega with slip coupling, held
    on the phase's side (``stick.branch_slip``); F = sign(u) (a N + c dA/dt) or k A u from the half-sine
    or constant models (zero outside the contact); dv/dt = drive - F/m, domega/dt = F r / I,
    dtheta/dt = omega; each times span / scale. Returns the three rates and whether F is finite."""
    mass, r, inertia, drive, vanish, a, c, pa, phia, tca, ca, pn, phin, tcn, cn = sp
    form, area, normal, coupled, spin, dadt = cd
    t = s * tsc
    v = z0 * ssc0
    omega = z1 * ssc1 if spin else 0.0
    u = v - r * omega if coupled else v
    if not direction * u > 0:
        u = direction * vanish
    A = 0.0
    dA = 0.0
    if area == HALF_SINE:
        if t >= 0 and t <= tca:
            A = pa * math.sin(phia * t)
            if dadt:
                dA = pa * phia * math.cos(phia * t)
    elif area == CONSTANT:
        A = ca
    if form == FORM_NAR:
        N = 0.0
        if normal == HALF_SINE:
            if t >= 0 and t <= tcn:
                N = pn * math.sin(phin * t)
        elif normal == CONSTANT:
            N = cn
        q = a * N
        if dadt:
            q = q + c * dA
        F = q * direction  # sign(u) is the direction: u is held on the phase's side
    else:
        F = a * A * u
    f0 = (drive - F / mass) * fac0
    f1 = (F * r / inertia) * fac1 if spin else 0.0
    f2 = omega * fac2 if spin else 0.0
    return f0, f1, f2, math.isfinite(F)

@inline
def _constants(cols, g):
    return (cols[g, MASS], cols[g, RADIUS], cols[g, INERTIA], cols[g, DRIVE], cols[g, VANISH], cols[g, A_OR_K],
            cols[g, C], cols[g, AREA_PEAK], cols[g, AREA_PHI], cols[g, AREA_TC], cols[g, AREA_CONST],
            cols[g, NORMAL_PEAK], cols[g, NORMAL_PHI], cols[g, NORMAL_TC], cols[g, NORMAL_CONST])

@inline
def _comb(coef, K, nterm):
    """sum_j coef[j] K[j] over the nonzero coefficients, added in order (as ``vecdense.vec_dot``)."""
    a0 = a1 = a2 = 0.0
    first = True
    for j in range(nterm):
        c = coef[j]
        if c == 0.0:
            continue
        if first:
            a0, a1, a2 = K[j, 0] * c, K[j, 1] * c, K[j, 2] * c
            first = False
        else:
            a0 += K[j, 0] * c
            a1 += K[j, 1] * c
            a2 += K[j, 2] * c
    return a0, a1, a2

@inline
def _dense(Fc, nc, dop, x, h, y0, y1, y2):
    """The step's dense output at fraction x (``vecdense.Dense``: DOP853's nested x, 1 - x products, or
    RK45's polynomial times h)."""
    a0, a1, a2 = Fc[nc - 1, 0] * x, Fc[nc - 1, 1] * x, Fc[nc - 1, 2] * x
    if dop:
        om = 1.0 - x
        odd = True
        for j in range(nc - 2, -1, -1):
            w = om if odd else x
            a0 = (a0 + Fc[j, 0]) * w
            a1 = (a1 + Fc[j, 1]) * w
            a2 = (a2 + Fc[j, 2]) * w
            odd = not odd
    else:
        for j in range(nc - 2, -1, -1):
            a0 = (a0 + Fc[j, 0]) * x
            a1 = (a1 + Fc[j, 1]) * x
            a2 = (a2 + Fc[j, 2]) * x
        a0 *= h
        a1 *= h
        a2 *= h
    return a0 + y0, a1 + y1, a2 + y2

@inline
def _slip(z0, z1, ssc0, ssc1, r, coupled, dsc):
    """The event: slip (v - r omega with slip coupling) over its scale, times the phase's direction."""
    v = z0 * ssc0
    return ((v - r * (z1 * ssc1)) if coupled else v) * dsc

@numba.njit(cache=True, fastmath=False, error_model="numpy")
def kernel(A, B, Cn, E, AX, CX, D, order, exponent, dop, codes, cols, ids, t0a, y0a, dira, spana, scalea, grid,
           per_row, rel, rtol, atol, max_iter, Y0, Y1, Y2, reached, t_event, y_event, nfev, stat):
    """Each scene ids[i] from t0a[g] in state y0a[:, g] to the end of its span or its zero of slip, as
    ``vecrk.integrate`` steps it; outputs into row i of Y0, Y1, Y2 (the states' (k, m) output arrays; NaN
    where not reached; in the states' units, not scaled), reached[i], the event
    into t_event[i], y_event[:, i], evaluations into nfev[i]; a failure into stat. Returns the most
    step attempts of a scene. Output times: grid[0] (scaled) for every scene, or with per_row each scene's
    row of grid (times [s], the chunk's rows), taken as exactly ``rel`` where it is span * rel (as
    ``batchrk.scaled_grid`` takes them), else divided by the span."""
    d = y0a.shape[0]
    k = ids.size
    m = grid.shape[1]
    ns = B.size
    nx = CX.size
    nk = ns + 1 + nx
    nd = D.shape[0]
    nc = nd + 3 if dop else nd
    K = np.zeros((nk, 3))
    gr = np.empty(m)
    Fc = np.zeros((nc, 3))
    eps = 2.220446049250313e-16
    eps4 = 1 + 4 * eps
    cd = (codes[0], codes[1], codes[2], codes[3], codes[4], codes[5])
    coupled = codes[3]
    iters_max = 0
    for i in range(k):
        g = ids[i]
        sp = _constants(cols, g)
        tsc = spana[g]
        ssc0 = scalea[0, g]
        ssc1 = scalea[1, g] if d > 1 else 1.0
        fac0 = tsc / ssc0
        fac1 = tsc / ssc1 if d > 1 else 0.0
        ssc2 = scalea[2, g] if d > 2 else 1.0
        fac2 = tsc / ssc2 if d > 2 else 0.0
        direction = dira[g]
        dsc = direction / ssc0
        r = sp[1]
        b0 = cols[g, BREAK_AREA] / tsc if not math.isnan(cols[g, BREAK_AREA]) else np.inf
        b1 = cols[g, BREAK_NORMAL] / tsc if not math.isnan(cols[g, BREAK_NORMAL]) else np.inf
        if per_row:
            on = True
            for col in range(m):
                if grid[g, col] != tsc * rel[col]:
                    on = False
                    break
            for col in range(m):
                gr[col] = rel[col] if on else grid[g, col] / tsc
        else:
            for col in range(m):
                gr[col] = grid[0, col]
        t = t0a[g] / tsc
        y0 = y0a[0, g] / ssc0
        y1 = y0a[1, g] / ssc1 if d > 1 else 0.0
        y2 = y0a[2, g] / scalea[2, g] if d > 2 else 0.0
        t_end = 1.0
        # the first output at or after t; one exactly at t is the initial state
        ptr = 0
        while ptr < m and gr[ptr] < t:
            ptr += 1
        ptr0 = ptr
        if ptr < m and gr[ptr] == t:
            Y0[i, ptr] = y0 * ssc0
            if d > 1:
                Y1[i, ptr] = y1 * ssc1
                Y2[i, ptr] = y2 * ssc2
            ptr += 1
        it = 0
        if t < t_end:
            f0, f1, f2, fin = _rhs(t, y0, y1, sp, cd, tsc, fac0, fac1, fac2, ssc0, ssc1, direction)
            K[0, 0], K[0, 1], K[0, 2] = f0, f1, f2
            g_old = _slip(y0, y1, ssc0, ssc1, r, coupled, dsc)
            # initial step: Hairer, Norsett and Wanner, II.4 (as vecrk._initial_step)
            s0 = atol + abs(y0) * rtol
            s1 = atol + abs(y1) * rtol
            s2 = atol + abs(y2) * rtol
            d0 = (y0 / s0) ** 2
            d1 = (f0 / s0) ** 2
            if d > 1:
                d0 = d0 + (y1 / s1) ** 2 + (y2 / s2) ** 2
                d1 = d1 + (f1 / s1) ** 2 + (f2 / s2) ** 2
            d0 = math.sqrt(d0 / d)
            d1 = math.sqrt(d1 / d)
            h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
            span = t_end - t
            h0 = min(h0, span)
            e0, e1, e2, fin2 = _rhs(t + h0, y0 + h0 * f0, y1 + h0 * f1, sp, cd, tsc, fac0, fac1, fac2, ssc0, ssc1,
                                    direction)
            nfev[i] += 2
            d2 = ((e0 - f0) / s0) ** 2
            if d > 1:
                d2 = d2 + ((e1 - f1) / s1) ** 2 + ((e2 - f2) / s2) ** 2
            d2 = math.sqrt(d2 / d) / h0
            big = max(d1, d2)
            h1 = max(1e-6, h0 * 1e-3) if big <= 1e-15 else (0.01 / big) ** (1.0 / (order + 1))
            H = min(min(100 * h0, h1), span)
            lim = np.inf
            if b0 > t:
                lim = b0 - t
            if b1 > t and b1 - t < lim:
                lim = b1 - t
            H = min(H, lim)
            if not (fin and fin2):
                stat[0], stat[1] = NOT_FINITE, i
                return iters_max
            rejected = False
            while True:
                it += 1
                if it > max_iter:
                    stat[0], stat[1] = TOO_MANY, i
                    return iters_max
                ha = min(H, t_end - t)
                ahead = np.inf
                if b0 > t * eps4:
                    ahead = b0
                if b1 > t * eps4 and b1 < ahead:
                    ahead = b1
                ha = min(ha, ahead - t)
                if ha < 10.0 * abs(np.nextafter(t, np.inf) - t):
                    stat[0], stat[1] = UNDERFLOW, i
                    return iters_max
                fin = True
                for s in range(1, ns):
                    c0, c1, c2 = _comb(A[s], K, s)
                    f0, f1, f2, ok_s = _rhs(t + Cn[s] * ha, c0 * ha + y0, c1 * ha + y1, sp, cd, tsc, fac0, fac1,
                                            fac2, ssc0, ssc1, direction)
                    K[s, 0], K[s, 1], K[s, 2] = f0, f1, f2
                    fin = fin and ok_s
                c0, c1, c2 = _comb(B, K, ns)
                n0, n1, n2 = c0 * ha + y0, c1 * ha + y1, c2 * ha + y2
                t_new = t + ha
                f0, f1, f2, ok_s = _rhs(t_new, n0, n1, sp, cd, tsc, fac0, fac1, fac2, ssc0, ssc1, direction)
                K[ns, 0], K[ns, 1], K[ns, 2] = f0, f1, f2
                nfev[i] += ns
                if not (fin and ok_s):
                    stat[0], stat[1] = NOT_FINITE, i
                    return iters_max
                s0 = max(abs(y0), abs(n0)) * rtol + atol
                s1 = max(abs(y1), abs(n1)) * rtol + atol
                s2 = max(abs(y2), abs(n2)) * rtol + atol
                if dop:
                    c0, c1, c2 = _comb(E[0], K, ns + 1)
                    q0, q1, q2 = _comb(E[1], K, ns + 1)
                    e5 = (c0 / s0) ** 2
                    e3 = (q0 / s0) ** 2
                    if d > 1:
                        e5 = e5 + (c1 / s1) ** 2 + (c2 / s2) ** 2
                        e3 = e3 + (q1 / s1) ** 2 + (q2 / s2) ** 2
                    denom = e5 + 0.01 * e3
                    err = abs(ha) * e5 / math.sqrt(denom * d) if denom > 0 else 0.0
                else:
                    c0, c1, c2 = _comb(E[0], K, ns + 1)
                    acc = (c0 * ha / s0) ** 2
                    if d > 1:
                        acc = acc + (c1 * ha / s1) ** 2 + (c2 * ha / s2) ** 2
                    err = math.sqrt(acc / d)
                if math.isnan(err):
                    stat[0], stat[1] = NOT_FINITE, i
                    return iters_max
                ok = err < 1.0
                factor = 10.0 if err == 0.0 else 0.9 * err ** exponent
                if ok:
                    factor = min(10.0, factor)
                    if rejected:
                        factor = min(1.0, factor)
                else:
                    factor = max(0.2, factor)
                H = ha * factor
                rejected = not ok
                if not ok:
                    continue
                g_new = _slip(n0, n1, ssc0, ssc1, r, coupled, dsc)
                stop = g_new <= 0.0 and g_old > 0.0
                g_old = g_new
                if stop or (ptr < m and gr[ptr] <= t_new):
                    if dop:  # DOP853's extra stages and interpolant (vecdense.dense_output)
                        for j in range(nx):
                            sx = ns + 1 + j
                            c0, c1, c2 = _comb(AX[j], K, sx)
                            f0, f1, f2, ok_s = _rhs(t + CX[j] * ha, c0 * ha + y0, c1 * ha + y1, sp, cd, tsc, fac0,
                                                    fac1, fac2, ssc0, ssc1, direction)
                            K[sx, 0], K[sx, 1], K[sx, 2] = f0, f1, f2
                        nfev[i] += nx
                        for q, (yo, yn) in enumerate(((y0, n0), (y1, n1), (y2, n2))):
                            dyv = yn - yo
                            Fc[0, q] = dyv
                            Fc[1, q] = K[0, q] * ha - dyv
                            Fc[2, q] = (K[ns, q] + K[0, q]) * -ha + 2 * dyv
                        for j in range(nd):
                            c0, c1, c2 = _comb(D[j], K, nk)
                            Fc[3 + j, 0], Fc[3 + j, 1], Fc[3 + j, 2] = c0 * ha, c1 * ha, c2 * ha
                    else:
                        for j in range(nd):
                            Fc[j, 0], Fc[j, 1], Fc[j, 2] = _comb(D[j], K, nk)
                    t_stop = t_new
                    if stop:
                        # the first slip <= 0 in the step on the dense output, as vecrk._locate finds it
                        # (root_bracketed: tol 4 eps, gtol 8 eps, regula falsi with the Anderson-Bjorck
                        # correction, bisection where it stalls and after 30 iterations)
                        lo, hi = 0.0, 1.0
                        z0, z1, z2 = _dense(Fc, nc, dop, lo, ha, y0, y1, y2)
                        glo = _slip(z0, z1, ssc0, ssc1, r, coupled, dsc)
                        z0, z1, z2 = _dense(Fc, nc, dop, hi, ha, y0, y1, y2)
                        ghi = _slip(z0, z1, ssc0, ssc1, r, coupled, dsc)
                        tol, gtol = 4 * eps, 8 * eps
                        side = 0.0
                        w0 = w1 = w2 = np.inf
                        x = hi
                        for rit in range(BISECTIONS + 40):
                            x = hi
                            if not (hi - lo > tol and abs(ghi) > gtol):
                                break
                            mid = (lo * ghi - hi * glo) / (ghi - glo)
                            slow = (hi - lo) > 0.5 * w0
                            w0, w1, w2 = w1, w2, hi - lo
                            if not math.isfinite(mid) or slow or rit >= 30:
                                mid = 0.5 * (lo + hi)
                            mid = min(max(mid, lo + tol), hi - tol) if hi - lo > 2 * tol else 0.5 * (lo + hi)
                            z0, z1, z2 = _dense(Fc, nc, dop, mid, ha, y0, y1, y2)
                            gm = _slip(z0, z1, ssc0, ssc1, r, coupled, dsc)
                            if gm <= 0.0:
                                m_hi = 1.0 - gm / ghi
                                hi, ghi = mid, gm
                                if side < 0:
                                    glo = glo * (m_hi if m_hi > 0 else 0.5)
                                side = -1.0
                            else:
                                m_lo = 1.0 - gm / glo
                                lo, glo = mid, gm
                                if side > 0:
                                    ghi = ghi * (m_lo if m_lo > 0 else 0.5)
                                side = 1.0
                        t_stop = t + x * ha
                        z0, z1, z2 = _dense(Fc, nc, dop, x, ha, y0, y1, y2)
                        t_event[i] = t_stop
                        y_event[0, i] = z0
                        if d > 1:
                            y_event[1, i] = z1
                            y_event[2, i] = z2
                    stop_at = ptr
                    while stop_at < m and gr[stop_at] <= t_stop:
                        stop_at += 1
                    for col in range(ptr, stop_at):
                        z0, z1, z2 = _dense(Fc, nc, dop, (gr[col] - t) / ha, ha, y0, y1, y2)
                        Y0[i, col] = z0 * ssc0
                        if d > 1:
                            Y1[i, col] = z1 * ssc1
                            Y2[i, col] = z2 * ssc2
                    ptr = stop_at
                t = t_new
                y0, y1, y2 = n0, n1, n2
                K[0, 0], K[0, 1], K[0, 2] = K[ns, 0], K[ns, 1], K[ns, 2]
                if stop or t_new >= t_end:
                    break
        if it > iters_max:
            iters_max = it
        for col in range(m):
            inside = col >= ptr0 and col < ptr
            reached[i, col] = inside
            if not inside:
                Y0[i, col] = np.nan
                if d > 1:
                    Y1[i, col] = np.nan
                    Y2[i, col] = np.nan
    return iters_max



@numba.njit(cache=True)
def scatter_stuck(Ys, rows, Ts, t_from, t_to, done, stuck_mask, Y0, Y1, Y2):
    """Bookkeeping of ``batchstick.fill_stuck`` in one pass: the stuck states Ys (d, k, m) of scenes rows at
    their output times Ts (k, m) into the outputs of those scenes in [t_from, t_to] not yet done (rows
    of Y0, Y1, Y2), marking them done and stuck. No physics: Ys comes from ``stick.stuck_states``."""
    d = Ys.shape[0]
    m = Ts.shape[1]
    for r in range(rows.size):
        g = rows[r]
        lo, hi = t_from[r], t_to[r]
        for c in range(m):
            tt = Ts[r, c]
            if tt >= lo and tt <= hi and not done[g, c]:
                Y0[g, c] = Ys[0, r, c]
                if d > 1:
                    Y1[g, c] = Ys[1, r, c]
                    Y2[g, c] = Ys[2, r, c]
                done[g, c] = True
                stuck_mask[g, c] = True
