"""Does the equivalence verdict depend on the Monte-Carlo seed? incline-oil-a400 (Couette truth, one curve with
wear) tested as compare tests it, wear against area-rate and Coulomb against wear, at seeds 0..N-1:

    python benchmarks/seed_stability.py [N=8]

Prints each verdict with the true law's (wear's) own p and why sampling stopped, then how often that p is
below 0.05 and how often the two-sided rule rejects the true law.
"""
import sys
from frictionlab import load_dataset, fit, analyze_equivalence
ds = load_dataset("incline-oil-a400")
fw, fa, fc = fit("wear", ds), fit("area-rate", ds), fit("coulomb", ds)
n_rule = n_05 = n = 0
for seed in range(int(sys.argv[1]) if len(sys.argv) > 1 else 8):
    for a, b, truth_side in ((fw, fa, "a"), (fc, fw, "b")):
        e = analyze_equivalence(a, b, seed=seed)
        p = e.p_a if truth_side == "a" else e.p_b
        n += 1; n_05 += p < 0.05; n_rule += (e.p < 0.05 and p == min(e.p_a, e.p_b))
        print(seed, e.label, e.verdict, f"p(wear)={p:.3g}", f"p={e.p:.2g}", e.stopped, "|", e.explanation.split(':')[-1][:120], flush=True)
print(f"true law (wear) p < 0.05 in {n_05} of {n}; rejected by the rule in {n_rule} of {n}")
