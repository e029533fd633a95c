"""Property tests of the dataset boundary (hypothesis).

- Unit invariance: the same data written in other units loads to the same SI arrays and scene,
  and fits to the same parameters. The conversion factors here are written out by hand, not
  taken from pint, so that a wrong factor in frictionlab cannot cancel itself out.
- The loader never crashes on fuzzed CSV or TOML: it loads, or raises a one-line
  FrictionLabError subclass; never another exception type.
"""
from __future__ import annotations

import copy
import datetime
import math
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import frictionlab as fl
from frictionlab.core.errors import FrictionLabError
from frictionlab.io.dataset import builtin_dir, from_meta

RPM = 2 * math.pi / 60
#: unit -> SI factor, by hand
TIME = {"s": 1.0, "ms": 1e-3, "us": 1e-6}
SPIN = {"rad/s": 1.0, "rpm": RPM, "deg/s": math.pi / 180, "rps": 2 * math.pi}
ANGLE = {"rad": 1.0, "deg": math.pi / 180, "turn": 2 * math.pi}
AREA = {"m^2": 1.0, "mm^2": 1e-6, "cm^2": 1e-4}
SPEED = {"m/s": 1.0, "mm/s": 1e-3, "km/h": 1 / 3.6, "cm/s": 1e-2}
MASS = {"kg": 1.0, "g": 1e-3}
LENGTH = {"m": 1.0, "mm": 1e-3, "cm": 1e-2}

FUZZ = settings(deadline=None, max_examples=120, suppress_health_check=[HealthCheck.too_slow,
                                                                        HealthCheck.function_scoped_fixture])


def _write_golf(folder: Path, name: str, data: dict, u: dict, scene_units: dict) -> Path:
    """A golf-impact dataset with SI ``data`` written in units ``u``; returns the TOML path."""
    cols = ["t", "omega", "theta"]
    lines = [",".join(cols)]
    for row in zip(*(data[c] / FACTORS[c][u[c]] for c in cols)):
        lines.append(",".join(repr(float(x)) for x in row))
    (folder / f"{name}.csv").write_text("\n".join(lines) + "\n")
    q = lambda si, table, unit: f"{si / table[unit]!r} {unit}"  # noqa: E731
    mu, lu, su, au, tu = scene_units["mass"], scene_units["length"], scene_units["speed"], scene_units["area"], \
        scene_units["time"]
    (folder / f"{name}.toml").write_text(f"""
name = "{name}"
kind = "impact"
observable = "omega"

[columns]
t = "{u['t']}"
omega = "{u['omega']}"
theta = "{u['theta']}"

[noise]
kind = "known"
omega = "{q(20.0, SPIN, u['omega'])}"

[scene]
mass = "{q(0.046, MASS, mu)}"
radius = "{q(0.0213, LENGTH, lu)}"
u0 = "{q(12.0, SPEED, su)}"
effects = ["spin"]

[scene.area]
model = "half-sine"
peak = "{q(130e-6, AREA, au)}"
contact_time = "{q(500e-6, TIME, tu)}"

[scene.normal]
model = "half-sine"
normal_speed = "{q(24.2487, SPEED, su)}"
restitution = 0.8

[provenance]
kind = "synthetic"
source = "test"
command = "pytest"
""")
    return folder / f"{name}.toml"


FACTORS = {"t": TIME, "omega": SPIN, "theta": ANGLE}
SI_UNITS = {"t": "s", "omega": "rad/s", "theta": "rad"}
SI_SCENE = {"mass": "kg", "length": "m", "speed": "m/s", "area": "m^2", "time": "s"}


