r"""# A whole laboratory record with several steps

The sepiolite experiment of Giacomel et al. (2024, MIT) is *measured*: one run with three velocity steps,
each read as its own dataset (`sepiolite-velstep1`, `-2`, `-3`) when the records are present (a
`shared/data/steadystate/` folder beside the repository, or the folders named in `FRICTIONLAB_RAW_DATA`).
This example fits the aging and the slip law to every step, each step on its own, and sets the parameters side
by side: one record should give one material's $a$, $b$ and $D_c$.
"""

# %%
# Which steps are present, with their size. Without the records the example says where it looked and stops.
import matplotlib.pyplot as plt

import frictionlab as fl

names = [f"sepiolite-velstep{i}" for i in (1, 2, 3)]
try:
    steps = [fl.load_dataset(name) for name in names]
except fl.FrictionLabError as exc:
    steps = []
    print(f"the sepiolite records are not here: {exc}")
for d in steps:
    print(d, "-", d.provenance.kind)

# %%
# Fit both state laws to each step. What the table shows: per step and law, $a - b$ (the sign says whether
# sepiolite strengthens or weakens with velocity), $D_c$ in µm, and whether the law fits. On these records
# the slow wander of the friction is a real misfit for both laws (see
# [correlated noise](../science/correlated-noise.md)): read the parameters as the best a law can do.
rows = []
for d in steps:
    for law in ("rate-state-aging", "rate-state-slip"):
        f = fl.fit(law, d)
        q = f.velstep.rows[0].quantities
        rows.append((d.name, law, q["a-b"].value, q["a-b"].stderr, q["Dc"].value, f.goodness.fits, f))
        print(f"{d.name:>19} {law:>16}: a - b = {q['a-b'].value:+.5f} ± {q['a-b'].stderr:.5f}, "
              f"Dc = {q['Dc'].value:7.2f} µm, {'fits' if f.goodness.fits else 'does not fit'}")

# %%
# $a - b$ of each step by each law. Steps of one record whose intervals do not overlap say that one parameter
# set does not describe the whole run, a question a joint fit of the record's whole load-point history asks.
if rows:
    fig, ax = plt.subplots(figsize=(7, 3.5), layout="constrained")
    for k, law in enumerate(("rate-state-aging", "rate-state-slip")):
        mine = [r for r in rows if r[1] == law]
        ax.errorbar([i + 0.1 * (2 * k - 1) for i in range(len(mine))], [r[2] for r in mine],
                    yerr=[2 * r[3] for r in mine], fmt="o", capsize=3, label=law)
    ax.set_xticks(range(len(steps)), [d.name for d in steps])
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_ylabel("a - b (± 2 standard errors)")
    ax.legend()
