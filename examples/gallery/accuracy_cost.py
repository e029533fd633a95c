r"""# What accuracy costs

The wear law on the paper's impact can be solved three ways: the `exact` closed form
$u = u_0 \exp(b\cos\varphi t - b)$, the paper's first-order `series`, or numerically (`ode:DOP853`, an
explicit Runge-Kutta method at a chosen tolerance). This example measures, on the paper's stated
$\lambda = 1.81 \times 10^6$ Pa s/m, how far each is from the closed form and what each costs in CPU time.
"""

# %%
# Solve the same impact with every solver and time each (CPU seconds of this process, the best of five
# runs, so that a busy machine counts less). What the output shows: the spin at the end of contact and the
# largest difference from the closed form over the contact, in rpm.
import time

import matplotlib.pyplot as plt
import numpy as np

import frictionlab as fl

RPM = 60 / (2 * np.pi)
data = fl.load_dataset("impact-golf-v28")
params = {"lam": "1.81e6 Pa s/m"}


def timed(**kwargs):
    best = np.inf
    for _ in range(5):
        start = time.process_time()
        traj = fl.simulate("wear", data, params, **kwargs)
        best = min(best, time.process_time() - start)
    return traj, best


exact, t_exact = timed(solver="exact")
runs = {"exact": (exact, t_exact), "series": timed(solver="series")}
for rtol in (1e-3, 1e-6, 1e-9):
    runs[f"ode:DOP853 rtol {rtol:g}"] = timed(solver="ode:DOP853", rtol=rtol)
for label, (traj, cpu) in runs.items():
    gap = np.max(np.abs(np.interp(exact.t, traj.t, traj.omega) - exact.omega)) * RPM
    print(f"{label:>22}: end spin {traj.omega[-1] * RPM:7.1f} rpm, off the closed form by up to "
          f"{gap:9.3g} rpm, {cpu * 1e3:7.2f} CPU ms")

# %%
# The series is not a cheaper approximation of the same answer: at the paper's $b \approx 0.8$ it is a
# different curve, thousands of rpm away (frictionlab warns when $b > 0.1$), while the numerical solver reaches the closed form as its tolerance
# tightens, at a cost that grows with it. The figure shows the spin of each, and how far each is from the
# closed form.
fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 6), sharex=True, layout="constrained")
for label, (traj, _) in runs.items():
    top.plot(traj.t * 1e6, traj.omega * RPM, label=label)
    gap = np.abs(np.interp(exact.t, traj.t, traj.omega) - exact.omega) * RPM
    if label != "exact":
        bottom.semilogy(exact.t * 1e6, np.maximum(gap, 1e-12), label=label)
top.set_ylabel("spin [rpm]")
top.legend(fontsize="small")
bottom.set_ylabel("|spin - closed form| [rpm]")
bottom.set_xlabel("time since first contact [µs]")
