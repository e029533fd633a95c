"""The compiled integrator of ``frictionlab.solve.quasistatic``: a quasi-static rate-and-state slider.

States (laboratory units: time in s, slip in um): m = mu - mu_ss(V1) and psi = ln(V1 theta / Dc), with V1 the
first load-point velocity and the slider in steady state there at t = 0 (m = psi = 0):

    V = V1 exp((m - b psi) / a)                     (mu = mu_ss(V1) + a ln(V/V1) + b psi)
    dm/dt = k (V_lp(t) - V)
    dpsi/dt = (V1 exp(-psi) - V) / Dc               aging law, d theta/dt = 1 - V theta / Dc
    dpsi/dt = -(V / Dc) (ln(V/V1) + psi)            slip law, d theta/dt = -(V theta / Dc) ln(V theta / Dc)
    dpsi/dt = (V1 e^-psi - V^2 e^psi / V1) / (2 Dc)  PRZ law, d theta/dt = 1 - (V theta / (2 Dc))^2,
                                                    psi = ln(V1 theta / (2 Dc))
    dpsi/dt = (V1 e^-psi - V) / Dc - (c/b) dm/dt    Nagata's law, d theta/dt = 1 - V theta/Dc - (c/b) theta dmu/dt

Integrated by SDIRK4 (Hairer and Wanner, Solving ODEs II, Table IV.6.5: 5 stages, order 4, L-stable,
stiffly accurate, embedded order 3), each stage by Newton's method on the analytic 2 x 2 Jacobian, restarted
at every load-point step. The forward sensitivities S = d(m, psi)/d(a, b, Dc, k) (and for Nagata's law to c, a
fifth column) are the exact derivatives of
the discrete scheme (each stage's equation differentiated: (I - h g J) K^S = J (S + h sum a K^S) + f_p, the
same matrix as the stage's Newton iteration), so the least-squares Jacobian is that of the computed solution.
Outputs at the sample times come from the cubic Hermite interpolant of each step (m, its rate and their
sensitivities: the interpolated sensitivity is the derivative of the interpolated m).

Module-level functions compiled by numba with an on-disk cache (``cache=True``) when numba imports; otherwise
the same functions run as Python (correct, about a hundred times slower).
"""
import math

import numpy as np

from ..core.jit import jit

AGING, SLIP, PRZ, NAGATA = 0, 1, 2, 3
#: Status codes of ``integrate``.
OK, TOO_MANY_STEPS, RUNAWAY, STEP_TOO_SMALL = 0, 1, 2, 3
#: Largest exponent ln(V/V1) the kernel evaluates (beyond it the step is rejected as not finite).
MAX_EXPONENT = 700.0
MAX_STEPS = 2_000_000

G = 0.25  # SDIRK4's diagonal
# Stage coefficients (row i: a_i0 .. a_i,i-1), weights b (= the last row: stiffly accurate) and b - bhat.
A10 = 0.5
A20, A21 = 17.0 / 50.0, -1.0 / 25.0
A30, A31, A32 = 371.0 / 1360.0, -137.0 / 2720.0, 15.0 / 544.0
A40, A41, A42, A43 = 25.0 / 24.0, -49.0 / 48.0, 125.0 / 16.0, -85.0 / 12.0
E0, E1, E2, E3, E4 = 25.0 / 24.0 - 59.0 / 48.0, -49.0 / 48.0 + 17.0 / 96.0, 125.0 / 16.0 - 225.0 / 32.0, 0.0, 0.25
#: The rows a_i0 .. a_i3 of the stage coefficients (zero past the diagonal), indexed by stage in the loops (an
#: array, which numba takes as a constant: a tuple of tuples indexed at run time took a quarter longer to compile).
TABLEAU = np.array(((0.0, 0.0, 0.0, 0.0), (A10, 0.0, 0.0, 0.0), (A20, A21, 0.0, 0.0), (A30, A31, A32, 0.0),
                    (A40, A41, A42, A43)))


