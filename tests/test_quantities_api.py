"""One way to give a quantity: every API entry point that takes a parameter value, bound or start accepts an
SI float, a quantity string and a pint Quantity (and, where a range is meant, the command line's 'low:high'
form or a tuple of any of the three), and gives the same numbers for each; an error names the parameter and
the unit it expected."""
from __future__ import annotations

import numpy as np
import pint
import pytest

import frictionlab as fl
from frictionlab.core.errors import FrictionLabError
from frictionlab.solve.batch import simulate_batch

UREG = pint.UnitRegistry()
LAM = {"float": 1.6e6, "string": "1.6 MPa s/m", "quantity": 1.6e6 * UREG("Pa s/m")}
U0 = {"float": (9.0, 13.0), "string": "9 m/s:13 m/s", "tuple of strings": ("9 m/s", "13 m/s"),
      "tuple of quantities": (9.0 * UREG("m/s"), 46.8 * UREG("km/h")), "mixed tuple": (9.0, "13 m/s")}


@pytest.fixture(scope="module")
def golf():
    return fl.load_dataset("impact-golf-v28")


def _simulate(golf, v):
    return fl.simulate("wear", golf, {"lam": v}, solver="exact").omega


def _batch(golf, v):
    return simulate_batch("wear", [golf.scene] * 2, {"lam": v}, solver="exact", n=11).omega


def _resolve(golf, v):
    return np.array([fl.get_law("wear").resolve({"lam": v})["lam"]])


def _fit_initial(golf, v):
    return np.array([fl.fit("wear", golf, solver="exact", initial={"lam": v}, scan=0, n_starts=1).value("lam")])


def _fit_fixed(golf, v):
    return np.array([fl.fit("wear", golf, solver="exact", fixed={"lam": v}, free={"u0": (9.0, 13.0)}).value("u0")])


VALUE_ENTRY_POINTS = {"simulate params": _simulate, "simulate_batch params": _batch, "law.resolve": _resolve,
                      "fit initial": _fit_initial, "fit fixed": _fit_fixed}


@pytest.mark.parametrize("entry", VALUE_ENTRY_POINTS)
@pytest.mark.parametrize("form", ["string", "quantity"])
def test_a_value_in_every_form_gives_the_same_numbers(golf, entry, form):
    call = VALUE_ENTRY_POINTS[entry]
    np.testing.assert_allclose(call(golf, LAM[form]), call(golf, LAM["float"]), rtol=1e-12)


def _fit_free(golf, v):
    r = fl.fit("wear", golf, solver="exact", free={"u0": v})
    return np.array([r.value("lam"), r.value("u0"), r.params["u0"].lower, r.params["u0"].upper])


def _compare_free(golf, v):
    c = fl.compare(laws=["wear"], datasets=[golf], solvers=["exact"], free={"u0": v}, equivalence=False,
                   transfer=False)
    p = c.fits[0].params["u0"]
    return np.array([p.value, p.lower, p.upper])


RANGE_ENTRY_POINTS = {"fit free": _fit_free, "compare free": _compare_free}


@pytest.mark.parametrize("entry", RANGE_ENTRY_POINTS)
@pytest.mark.parametrize("form", [f for f in U0 if f != "float"])
def test_a_range_in_every_form_gives_the_same_numbers(golf, entry, form):
    call = RANGE_ENTRY_POINTS[entry]
    np.testing.assert_allclose(call(golf, U0[form]), call(golf, U0["float"]), rtol=1e-12)


@pytest.mark.parametrize("call, match", [
    (lambda g: fl.simulate("wear", g, {"lam": "1.6e6 m/s"}), r"lam: '1.6e6 m/s' is .*expected .*'1 Pa s/m'"),
    (lambda g: fl.simulate("wear", g, {"lam": 2 * UREG.second}), r"lam .*expected .*Pa s/m"),
    (lambda g: fl.fit("wear", g, initial={"lam": "1.5e6 m/s"}), r"fit: initial: lam: .*'1 Pa s/m'"),
    (lambda g: fl.fit("wear", g, initial={"lam": [1.0]}), r"fit: initial: lam: expected a number in SI, a quantity"),
    (lambda g: fl.fit("wear", g, fixed={"lam": "1e6"}), r"fit: fixed: lam: '1e6' has no unit; write it like '1e6 Pa s/m'"),
    (lambda g: fl.fit("wear", g, free={"u0": "9:13"}), r"fit: free: u0: '9' has no unit.*m/s"),
    (lambda g: fl.fit("wear", g, free={"u0": "13 m/s:9 m/s"}), r"fit: free: u0: lower bound '13 m/s' must be below"),
    (lambda g: fl.fit("wear", g, free={"u0": ("9 m/s", "13 m/s", "20 m/s")}), r"fit: free: u0: start '20 m/s' is outside"),
    (lambda g: fl.fit("wear", g, free={"u0": (9 * UREG("s"), 13.0)}), r"fit: free: u0 .*expected .*m/s"),
    (lambda g: fl.fit("wear", g, free={"speed": (1, 2)}), r"fit: free: 'speed' is not a scene quantity"),
    (lambda g: fl.compare(laws=["wear"], datasets=[g], free={"u0": "9 m/s"}), r"compare: free: u0: .*LOWER:UPPER"),
    (lambda g: simulate_batch("wear", [g.scene], {"lam": "3 kg"}), r"law 'wear': lam: '3 kg' is \[mass\]"),
])
def test_an_error_names_the_parameter_and_the_unit(golf, call, match):
    with pytest.raises(FrictionLabError, match=match):
        call(golf)


def test_the_command_line_reads_ranges_as_the_api_does():
    from frictionlab.commands.fit import parse_free

    assert parse_free(["u0=9 m/s:13 m/s:10 m/s"]) == {"u0": (9.0, 13.0, 10.0)}
