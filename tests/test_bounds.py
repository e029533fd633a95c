"""A parameter that ends at a bound of its range is reported there, in every view, and never as identifiable."""
import json
import re
from pathlib import Path

import pytest

from frictionlab import fit, load_dataset
from frictionlab.inference.diagnostics.identifiability import AT_BOUND_MEANING, at_bounds, bound_side, bounds_text
from frictionlab.inference.verdicts.ranking import fit_row, to_csv
from frictionlab.report.results import fit_json

KT = Path(__file__).resolve().parent.parent / "examples" / "known-truth"


def test_the_side_of_a_bound_is_relative_to_a_nonzero_bound_and_to_the_scale_at_zero():
    assert bound_side(997_389.0, 1e3, 1e6, 1e4) == "upper"  # 0.26% below a bound of 1e6: at it
    assert bound_side(1.5e3, 1e3, 1e6, 1e4) == ""
    assert bound_side(1.001e3, 1e3, 1e6, 1e4) == "lower"
    assert bound_side(1655.0, 0.0, 1e9, 1e6) == ""  # 1.7e-3 scales above a bound of 0: determined
    assert bound_side(50.0, 0.0, 1e9, 1e6) == "lower"


@pytest.fixture(scope="module")
def pressed():
    """wear on data of u0 = 12 m/s with u0 free but held below 11.9 m/s: the fit ends at that bound."""
    return fit("wear", load_dataset(KT / "kt-wear-impact.toml"), free={"u0": (5.0, 11.9)})


def test_a_parameter_pressed_against_its_bound_is_reported_there_in_every_view(pressed):
    (hit,) = at_bounds(pressed)
    assert hit.side == "upper" and hit.bound == 11.9 and hit.value == pytest.approx(11.9, rel=0.01)
    p = pressed.params[hit.name]
    assert p.at_bound == "upper" and p.stderr is None  # a bound's value has no error bar
    assert pressed.identifiability.verdict != "identifiable"
    assert "parameter at a bound" in pressed.identifiability.verdict
    assert any("at its upper bound (11.9 m/s)" in w and AT_BOUND_MEANING in w for w in pressed.identifiability.warnings)
    assert re.search(rf"{re.escape(hit.name)} = 11\.9\d* m/s \(at its upper bound 11\.9\d* m/s: not identifiable\)",
                     repr(pressed))
    assert re.search(r"at its upper bound 11\.9\d* m/s: not identifiable", pressed.summary())
    assert re.search(r"is at its upper bound 11\.9\d* m/s", bounds_text(pressed))
    row = fit_row(pressed)
    assert row.at_bounds == (f"{hit.name} at upper bound 11.9 m/s",)
    header, line = to_csv([row]).splitlines()
    assert line.split(",")[header.split(",").index("at_bounds")] == f"{hit.name} at upper bound 11.9 m/s"
    j = json.loads(json.dumps(fit_json(pressed), default=str))
    assert j["parameters"][hit.name]["at_bound"] == "upper"
    assert j["identifiability"]["bounds"][0]["side"] == "upper" and j["identifiability"]["bounds"][0]["bound"] == 11.9
    assert pressed.to_dataframe().set_index("parameter").loc[hit.name, "at_bound"] == "upper"
    from frictionlab.report.fits import param_rows

    (comment,) = [r[-1] for r in param_rows(pressed) if r[1] == hit.name]
    assert re.match(r"at its upper bound 11\.9\d* m/s: not identifiable", comment)


def test_a_parameter_inside_its_range_is_not_at_a_bound():
    f = fit("wear", load_dataset(KT / "kt-wear-impact.toml"), free={"u0": (5.0, 20.0)})
    assert at_bounds(f) == () and all(not p.at_bound for p in f.params.values())
    assert "bound" not in f.identifiability.verdict and fit_row(f).at_bounds == ()