@jit
def rates(law, a, b, Dc, k, cn, V1, vlp, m, psi, f, J, Fp):
    """Fill f = (dm/dt, dpsi/dt), J = d f / d(m, psi) and Fp = d f / d(a, b, Dc, k) at (m, psi) (cn: Nagata's c;
    where Fp has a fifth column, d f / d c there); return the slip rate V [um/s] (inf where ln(V/V1) exceeds
    MAX_EXPONENT or psi is beyond range)."""
    lnE = (m - b * psi) / a
    if not (lnE < MAX_EXPONENT) or not (-psi < MAX_EXPONENT) or (law == PRZ and not (psi + 2.0 * lnE < MAX_EXPONENT)):
        return math.inf
    V = V1 * math.exp(lnE)
    f[0] = k * (vlp - V)
    J[0, 0] = -k * V / a
    J[0, 1] = k * b * V / a
    dVa = -V * lnE / a
    dVb = -V * psi / a
    if law == SLIP:
        L = lnE + psi
        f[1] = -V * L / Dc
        J[1, 0] = -V * (L + 1.0) / (a * Dc)
        J[1, 1] = -(-b * V * L / a + V * (1.0 - b / a)) / Dc
        Fp[1, 0] = -(dVa * L - V * lnE / a) / Dc
        Fp[1, 1] = -(dVb * L - V * psi / a) / Dc
    elif law == PRZ:
        g = V1 * math.exp(-psi)
        h = V1 * math.exp(psi + 2.0 * lnE)  # V^2 e^psi / V1
        f[1] = (g - h) / (2.0 * Dc)
        J[1, 0] = -h / (a * Dc)
        J[1, 1] = (-g - h * (1.0 - 2.0 * b / a)) / (2.0 * Dc)
        Fp[1, 0] = -h * dVa / (V * Dc)
        Fp[1, 1] = -h * dVb / (V * Dc)
    else:
        g = V1 * math.exp(-psi)
        f[1] = (g - V) / Dc
        J[1, 0] = -V / (a * Dc)
        J[1, 1] = (-g + b * V / a) / Dc
        Fp[1, 0] = -dVa / Dc
        Fp[1, 1] = -dVb / Dc
    Fp[1, 2] = -f[1] / Dc  # every evolution rate above is proportional to 1 / Dc
    Fp[1, 3] = 0.0
    for c in range(4, Fp.shape[1]):
        Fp[1, c] = 0.0
    if law == NAGATA:  # - (c/b) dm/dt
        q = cn / b
        f[1] -= q * f[0]
        J[1, 0] -= q * J[0, 0]
        J[1, 1] -= q * J[0, 1]
        Fp[1, 0] -= q * (-k * dVa)
        Fp[1, 1] -= q * (-k * dVb) - q / b * f[0]
        Fp[1, 3] = -q * (vlp - V)
        if Fp.shape[1] > 4:
            Fp[1, 4] = -f[0] / b
    Fp[0, 0] = -k * dVa
    Fp[0, 1] = -k * dVb
    Fp[0, 2] = 0.0
    Fp[0, 3] = vlp - V
    for c in range(4, Fp.shape[1]):
        Fp[0, c] = 0.0
    return V


@jit
def _solve2(M00, M01, M10, M11, r0, r1):
    det = M00 * M11 - M01 * M10
    return (M11 * r0 - M01 * r1) / det, (M00 * r1 - M10 * r0) / det


