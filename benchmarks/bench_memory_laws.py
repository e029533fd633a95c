"""Laws with memory: frictionlab's fit against a careful plain scipy fit, on every built-in dataset they apply to.

    python benchmarks/bench_memory_laws.py [--quick] [--plugin-dataset incline-oil-a100]

For each law with memory (LuGre, Dahl, rate-and-state aging and slip) and each built-in dataset a frictionlab
fit applies to outside the quasi-static spring-slider (inclines, and the impacts' stated numbers where there
are more numbers than parameters), prints the chi-square and CPU seconds of

  frictionlab   ``fl.fit(law, dataset)``: the compiled right-hand side with its analytic Jacobian, LSODA, the
                search of ``inference.fitting.model`` (a fresh process's first fit also loads numba's cached kernel:
                shown once, as the cold start);
  plain scipy   ``plain_memory_fits.plain_fit``: written independently of frictionlab (float right-hand side,
                analytic Jacobian, LSODA at rtol 1e-8, a 125-point scan, two least_squares runs),

and whether frictionlab's minimum is at or below the plain one (within 0.1% of it). Then a plugin law with a
plain Python ``force`` and ``rates`` (LuGre's formulas, registered at run time, so it takes the general path)
is fitted to one dataset and timed beside the built-in LuGre. The reference unit (``refunit.py``) is measured
right before and right after, and the machine's load is printed.
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import refunit
from plain_memory_fits import plain_fit

CASES = [(law, ds) for law in ("lugre", "dahl", "rate-state-aging", "rate-state-slip")
         for ds in ("incline-oil-a100", "incline-oil-a200", "incline-oil-a400", "incline-dry-d10", "incline-dry-d12p7")]
CASES += [("dahl", "impact-golf-v28"), ("dahl", "impact-golf-v61")]
QUICK = [("lugre", "incline-oil-a100"), ("dahl", "incline-dry-d10"), ("rate-state-aging", "incline-oil-a100"),
         ("dahl", "impact-golf-v28")]


def plugin_lugre():
    """LuGre's formulas as a third party writes them: a plain Python law registered at run time."""
    import frictionlab as fl
    from frictionlab.physics.law import FrictionLaw, StateSpec

    lugre = fl.get_law("lugre")

    @fl.register_law
    class PluginLuGre(FrictionLaw):
        name = "lugre-plugin"
        formula = lugre.formula
        citation = lugre.citation
        params = lugre.params
        requires = lugre.requires
        states = (StateSpec("z", "m", "steady", 1e-6, "mean bristle deflection"),)

        def _zd(self, p, c):
            g = p["mu_c"] + (p["mu_s"] - p["mu_c"]) * np.exp(-(c.u / p["vs"]) ** 2)
            return c.u - p["sigma0"] * np.abs(c.u) * c.state["z"] / g

        def force(self, p, c):
            return c.N * (p["sigma0"] * c.state["z"] + p["sigma1"] * self._zd(p, c) + p["sigma2"] * c.u)

        def rates(self, p, c):
            return {"z": self._zd(p, c)}

        def steady_state(self, p, c):
            g = p["mu_c"] + (p["mu_s"] - p["mu_c"]) * np.exp(-(c.u / p["vs"]) ** 2)
            return {"z": g * np.sign(c.u) / p["sigma0"]}

    return "lugre-plugin"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help=f"only {len(QUICK)} cases")
    ap.add_argument("--plugin-dataset", default="incline-oil-a100")
    args = ap.parse_args()
    print(refunit.load())
    unit_before = refunit.unit()
    print(f"reference unit before: {unit_before:.2f} CPU s (1000 plain DOP853 solves of the dimensionless wear impact)")
    import frictionlab as fl

    t0 = time.process_time()
    fl.simulate("lugre", fl.load_dataset("incline-oil-a100"), rtol=1e-6)
    print(f"cold start: the first compiled solve in this process {time.process_time() - t0:.2f} CPU s "
          "(numba's kernel loaded from its cache, or compiled once per machine)")
    print(f"\n{'law':17s} {'dataset':18s} {'chi2 frictionlab':>16s} {'chi2 plain':>12s} {'CPU fl [s]':>10s} "
          f"{'CPU plain [s]':>13s} {'plain/fl':>8s}  minimum")
    ratios, reached = [], 0
    cases = QUICK if args.quick else CASES
    for law, ds in cases:
        t0 = time.process_time()
        r = fl.fit(law, ds)
        cpu = time.process_time() - t0
        chi_plain, _, cpu_plain = plain_fit(law, ds)
        chi = r.stats.chisqr if r.ok else float("nan")
        ok = r.ok and chi <= chi_plain * (1 + 1e-3)
        reached += ok
        ratios.append(cpu_plain / cpu)
        print(f"{law:17s} {ds:18s} {chi:16.6g} {chi_plain:12.6g} {cpu:10.2f} {cpu_plain:13.2f} {cpu_plain / cpu:8.2f}  "
              f"{'reached' if ok else 'NOT reached' if r.ok else r.status + ': ' + r.reason}")
    print(f"\nfrictionlab reaches the plain fit's minimum (or a lower one) in {reached} of {len(cases)} fits; plain CPU / "
          f"frictionlab CPU: median {statistics.median(ratios):.2f} (range {min(ratios):.2f} to {max(ratios):.2f})")
    plugin = plugin_lugre()
    for law in ("lugre", plugin):
        t0 = time.process_time()
        r = fl.fit(law, args.plugin_dataset)
        print(f"{law:13s} on {args.plugin_dataset}: chi2 {r.stats.chisqr if r.ok else float('nan'):.6g}, {r.nfev} "
              f"evaluations, {time.process_time() - t0:.2f} CPU s ({'compiled path' if law == 'lugre' else 'general path: plain Python force'})")
    unit_after = refunit.unit()
    print(f"reference unit after: {unit_after:.2f} CPU s; {refunit.load()}")


if __name__ == "__main__":
    main()