@given(
    u=st.fixed_dictionaries({"t": st.sampled_from(list(TIME)), "omega": st.sampled_from(list(SPIN)),
                             "theta": st.sampled_from(list(ANGLE))}),
    scene_units=st.fixed_dictionaries({"mass": st.sampled_from(list(MASS)), "length": st.sampled_from(list(LENGTH)),
                                       "speed": st.sampled_from(list(SPEED)), "area": st.sampled_from(list(AREA)),
                                       "time": st.sampled_from(list(TIME))}),
    steps=st.lists(st.floats(1e-6, 1e-4), min_size=2, max_size=30),
    seed=st.integers(0, 2**32 - 1),
)
@settings(deadline=None, max_examples=40)
def test_same_data_in_other_units_loads_to_the_same_si(tmp_path_factory, u, scene_units, steps, seed):
    folder = tmp_path_factory.mktemp("units")
    rng = np.random.default_rng(seed)
    t = np.concatenate([[0.0], np.cumsum(steps)])
    data = {"t": t, "omega": rng.normal(0, 700, t.size), "theta": rng.normal(0, 0.3, t.size)}
    a = fl.load_dataset(_write_golf(folder, "si", data, SI_UNITS, SI_SCENE))
    b = fl.load_dataset(_write_golf(folder, "other", data, u, scene_units))
    for col in ("t", "omega", "theta"):
        np.testing.assert_allclose(b.columns[col], a.columns[col], rtol=1e-13, atol=0)
        np.testing.assert_allclose(a.columns[col], data[col], rtol=1e-13, atol=0)
    assert b.sigma == pytest.approx(a.sigma, rel=1e-13) and a.sigma == pytest.approx(20.0, rel=1e-13)
    sa, sb = a.scene, b.scene
    for attr in ("mass", "radius", "u0", "duration"):
        assert getattr(sb, attr) == pytest.approx(getattr(sa, attr), rel=1e-13)
    assert sb.area.peak == pytest.approx(130e-6, rel=1e-13) and sa.area.peak == pytest.approx(130e-6, rel=1e-13)
    assert sb.normal.impulse == pytest.approx(sa.normal.impulse, rel=1e-13)


@pytest.mark.parametrize("base, law, edits", [
    # spin in rpm and time in us (as shipped) against rad/s and s
    ("impact-golf-v28", "wear", {"t": ("us", "s", 1e-6), "omega": ("rpm", "rad/s", RPM), "theta": ("deg", "rad", math.pi / 180)}),
    # speed in m/s and time in s against mm/s and ms; the contact area in mm^2 against m^2
    ("incline-oil-a100", "couette", {"t": ("s", "ms", 1e3), "v": ("m/s", "mm/s", 1e3)}),
])
def test_same_data_in_other_units_fits_to_the_same_parameters(tmp_path, base, law, edits):
    for ext in ("toml", "csv"):
        shutil.copy(builtin_dir() / f"{base}.{ext}", tmp_path / f"d.{ext}")
    toml, csv = tmp_path / "d.toml", tmp_path / "d.csv"
    text = toml.read_text()
    lines = [x for x in csv.read_text().splitlines() if not x.startswith("#")]
    header = lines[0].split(",")
    rows = [list(map(float, x.split(","))) for x in lines[1:]]
    for col, (old, new, factor) in edits.items():
        assert f'{col} = "{old}"' in text
        text = text.replace(f'{col} = "{old}"', f'{col} = "{new}"', 1)
        i = header.index(col)
        for r in rows:
            r[i] = r[i] * factor  # value in the new unit, by a hand-written factor
    if base.startswith("incline"):
        text = text.replace('area = "100 mm^2"', 'area = "1e-4 m^2"', 1)
        text = text.replace('v = "3 mm/s"', 'v = "0.003 m/s"', 1)
    toml.write_text(text)
    csv.write_text(",".join(header) + "\n" + "\n".join(",".join(repr(x) for x in r) for r in rows) + "\n")
    a, b = fl.load_dataset(base), fl.load_dataset(toml)
    for col in a.columns:
        np.testing.assert_allclose(b.columns[col], a.columns[col], rtol=1e-12)
    from frictionlab.inference.fitting.fit import fit

    fa, fb = fit(law, a), fit(law, b)
    assert fa.ok and fb.ok
    for name, p in fa.params.items():
        assert fb.params[name].value == pytest.approx(p.value, rel=1e-6), name
    assert fb.stats.chisqr == pytest.approx(fa.stats.chisqr, rel=1e-6)


