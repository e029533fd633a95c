"""Units read without pint (``core.units.KNOWN``) convert exactly as pint converts them, to the last bit; any
other unit is still pint's to read or refuse; the built-in data are read without importing pint."""
import functools
import subprocess
import sys

import numpy as np
import pint
import pytest

from frictionlab.core import units
from frictionlab.core.errors import UnitError

PAIRS = [(si, unit) for si, table in units.KNOWN.items() for unit in table]


@functools.cache
def _pint():
    return pint.UnitRegistry(autoconvert_offset_to_baseunit=True)


def _pint_si(text: str, si: str) -> float:
    u = _pint()
    target = u.Quantity(1.0, si) if si else u.Quantity(1.0)
    q = u.Quantity(text)
    q = q if hasattr(q, "dimensionality") else u.Quantity(float(q))
    return float(q.to(target.units).magnitude)


@pytest.mark.parametrize("si, unit", PAIRS, ids=[f"{u or 'plain'}->{s or 'plain'}" for s, u in PAIRS])
def test_each_known_unit_converts_as_pint_does(si, unit):
    u = _pint()
    given = u.Quantity(1.0, unit) if unit else u.Quantity(1.0)
    target = u.Quantity(1.0, si) if si else u.Quantity(1.0)
    assert units.unit_factor(unit, si, "f") == float(given.to(target.units).magnitude)
    rng = np.random.default_rng(len(PAIRS) + PAIRS.index((si, unit)))
    values = [repr(float(v)) for v in rng.uniform(-5, 5, 40) * 10.0 ** rng.integers(-8, 9, 40)]
    values += ["0", "46", "0.13327", "1.81e+06", "-0.2", ".5", "3."]
    for v in values:
        text = f"{v} {unit}".strip()
        if si and float(v) == 0:
            continue  # pint's zero of an offset-free unit is 0 either way
        assert units.to_si(text, si, "f") == _pint_si(text, si), text


def test_other_units_are_still_read_and_refused_by_pint():
    assert units.to_si("2 lb", "kg", "m") == pytest.approx(0.90718474)
    assert units.to_si("1 inch/s", "m/s", "u0") == pytest.approx(0.0254)
    assert units.unit_factor("ft", "m", "col") == pytest.approx(0.3048)
    with pytest.raises(UnitError, match="u0: '30' has no unit"):
        units.to_si("30", "m/s", "u0")
    with pytest.raises(UnitError, match="x: '3 deg' is dimensionless, expected \\[length\\]"):
        units.to_si("3 deg", "m", "x")
    with pytest.raises(UnitError, match="is an angle"):
        units.to_si("3 deg", "", "ratio")
    with pytest.raises(UnitError, match="has no angle unit"):
        units.to_si("3 Hz", "rad/s", "omega0")
    with pytest.raises(UnitError, match="unit 'mm' is \\[length\\], expected \\[time\\]"):
        units.unit_factor("mm", "s", "t")


def test_the_built_in_data_are_read_without_pint():
    code = ("import sys\nfrom frictionlab.io.dataset import available_names, load_dataset\n"
            "ds = [load_dataset(n) for n in available_names()]\nprint(len(ds), 'pint' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert int(out[0]) > 10 and out[1] == "False"
