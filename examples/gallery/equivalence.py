r"""# Equivalence within a margin

"Not rejected" is not "equivalent": a test without power rejects nothing. frictionlab gives one of three
answers for two laws fitted to one dataset: *different*, *equivalent within* $\delta$ (an upper confidence bound
of the RMS distance between the two fitted curves lies below the margin $\delta$, in the observable's unit), or
*cannot tell at this noise*. The data here are the lubricated incline `incline-oil-a100` (*synthetic*, drawn
from Couette friction, known noise).
"""

# %%
# Three laws, every pair tested, with 40 replicate datasets per law (the report's default is more; fewer keep
# this example quick, and the p-values are then coarser). What the output shows: each pair's verdict, the
# margin, the distance between the curves and its upper bound. Wear and Couette are one closed-form family
# (one curve), so they are equivalent at any margin; Coulomb's velocity cannot level off as the data do.
import frictionlab as fl

c = fl.compare(laws=["wear", "couette", "coulomb"], datasets=["incline-oil-a100"], replicates=40)
for e in c.equivalence:
    print(f"{e.label}: {e.verdict} ({e.margin_text}; distance {e.quantity(e.rms)}, bound {e.quantity(e.upper)})")

# %%
# A margin is a claim about what difference matters, stated before looking: here two noise sigmas instead of
# one. A wider margin can turn "cannot tell" into "equivalent", never "different" into "equivalent".
wide = fl.compare(laws=["wear", "coulomb"], datasets=["incline-oil-a100"], replicates=40, margin=2)
for e in wide.equivalence:
    print(f"{e.label}: {e.verdict} ({e.margin_text})")