# -- fuzzing ---------------------------------------------------------------------------------
def _load_or_clear_error(path: Path):
    try:
        fl.load_dataset(path)
    except FrictionLabError as exc:
        msg = str(exc)
        assert msg and "\n" not in msg and "\r" not in msg, repr(msg)


CSV_ALPHABET = "0123456789.,-+eE \n\r\t#\"';:xnaifNI_/"


@pytest.fixture(scope="module")
def golf_folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzz")
    for ext in ("toml", "csv"):
        shutil.copy(builtin_dir() / f"impact-golf-v28.{ext}", folder / f"g.{ext}")
    return folder


@given(text=st.text(alphabet=CSV_ALPHABET, max_size=300))
@FUZZ
def test_loader_never_crashes_on_fuzzed_csv_text(golf_folder, text):
    (golf_folder / "g.csv").write_text("t,omega,theta\n" + text, encoding="utf-8")
    _load_or_clear_error(golf_folder / "g.toml")


@given(data=st.binary(max_size=200))
@FUZZ
def test_loader_never_crashes_on_fuzzed_csv_bytes(golf_folder, data):
    (golf_folder / "g.csv").write_bytes(data)
    _load_or_clear_error(golf_folder / "g.toml")


GOLF_CSV = (builtin_dir() / "impact-golf-v28.csv").read_text()
GOLF_TOML = (builtin_dir() / "impact-golf-v28.toml").read_text()


@st.composite
def mutated(draw, text: str, alphabet: str):
    """``text`` with a few characters deleted, replaced or inserted, or a line dropped or doubled."""
    lines = text.splitlines(keepends=True)
    for _ in range(draw(st.integers(1, 4))):
        op = draw(st.sampled_from(["delete", "replace", "insert", "drop-line", "double-line"]))
        joined = "".join(lines)
        i = draw(st.integers(0, max(len(joined) - 1, 0)))
        ch = draw(st.sampled_from(alphabet))
        if op == "delete":
            joined = joined[:i] + joined[i + 1:]
        elif op == "replace":
            joined = joined[:i] + ch + joined[i + 1:]
        elif op == "insert":
            joined = joined[:i] + ch + joined[i:]
        lines = joined.splitlines(keepends=True)
        if op in ("drop-line", "double-line") and lines:
            j = draw(st.integers(0, len(lines) - 1))
            lines = lines[:j] + lines[j + 1:] if op == "drop-line" else lines[:j + 1] + lines[j:]
    return "".join(lines)


@given(text=mutated(GOLF_CSV, CSV_ALPHABET))
@FUZZ
def test_loader_never_crashes_on_mutated_csv(golf_folder, text):
    (golf_folder / "g.csv").write_text(text, encoding="utf-8")
    (golf_folder / "g.toml").write_text(GOLF_TOML)
    _load_or_clear_error(golf_folder / "g.toml")


@given(text=mutated(GOLF_TOML, "[]{}=\"'.,#\n 0123456789abcdefgmsuk^/-_"))
@FUZZ
def test_loader_never_crashes_on_mutated_toml(golf_folder, text):
    (golf_folder / "g.csv").write_text(GOLF_CSV)
    (golf_folder / "g.toml").write_text(text, encoding="utf-8")
    _load_or_clear_error(golf_folder / "g.toml")


# structured fuzz: any TOML value in any place of a valid dataset's table
toml_scalars = st.one_of(
    st.text(max_size=12), st.sampled_from(["46 g", "-1 m/s", "nan s", "1e400 m", "rpm", "", "half-sine", "omega",
                                           "1 Hz", "30 deg", "inf", "0 m^2", "spin", "t"]),
    st.integers(-10**20, 10**20), st.floats(allow_nan=True), st.booleans(),
    st.dates(), st.datetimes(), st.times())
toml_values = st.recursive(toml_scalars, lambda inner: st.one_of(
    st.lists(inner, max_size=3), st.dictionaries(st.text(max_size=8), inner, max_size=3)), max_leaves=6)

