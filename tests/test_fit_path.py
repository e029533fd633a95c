"""The lean fit path gives the answers of the general one: each shortcut against the long way round."""
import math

import pytest

from _fit_helpers import TRUTH, incline_scene, synthetic
from frictionlab import fit


def test_an_ode_fit_in_a_valley_pays_for_one_start_and_says_so():
    """Couette's eta and h enter only as eta/h: the first start ends on that valley, a second would too."""
    data = synthetic("couette", TRUTH["couette"], incline_scene(), n=21, name="incline-couette")
    one = fit("couette", data, solver="ode")
    two = fit("couette", data, solver="ode", n_starts=1)  # the general path with a single start, for the count
    exact = fit("couette", data, solver="exact")
    assert one.ok and any("one Levenberg-Marquardt start of 2" in n and "correlated" in n for n in one.notes)
    assert one.nfev == two.nfev  # the second start was not run
    ratio, ref = one.params["eta/h"], exact.params["eta/h"]
    assert abs(ratio.value - ref.value) <= 0.01 * ref.stderr
    assert one.stats.chisqr == pytest.approx(exact.stats.chisqr, rel=1e-6)


def test_a_well_determined_ode_fit_still_runs_every_start():
    data = synthetic("wear", TRUTH["wear"], incline_scene(), n=21, name="incline-wear")
    r = fit("wear", data, solver="ode")
    assert r.ok and not any("Levenberg-Marquardt start" in n for n in r.notes)
    assert math.isclose(r.value("lam"), fit("wear", data, solver="exact").value("lam"), rel_tol=1e-4)


@pytest.mark.parametrize("law, params", [("coulomb", {"mu": 0.25}), ("wear", {"lam": 1e6}),
                                         ("area-rate", {"mu": 0.2, "eta_prime": 1e3}),
                                         ("couette", {"eta": 0.1, "h": 1e-7})])
def test_impact_outcomes_on_the_batch_engine_equal_the_row_by_row_solve(law, params):
    import numpy as np

    from frictionlab import get_law, load_dataset
    from frictionlab.outcome import _rebounds, rows_of

    ds = load_dataset("impact-outcome-synthetic")
    rows = rows_of(ds)
    imps = [ds.scene.impact(float(a), float(b), float(c)) for a, b, c in zip(rows["speed"], rows["incidence"], rows["spin"])]
    p = get_law(law).resolve(params)
    v2, w2, rolled = _rebounds(law, imps, p, "exact", 1e-6)  # all rows in one batch
    alone = [_rebounds(law, [imp], p, "exact", 1e-6) for imp in imps]  # one row at a time: the scalar solver
    assert np.allclose(v2, [a[0][0] for a in alone], rtol=1e-12, atol=1e-12 * np.max(np.abs(v2)))
    assert np.allclose(w2, [a[1][0] for a in alone], rtol=1e-12, atol=1e-12 * np.max(np.abs(w2)))
    assert list(rolled) == [bool(a[2][0]) for a in alone]
    if law == "coulomb":
        assert 0 < rolled.sum() < len(imps)  # both kinds of row are exercised
