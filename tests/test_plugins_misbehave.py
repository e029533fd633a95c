"""Law plugins that misbehave: each is caught with a message naming the plugin, and the rest of
the registry keeps working. (test_registry.py covers an ImportError plugin, a wrong-sign law
registered at run time and two third-party plugins sharing a name; these are the other ways.)
"""
from __future__ import annotations

import re
import textwrap
import warnings
from pathlib import Path

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.core.errors import FrictionLabError, LawError, RegistryError
from frictionlab.physics import registry

BAD_LAWS = '''
    import numpy as np
    from frictionlab import FrictionLaw, ParamSpec


    class _Base(FrictionLaw):
        formula = "F = c u"
        citation = "test"
        params = (ParamSpec("c", "N s/m", 1.0, 0.0, 10.0, 1.0, "coefficient"),)
        requires = frozenset({"u"})

        def force(self, p, c):
            return p["c"] * c.u


    class Good(_Base):
        name = "good-viscous"


    class ReturnsNaN(_Base):
        name = "returns-nan"

        def force(self, p, c):
            return p["c"] * c.u * np.nan


    class WrongShape(_Base):
        name = "wrong-shape"

        def force(self, p, c):
            return np.array([p["c"]])  # one number for a whole batch of samples


    class WrongSign(_Base):
        name = "wrong-sign"

        def force(self, p, c):
            return -p["c"] * c.u  # the force on the body, not frictionlab's F


    class Raises(_Base):
        name = "raises"

        def force(self, p, c):
            return p["c"] / 0 * c.u  # ZeroDivisionError on a Python float


    class NoRequires(FrictionLaw):
        name = "no-requires"
        formula = "F = 0"
        citation = "test"
        params = ()


    NOT_A_LAW = object()
'''

ENTRY_POINTS = """\
good-viscous = bad_laws:Good
returns-nan = bad_laws:ReturnsNaN
wrong-shape = bad_laws:WrongShape
wrong-sign = bad_laws:WrongSign
raises = bad_laws:Raises
no-requires = bad_laws:NoRequires
not-a-law = bad_laws:NOT_A_LAW
missing-attr = bad_laws:DoesNotExist
crashes-on-import = crash_on_import:Law
"""

#: entry point -> what its warning must say (besides naming the entry point and the distribution)
EXPECTED = {
    "returns-nan": r"force\(\) returned NaN",
    "wrong-shape": r"force\(\) returned shape \(1,\), expected \(5,\)",
    "wrong-sign": r"does not oppose slip",
    "raises": r"force\(\) raised ZeroDivisionError",
    "no-requires": r"missing class attribute 'requires'",
    "not-a-law": r"is not a frictionlab\.FrictionLaw",
    "missing-attr": r"import failed: AttributeError",
    "crashes-on-import": r"import failed: RuntimeError: plugin configuration missing",
}


def _write_dist(root: Path, dist: str, modules: dict[str, str], entry_points: str) -> None:
    for module, code in modules.items():
        (root / f"{module}.py").write_text(textwrap.dedent(code))
    info = root / f"{dist.replace('-', '_')}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[frictionlab.laws]\n" + entry_points)


@pytest.fixture
def bad_dist(tmp_path, monkeypatch):
    _write_dist(tmp_path, "bad-laws", {"bad_laws": BAD_LAWS,
                                       "crash_on_import": "raise RuntimeError('plugin configuration missing')\n"},
                ENTRY_POINTS)
    monkeypatch.syspath_prepend(str(tmp_path))
    yield tmp_path
    monkeypatch.undo()
    registry.reload_registry()


def test_each_broken_plugin_is_skipped_with_a_warning_naming_it(bad_dist):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        registry.reload_registry()
    messages = [str(w.message) for w in caught if issubclass(w.category, registry.PluginWarning)]
    for ep, what in EXPECTED.items():
        mine = [m for m in messages if f"entry point '{ep} = " in m]
        assert len(mine) == 1, f"{ep}: {messages}"
        assert "bad-laws 0.1" in mine[0], mine[0]
        assert re.search(what, mine[0]), mine[0]
        assert "\n" not in mine[0]
    assert len(messages) == len(EXPECTED)  # the good plugin raised no warning
    laws = fl.available_laws()
    assert "good-viscous" in laws and not set(EXPECTED) & set(laws)
    # the registry still works: built-ins and the good plugin simulate
    assert {"coulomb", "area-rate", "wear", "couette"} <= set(laws)
    traj = fl.simulate("good-viscous", fl.Scene(kind="incline", mass=1.0, u0=1.0, duration=1.0), {"c": 2.0},
                       t=np.linspace(0, 1, 5))
    assert np.allclose(traj.v, np.exp(-2.0 * traj.t), rtol=1e-7)
    assert fl.simulate("wear", fl.load_dataset("impact-golf-v28"), solver="exact").omega[-1] > 0