GOLF_META = tomllib.loads(GOLF_TOML)
INCLINE_META = tomllib.loads((builtin_dir() / "incline-oil-a100.toml").read_text())


#: Keys a dataset may have, present in the base or not: the fuzz sets them too.
SCHEMA = [("name",), ("kind",), ("observable",), ("description",), ("columns",), ("noise",), ("scene",),
          ("fixed",), ("provenance",), ("reported",), ("columns", "t"), ("noise", "omega"), ("noise", "v"),
          ("scene", "mass"), ("scene", "radius"), ("scene", "u0"), ("scene", "omega0"), ("scene", "duration"),
          ("scene", "incline"), ("scene", "effects"), ("scene", "inertia_factor"), ("scene", "area"),
          ("scene", "normal"), ("scene", "compliance"), ("provenance", "kind"), ("provenance", "source"),
          ("provenance", "command"), ("provenance", "seed"), ("provenance", "truth"), ("provenance", "method"),
          ("fixed", "eta"), ("fixed", "lam"), ("fixed", "mu")]


def _paths(meta, prefix=()):
    out = []
    for k, v in meta.items():
        out.append(prefix + (k,))
        if isinstance(v, dict):
            out += _paths(v, prefix + (k,))
    return out


@given(which=st.sampled_from(["golf", "incline"]), data=st.data())
@settings(FUZZ, max_examples=300)
def test_loader_never_crashes_on_any_value_anywhere(which, data):
    meta = copy.deepcopy(GOLF_META if which == "golf" else INCLINE_META)
    base = "impact-golf-v28" if which == "golf" else "incline-oil-a100"
    for _ in range(data.draw(st.integers(1, 3))):
        path = data.draw(st.sampled_from(sorted(set(_paths(meta)) | set(SCHEMA))))
        table = meta
        for k in path[:-1]:
            table = table.get(k) if isinstance(table, dict) else None
        if not isinstance(table, dict):
            continue
        if data.draw(st.integers(0, 3)):
            table[path[-1]] = data.draw(toml_values)
        else:
            table.pop(path[-1], None)
    try:
        from_meta(meta, builtin_dir() / f"{base}.toml")
    except FrictionLabError as exc:
        assert "\n" not in str(exc)


WRONG = [0, -1, 3.5, float("nan"), True, [], [1, "x"], {}, {"model": "x"}, "", "junk", "-5 kg", "1 Hz",
         datetime.date(2020, 1, 1)]


@pytest.mark.parametrize("base", ["impact-golf-v28", "incline-oil-a100"])
def test_every_field_with_every_wrong_type_is_a_clear_error(base, monkeypatch):
    """A systematic sweep beside the random fuzz: each known field, set to each kind of wrong value
    (or removed), loads or fails with a one-line FrictionLabError."""
    from frictionlab.io import dataset

    csv = dataset.read_csv(builtin_dir() / f"{base}.csv")  # the TOML is under test here, not the CSV
    monkeypatch.setattr(dataset, "read_csv", lambda path: {k: v.copy() for k, v in csv.items()})
    meta0 = tomllib.loads((builtin_dir() / f"{base}.toml").read_text())
    crashes = []
    for path in SCHEMA:
        for value in WRONG + [None]:
            meta = copy.deepcopy(meta0)
            table = meta
            for k in path[:-1]:
                table = table.setdefault(k, {})
            if value is None:
                table.pop(path[-1], None)
            else:
                table[path[-1]] = value
            try:
                from_meta(meta, builtin_dir() / f"{base}.toml")
            except FrictionLabError as exc:
                if "\n" in str(exc):
                    crashes.append(f"{'.'.join(path)} = {value!r}: multi-line message")
            except Exception as exc:  # noqa: BLE001 - the point of the test
                crashes.append(f"{'.'.join(path)} = {value!r}: {type(exc).__name__}: {exc}")
    assert not crashes, "\n".join(crashes)
