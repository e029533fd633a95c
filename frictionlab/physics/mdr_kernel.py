"""The time loop of ``mdr.impacts``, compiled (numba where it imports; ``core.jit``): per row and step, the
spheres' Velocity Verlet half steps, each spring's Coulomb limit (``mdr.limits``) and MDR update (``mdr.step``),
and their sum, in one pass over the springs instead of a dozen array operations. The same arithmetic as those
functions, spring by spring; the sums over the springs are taken in order (numpy's are pairwise), so results
agree with the array form to round-off. Importing this module imports numba."""
import numpy as np

from ..core.jit import jit


@jit
def impacts_loop(t, N, a, mu, x, k, mass, radius, inertia, v, omega):
    """Integrate every row (t, N, a: rows x (steps + 1) [s, N, m]; x: rows x springs [m]; k: rows [N/m]) from the
    inbound v, omega (rows [m/s, rad/s]), which it overwrites with the end-of-contact values."""
    rows, n = t.shape
    springs = x.shape[1]
    f = np.zeros(springs)
    for r in range(rows):
        f[:] = 0.0
        F = 0.0
        vr, wr = v[r], omega[r]
        for i in range(n - 1):
            dt = t[r, i + 1] - t[r, i]
            vr -= 0.5 * dt * F / mass
            wr += 0.5 * dt * F * radius / inertia
            df = k[r] * ((vr - radius * wr) * dt)
            ai = a[r, i + 1]
            a2 = ai * ai
            total = 0.0
            for j in range(springs):
                q = a2 - x[r, j] ** 2
                if q > 0.0:
                    total += q
            scale = mu * N[r, i + 1]
            F = 0.0
            for j in range(springs):
                if x[r, j] < ai:
                    q = a2 - x[r, j] ** 2
                    lim = scale * (q / total) if (q > 0.0 and total > 0.0) else 0.0
                    g = f[j] + df
                    g = -lim if g < -lim else (lim if g > lim else g)
                else:
                    g = 0.0
                f[j] = g
                F += g
            vr -= 0.5 * dt * F / mass
            wr += 0.5 * dt * F * radius / inertia
        v[r], omega[r] = vr, wr