@jit
def integrate(law, a, b, Dc, k, cn, V1, seg_t, seg_v, t_out, rtol, atol_m, sens, vmax, out_m, out_psi, out_S, stats):
    """Integrate from the steady state at V1 (t = 0) through the load-point segments (start times seg_t [s],
    velocities seg_v [um/s]; cn: Nagata's c, else unused) and write m, psi and (sens) dm/d(a, b, Dc, k) at the
    sorted times t_out [s] (out_S: n x 4, or n x 5 for Nagata's law with dm/dc in the fifth column).

    rtol: relative tolerance; atol_m: absolute tolerance of m (psi's is rtol). vmax: slip rate [um/s] beyond
    which the slider has run away. stats[0:5] receive (accepted steps, rejected steps, Newton iterations, time
    [s] reached, and for a runaway the slip rate [um/s] then; for a failure the time it happened). Returns a
    status code (OK, TOO_MANY_STEPS, RUNAWAY, STEP_TOO_SMALL)."""
    n = t_out.size
    y = np.zeros(2)
    P = out_S.shape[1]  # sensitivity columns: (a, b, Dc, k), and c for Nagata's law
    S = np.zeros((2, P))
    f0 = np.zeros(2)
    J = np.zeros((2, 2))
    Fp = np.zeros((2, P))
    K = np.zeros((5, 2))
    KS = np.zeros((5, 2, P))
    Js = np.zeros((5, 2, 2))
    Fps = np.zeros((5, 2, P))
    base = np.zeros(2)
    baseS = np.zeros((2, P))
    S1 = np.zeros((2, P))
    Y = np.zeros(2)
    KS0 = np.zeros((2, P))
    H = np.zeros((4, P))  # a step's m-sensitivities and their rates at both ends, for the dense output
    f = np.zeros(2)
    i_out = 0
    while i_out < n and t_out[i_out] <= 0.0:  # samples at t = 0: the steady state
        out_m[i_out] = 0.0
        out_psi[i_out] = 0.0
        if sens:
            for c in range(P):
                out_S[i_out, c] = 0.0
        i_out += 1
    t_end = t_out[n - 1] if n else 0.0
    accepted = 0
    rejected = 0
    newton = 0
    nseg = seg_t.size
    status = OK
    t = 0.0
    for j in range(nseg):
        t0 = seg_t[j]
        t1 = seg_t[j + 1] if j + 1 < nseg else t_end
        if t1 > t_end:
            t1 = t_end
        if not t1 > t0:
            continue
        vlp = seg_v[j]
        V = rates(law, a, b, Dc, k, cn, V1, vlp, y[0], y[1], f0, J, Fp)
        if sens:
            for c in range(P):
                KS0[0, c] = J[0, 0] * S[0, c] + J[0, 1] * S[1, c] + Fp[0, c]
                KS0[1, c] = J[1, 0] * S[0, c] + J[1, 1] * S[1, c] + Fp[1, c]
        stiff = max(abs(J[0, 0]), abs(J[1, 1]), abs(J[0, 1] * J[1, 0]) ** 0.5, 1e-300)
        h = min(0.05 / stiff, t1 - t0)
        t = t0
        while t < t1:
            if accepted + rejected >= MAX_STEPS:
                stats[0], stats[1], stats[2], stats[3] = accepted, rejected, newton, t
                return TOO_MANY_STEPS
            last = h >= (t1 - t) * (1.0 - 1e-12)
            if last:
                h = t1 - t
            if h <= 1e-14 * max(t1, 1.0):
                stats[0], stats[1], stats[2], stats[3] = accepted, rejected, newton, t
                return STEP_TOO_SMALL
            sc0 = atol_m + rtol * abs(y[0])
            sc1 = rtol * (1.0 + abs(y[1]))
            ok = True
            for i in range(5):
                row = TABLEAU[i]
                for c in range(2):  # base = y + h sum_{l<i} a_il K[l]
                    acc = 0.0
                    for l in range(i):
                        acc += row[l] * K[l, c]
                    base[c] = y[c] + h * acc
                if i == 0:
                    Y[0] = base[0] + h * G * f0[0]
                    Y[1] = base[1] + h * G * f0[1]
                else:
                    Y[0] = base[0] + h * G * K[i - 1, 0]
                    Y[1] = base[1] + h * G * K[i - 1, 1]
                converged = False
                for _ in range(12):
                    newton += 1
                    V = rates(law, a, b, Dc, k, cn, V1, vlp, Y[0], Y[1], f, J, Fp)
                    if not math.isfinite(V):
                        break
                    r0 = -(Y[0] - base[0] - h * G * f[0])
                    r1 = -(Y[1] - base[1] - h * G * f[1])
                    d0, d1 = _solve2(1.0 - h * G * J[0, 0], -h * G * J[0, 1], -h * G * J[1, 0],
                                     1.0 - h * G * J[1, 1], r0, r1)
                    if not (math.isfinite(d0) and math.isfinite(d1)):
                        break
                    Y[0] += d0
                    Y[1] += d1
                    if (abs(d0) <= max(1e-3 * sc0, 1e-15 * abs(Y[0])) and
                            abs(d1) <= max(1e-3 * sc1, 1e-15 * abs(Y[1]))):
                        converged = True
                        break
                if not converged:
                    ok = False
                    break
                V = rates(law, a, b, Dc, k, cn, V1, vlp, Y[0], Y[1], f, J, Fp)
                if not math.isfinite(V):
                    ok = False
                    break
                K[i, 0] = f[0]
                K[i, 1] = f[1]
                if sens:
                    for r in range(2):
                        Js[i, r, 0] = J[r, 0]
                        Js[i, r, 1] = J[r, 1]
                        for c in range(P):
                            Fps[i, r, c] = Fp[r, c]
            if not ok:
                rejected += 1
                h *= 0.25
                continue
            e0 = h * (E0 * K[0, 0] + E1 * K[1, 0] + E2 * K[2, 0] + E3 * K[3, 0] + E4 * K[4, 0])
            e1 = h * (E0 * K[0, 1] + E1 * K[1, 1] + E2 * K[2, 1] + E3 * K[3, 1] + E4 * K[4, 1])
            sc0 = atol_m + rtol * max(abs(y[0]), abs(Y[0]))
            sc1 = rtol * (1.0 + max(abs(y[1]), abs(Y[1])))
            err = math.sqrt(0.5 * ((e0 / sc0) ** 2 + (e1 / sc1) ** 2))
            if not err <= 1.0:
                rejected += 1
                h *= max(0.2, 0.9 * err ** -0.25) if math.isfinite(err) else 0.2
                continue
            if V > vmax:
                stats[0], stats[1], stats[2], stats[3], stats[4] = accepted, rejected, newton, t + h, V
                return RUNAWAY
            accepted += 1
            t_new = t1 if last else t + h
            if sens:  # the stages' sensitivities, each with its stage's matrix
                for i in range(5):
                    row = TABLEAU[i]
                    for r in range(2):  # baseS = S + h sum_{l<i} a_il KS[l] (after stage 4: S1's base)
                        for c in range(P):
                            acc = 0.0
                            for l in range(i):
                                acc += row[l] * KS[l, r, c]
                            baseS[r, c] = S[r, c] + h * acc
                    J00, J01, J10, J11 = Js[i, 0, 0], Js[i, 0, 1], Js[i, 1, 0], Js[i, 1, 1]
                    M00, M01 = 1.0 - h * G * J00, -h * G * J01
                    M10, M11 = -h * G * J10, 1.0 - h * G * J11
                    for c in range(P):
                        r0 = J00 * baseS[0, c] + J01 * baseS[1, c] + Fps[i, 0, c]
                        r1 = J10 * baseS[0, c] + J11 * baseS[1, c] + Fps[i, 1, c]
                        KS[i, 0, c], KS[i, 1, c] = _solve2(M00, M01, M10, M11, r0, r1)
                for c in range(P):
                    S1[0, c] = baseS[0, c] + h * G * KS[4, 0, c]
                    S1[1, c] = baseS[1, c] + h * G * KS[4, 1, c]
            # dense output on (t, t_new]: cubic Hermite of m, psi (and of the sensitivities of m); the step's
            # values held in scalars and in H (an output array might alias the small arrays: they would be read again)
            dt = t_new - t
            m0, m1, dm0, dm1 = y[0], Y[0], f0[0], K[4, 0]
            q0, q1, dq0, dq1 = y[1], Y[1], f0[1], K[4, 1]
            if sens:
                for c in range(P):
                    H[0, c], H[1, c], H[2, c], H[3, c] = S[0, c], KS0[0, c], S1[0, c], KS[4, 0, c]
            final = last and j == nseg - 1
            while i_out < n and (t_out[i_out] <= t_new or (final and t_out[i_out] <= t_end)):
                th = (t_out[i_out] - t) / dt
                if th < 0.0:
                    th = 0.0
                elif th > 1.0:
                    th = 1.0
                u2 = (1.0 - th) * (1.0 - th)
                h00 = (1.0 + 2.0 * th) * u2
                h10 = th * u2 * dt
                h01 = th * th * (3.0 - 2.0 * th)
                h11 = th * th * (th - 1.0) * dt
                out_m[i_out] = h00 * m0 + h10 * dm0 + h01 * m1 + h11 * dm1
                out_psi[i_out] = h00 * q0 + h10 * dq0 + h01 * q1 + h11 * dq1
                if sens:
                    for c in range(P):
                        out_S[i_out, c] = h00 * H[0, c] + h10 * H[1, c] + h01 * H[2, c] + h11 * H[3, c]
                i_out += 1
            if sens:
                for c in range(P):
                    S[0, c] = S1[0, c]
                    S[1, c] = S1[1, c]
                    KS0[0, c] = KS[4, 0, c]
                    KS0[1, c] = KS[4, 1, c]
            y[0] = Y[0]
            y[1] = Y[1]
            f0[0] = K[4, 0]
            f0[1] = K[4, 1]
            t = t_new
            h *= min(4.0, max(0.2, 0.9 * err ** -0.25)) if err > 0 else 4.0
    while i_out < n:  # samples at the very end (t_end) when the last segment was empty
        out_m[i_out] = y[0]
        out_psi[i_out] = y[1]
        if sens:
            for c in range(P):
                out_S[i_out, c] = S[0, c]
        i_out += 1
    stats[0], stats[1], stats[2], stats[3] = accepted, rejected, newton, t
    return status
