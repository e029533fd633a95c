r"""# A velocity step, fitted, and its residuals

In a velocity-step test the load point's velocity jumps and friction answers with a direct jump of size
$a \ln(V_2/V_1)$ and an evolution over a slip distance $D_c$ to its new steady state, $(a - b)\ln(V_2/V_1)$
from the old one. `basalt-velstep4` is *measured* (Giacomel et al. 2024, MIT; 5,849 samples at 10 and then
100 Hz), read where the records are present (a `shared/data/steadystate/` folder beside the repository, or
the folders named in `FRICTIONLAB_RAW_DATA`).
"""

# %%
# Fit the aging law the way rate-and-state laboratories do: every sample, the machine stiffness $k$ fitted,
# a linear trend of friction with displacement solved jointly, and the noise taken as correlated. The
# summary gives $a$, $b$, $a - b$, $D_c$ and $k$ with their intervals, the noise model the likelihood used,
# and whether the law fits. Without the record the example says where it looked and stops.
import frictionlab as fl

try:
    data = fl.load_dataset("basalt-velstep4")
except fl.FrictionLabError as exc:
    data = None
    print(f"the basalt record is not here: {exc}")
if data is not None:
    print(data, "-", data.provenance.kind)
    f = fl.fit("rate-state-aging", data)
    print(f.summary())

# %%
# The parameters in laboratory units, each with its standard error: $D_c$ in µm, $k$ in 1/µm (per unit
# normal stress).
if data is not None:
    for name, q in f.velstep.rows[0].quantities.items():
        print(f"{name:>5}: {q.value:.5g} ± {q.stderr if q.stderr is not None else float('nan'):.2g} {q.unit}")

# %%
# The fit's own figure: friction and the fitted curve above, the residuals below. Residuals without
# structure around the step are what "fits" means; a wave that follows the step is a misfit of the law.
# Here the aging law does not fit: the summary above names the tests that reject it, notes that the noise is
# not AR(1) either (the prewhitened residuals keep a lag-1 autocorrelation) and that the sign of $a - b$
# depends on the trend. The residuals' spread also grows where the sampling rate changes from 10 to 100 Hz.
if data is not None:
    fig = f.plot()
    fig.set_size_inches(10, 6)   # room for the legend's verdict line
    fig.tight_layout()