def test_broken_plugins_on_the_command_line_warn_and_list_the_rest(bad_dist, run_cli):
    out = run_cli("laws", "--brief", env={"PYTHONPATH": str(bad_dist)})
    assert out.returncode == 0, out.stderr
    assert "Traceback" not in out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == len(EXPECTED), out.stderr  # one line per skipped plugin
    assert all(line.startswith("warning: frictionlab: skipped law plugin") for line in lines), out.stderr
    assert "good-viscous" in out.stdout and "wear" in out.stdout and "wrong-sign" not in out.stdout


def test_plugin_taking_a_builtin_name_is_an_error_naming_both(tmp_path, monkeypatch, run_cli):
    code = BAD_LAWS + "\n    class Wear2(_Base):\n        name = 'wear'\n"
    _write_dist(tmp_path, "clash-laws", {"clash_laws": code}, "wear = clash_laws:Wear2\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        with pytest.raises(RegistryError) as info:
            registry.reload_registry()
        msg = str(info.value)
        assert "'wear' is registered twice" in msg
        assert "frictionlab.laws.wear:Wear" in msg and "clash_laws:Wear2" in msg and "clash-laws 0.1" in msg
    finally:
        monkeypatch.undo()
        registry.reload_registry()
    assert "wear" in fl.available_laws()  # back to normal once the clash is gone
    out = run_cli("laws", env={"PYTHONPATH": str(tmp_path)})
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert out.stderr.count("\n") == 1 and "clash_laws:Wear2" in out.stderr and "frictionlab.laws.wear" in out.stderr


# -- run-time laws that pass the probe but misbehave during a simulation ---------------------
def _runtime_law(name, force):
    cls = type(name.title().replace("-", ""), (fl.FrictionLaw,), {
        "name": name, "formula": "F = c u (mostly)", "citation": "test",
        "params": (fl.ParamSpec("c", "N s/m", 1.0, 0.0, 10.0, 1.0, "coefficient"),),
        "requires": frozenset({"u"}), "force": force})
    return cls


@pytest.fixture
def runtime_law():
    names = []

    def register(name, force):
        fl.register_law(_runtime_law(name, force))
        names.append(name)
        return name

    yield register
    for n in names:
        fl.unregister_law(n)


@pytest.mark.parametrize("solver", ["ode", "ode:RK45", "ode:Radau"])
def test_nan_in_the_middle_of_a_simulation_names_the_law(runtime_law, solver):
    # fine at the probe's slips (|u| <= 3 m/s), NaN above 10 m/s
    name = runtime_law("nan-above-10", lambda self, p, c: p["c"] * c.u * np.sqrt(1.0 - np.abs(c.u) / 10.0))
    scene = fl.Scene(kind="incline", mass=1.0, u0=20.0, duration=1.0)
    with pytest.raises(LawError, match=r"law 'nan-above-10': force\(\) returned NaN or infinite values") as info:
        with np.errstate(invalid="ignore"):
            fl.simulate(name, scene, {"c": 1.0}, solver=solver)
    assert "\n" not in str(info.value)


def test_wrong_shape_for_some_inputs_names_the_law(runtime_law):
    def force(self, p, c):
        f = p["c"] * c.u
        return f[:-1] if f.size > 5 else f  # drops a sample on long batches

    name = runtime_law("drops-a-sample", force)
    scene = fl.Scene(kind="incline", mass=1.0, u0=1.0, duration=1.0)
    with pytest.raises(LawError, match=r"law 'drops-a-sample': force\(\) returned shape \(9,\), expected \(10,\)"):
        fl.simulate(name, scene, t=np.linspace(0, 1, 10))


def test_force_that_raises_during_a_simulation_names_the_law(runtime_law):
    def force(self, p, c):
        if np.any((np.abs(c.u) > 0.1) & (np.abs(c.u) < 0.4)):  # the probe uses 1e-3, 0.5, 1, 2, 3 m/s
            raise KeyError("lookup table has no entry")
        return p["c"] * c.u

    name = runtime_law("table-gap", force)
    scene = fl.Scene(kind="incline", mass=1.0, u0=5.0, duration=5.0)
    with pytest.raises(FrictionLabError, match=r"law 'table-gap': force\(\) raised KeyError"):
        fl.simulate(name, scene, {"c": 1.0})


def test_wrong_sign_at_runtime_registration_names_the_class():
    cls = _runtime_law("pushes", lambda self, p, c: -p["c"] * c.u)
    with pytest.raises(LawError, match=r"law 'pushes' \(run-time registration of .*Pushes\): force\(\) does not"):
        fl.register_law(cls)
    assert "pushes" not in fl.available_laws()


def test_nan_at_runtime_registration_names_the_class():
    cls = _runtime_law("all-nan", lambda self, p, c: np.full(np.shape(c.u), np.nan))
    with pytest.raises(LawError, match=r"law 'all-nan' \(run-time registration of .*AllNan\): force\(\) returned NaN"):
        fl.register_law(cls)
    assert "all-nan" not in fl.available_laws()
