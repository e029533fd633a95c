"""# Your own impact, from the template

`frictionlab datasets template impact --name ball-a` writes a commented dataset (`ball-a.toml`, the scene,
units, noise and provenance; `ball-a.csv`, the measured series) that loads as it is. Replace its example rows
with your measurements and it is ready. Here the template's own rows are used: they are computed from the wear
law on the template's scene (the file says so), so the wear law fits them almost exactly and every number
below is the template's, not a measurement.
"""

# %%
# Write the template pair into the current folder (the example runs in a fresh temporary folder) and load
# it: the dataset says its kind, its observable and how many points it has.
import subprocess
import sys
from pathlib import Path

import frictionlab as fl

cli = Path(sys.executable).with_name("frictionlab")
print(subprocess.run([str(cli), "datasets", "template", "impact", "--name", "ball-a"],
                     capture_output=True, text=True, check=True).stdout)
mine = fl.load_dataset("ball-a.toml")
print(mine, "-", mine.noise_note)

# %%
# Compare three laws on it. What the table shows: each candidate's rank by AIC, whether it fits (both its
# goodness-of-fit tests pass) and its reduced chi-square. A law is called best only when it fits.
c = fl.compare(laws=["wear", "area-rate", "coulomb"], datasets=[mine], equivalence=False)
table = c.to_dataframe()
print(table[table.dataset == "ball-a"][["candidate", "rank", "fits", "redchi"]].to_string(index=False))

# %%
# The wear law's exact-solution fit, as the comparison made it, drawn by its own `plot()`: data and fitted curve
# above, residuals below. Residuals that wander in long runs of one sign are what the runs test reads as a misfit
# of shape.
best = next(f for f in c.fits if f.law == "wear" and f.solver == "exact")
print(best.summary())
best.plot()
