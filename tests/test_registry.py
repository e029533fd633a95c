"""The law registry: entry points (built-in and third-party), run-time registration, errors."""
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.core.errors import LawError, RegistryError
from frictionlab.physics import registry
from frictionlab.physics.law import Contact

LAW_GUIDE = Path(__file__).resolve().parents[1] / "docs" / "guides" / "registering-a-law.md"


def test_builtin_laws_come_from_entry_points():
    laws = fl.available_laws()
    assert {"coulomb", "area-rate", "wear", "couette"} <= set(laws)
    for name in ("coulomb", "area-rate", "wear", "couette"):
        assert registry.law_source(name).startswith(f"entry point '{name} = frictionlab.laws.")
    assert "laws" not in sys.modules  # the folder is installed as frictionlab.laws only


@pytest.mark.parametrize("name, params, needs", [
    ("coulomb", ["mu"], {"u", "N"}),
    ("area-rate", ["mu", "eta_prime"], {"u", "N", "dAdt"}),
    ("wear", ["lam"], {"u", "A"}),
    ("couette", ["eta", "h"], {"u", "A"}),
])
def test_builtin_declarations(name, params, needs):
    law = fl.get_law(name)
    assert list(law.param_names) == params
    assert set(law.requires) == needs


def test_builtin_forces_by_hand():
    c = Contact(t=np.zeros(3), u=np.array([2.0, -1.0, 0.0]), N=np.array([10.0, 10.0, 10.0]),
                A=np.array([1e-4, 2e-4, 1e-4]), dAdt=np.array([0.5, -0.5, 0.0]))
    assert np.allclose(fl.get_law("coulomb").force({"mu": 0.3}, c), [3.0, -3.0, 0.0])
    assert np.allclose(fl.get_law("area-rate").force({"mu": 0.3, "eta_prime": 4.0}, c),
                       [0.3 * (10 + 2.0), -0.3 * (10 - 2.0), 0.0])
    assert np.allclose(fl.get_law("wear").force({"lam": 1e6}, c), [200.0, -200.0, 0.0])
    assert np.allclose(fl.get_law("couette").force({"eta": 0.1, "h": 1e-6}, c), [20.0, -20.0, 0.0])


def test_unknown_law_lists_the_registered_ones():
    with pytest.raises(RegistryError, match=r"unknown law 'nope'; registered laws: .*wear"):
        fl.get_law("nope")


def _law_class(name="tmp-law", sign=1.0):
    class TmpLaw(fl.FrictionLaw):
        formula = "F = k u"
        citation = "test"
        params = (fl.ParamSpec("k", "N s/m", 1.0, 0.0, 10.0, 1.0, "viscous coefficient"),)
        requires = frozenset({"u"})

        def force(self, p, c):
            return sign * p["k"] * c.u

    TmpLaw.name = name
    return TmpLaw


def test_runtime_registration_and_duplicate_names_both_sources():
    cls = _law_class("tmp-runtime")
    fl.register_law(cls)
    try:
        assert fl.get_law("tmp-runtime").force({"k": 2.0}, Contact(t=np.zeros(1), u=np.ones(1)))[0] == 2.0
        with pytest.raises(RegistryError, match=r"'wear' is registered twice: by entry point 'wear = .*run-time"):
            fl.register_law(_law_class("wear"))
    finally:
        fl.unregister_law("tmp-runtime")
    assert "tmp-runtime" not in fl.available_laws()


def test_law_with_wrong_sign_is_rejected_naming_it():
    with pytest.raises(LawError, match=r"law 'backwards' .* does not oppose slip"):
        fl.register_law(_law_class("backwards", sign=-1.0))


def _write_dist(root: Path, dist: str, module_code: str, entry_points: str):
    pkg = root / dist.replace("-", "_")
    pkg.mkdir()
    (pkg / "__init__.py").write_text(textwrap.dedent(module_code))
    info = root / f"{dist.replace('-', '_')}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[frictionlab.laws]\n" + textwrap.dedent(entry_points))


THIRD_PARTY = """
    import numpy as np
    from frictionlab import FrictionLaw, ParamSpec

    class Viscous(FrictionLaw):
        name = "viscous-third-party"
        formula = "F = c u"
        citation = "a third-party package"
        params = (ParamSpec("c", "N s/m", 2.0, 0.0, 100.0, 1.0, "viscous coefficient"),)
        requires = frozenset({"u"})

        def force(self, p, c):
            return p["c"] * c.u
"""


def installed_plugin(tmp_path, monkeypatch, dist, source, entry_points):
    """Generator for a fixture: a package ``dist`` with module ``source`` installed for the registry, then removed."""
    _write_dist(tmp_path, dist, source, entry_points)
    monkeypatch.syspath_prepend(str(tmp_path))
    registry.reload_registry()
    yield tmp_path
    monkeypatch.undo()
    registry.reload_registry()


@pytest.fixture
def third_party(tmp_path, monkeypatch):
    yield from installed_plugin(tmp_path, monkeypatch, "viscous-law", THIRD_PARTY,
                                "viscous-third-party = viscous_law:Viscous\n")


def test_third_party_entry_point_registers_and_evaluates(third_party):
    law = fl.get_law("viscous-third-party")
    assert "viscous-law 0.1" in registry.law_source("viscous-third-party")
    f = law.force({"c": 3.0}, Contact(t=np.zeros(2), u=np.array([1.0, -2.0])))
    assert np.allclose(f, [3.0, -6.0])
    scene = fl.Scene(kind="incline", mass=1.0, u0=1.0, duration=1.0)
    traj = fl.simulate(law, scene, {"c": 3.0}, solver="ode", t=np.linspace(0, 1, 5))
    assert np.allclose(traj.v, np.exp(-3.0 * traj.t), rtol=1e-7)


def test_third_party_law_in_cli_listing(third_party, run_cli):
    out = run_cli("laws", env={"PYTHONPATH": str(third_party)})
    assert out.returncode == 0, out.stderr
    assert "viscous-third-party: F = c u" in out.stdout
    assert "viscous-law 0.1" in out.stdout


def test_broken_plugin_warns_and_registry_still_works(tmp_path, monkeypatch):
    _write_dist(tmp_path, "broken-law", "raise ImportError('missing dependency foo')\n", "broken = broken_law:X\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        with pytest.warns(registry.PluginWarning, match=r"broken = broken_law:X.*missing dependency foo"):
            registry.reload_registry()
        assert "wear" in fl.available_laws()
    finally:
        monkeypatch.undo()
        registry.reload_registry()


def test_two_plugins_with_one_name_is_an_error_naming_both(tmp_path, monkeypatch):
    _write_dist(tmp_path, "dup-one", THIRD_PARTY, "viscous-third-party = dup_one:Viscous\n")
    _write_dist(tmp_path, "dup-two", THIRD_PARTY.replace("Viscous", "Viscous2"),
                "viscous-third-party = dup_two:Viscous2\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        with pytest.raises(RegistryError, match=r"registered twice: by entry point .*dup-(one|two) 0.1 and by .*dup-"):
            registry.reload_registry()
    finally:
        monkeypatch.undo()
        registry.reload_registry()


def _readme_law_code() -> str:
    text = LAW_GUIDE.read_text()
    block = re.search(r"```python\n(import numpy as np\n\nfrom frictionlab import FrictionLaw.*?)```", text, re.S)
    assert block, "the law guide has no law example"
    return block.group(1)


def test_readme_law_example_runs_as_written(tmp_path, run_cli):
    code = _readme_law_code()
    assert len(code.splitlines()) <= 35
    (tmp_path / "my_laws.py").write_text(code)
    out = run_cli("--load", tmp_path / "my_laws.py", "laws", "--brief")
    assert out.returncode == 0, out.stderr
    assert "exp-stribeck" in out.stdout
    namespace = {}
    exec(compile(code, "my_laws.py", "exec"), namespace)
    try:
        law = fl.get_law("exp-stribeck")
        scene = fl.Scene(kind="incline", mass=0.1, u0=1.0, duration=0.05, normal=fl.physics.scene.WeightNormal(1.0))
        traj = fl.simulate("exp-stribeck", scene, solver="ode", t=np.linspace(0, 0.05, 6))
        # mu between mu_k and mu_s, so the block decelerates at between 0.2 and 0.4 N / 0.1 kg
        assert 1.0 - 4.0 * 0.05 <= traj.v[-1] <= 1.0 - 2.0 * 0.05
        assert law.citation.startswith("R. Stribeck")
    finally:
        fl.unregister_law("exp-stribeck")


def test_a_notebook_cell_registering_a_law_can_run_again():
    """The same class again: a no-op with a warning; the class defined anew (same module and name): it
    replaces the earlier one, with a warning; another class of the same law name is still an error."""
    import warnings as _w

    from frictionlab import FrictionLaw, ParamSpec, get_law, register_law, unregister_law

    def define(k):
        class CellLaw(FrictionLaw):
            name = "cell-law"
            formula = "F = k N"
            citation = "a test"
            params = (ParamSpec("k", "", k, 0.0, 10.0, 0.3, "a coefficient"),)
            requires = frozenset({"u", "N"})

            def force(self, p, c):
                return p["k"] * c.N * np.sign(c.u)
        return CellLaw

    first = define(0.3)
    try:
        register_law(first)
        with _w.catch_warnings(record=True) as seen:
            _w.simplefilter("always")
            register_law(first)
            assert get_law("cell-law").spec("k").default == 0.3 and "nothing changed" in str(seen[-1].message)
            register_law(define(0.4))
            assert get_law("cell-law").spec("k").default == 0.4 and "replaces the earlier" in str(seen[-1].message)
    finally:
        unregister_law("cell-law")


#: A law file for ``--load``: a linear law F = k u, named by ``format(cls=..., name=...)``.
LINEAR_LAW_FILE = '''from frictionlab import FrictionLaw, ParamSpec, register_law


@register_law
class {cls}(FrictionLaw):
    name = "{name}"
    formula = "F = k u"
    citation = "a test"
    params = (ParamSpec("k", "N s/m", 1.0, 0.0, 10.0, 1.0, "coefficient"),)
    requires = frozenset({{"u"}})

    def force(self, p, c):
        return p["k"] * c.u
'''


def test_loading_the_same_law_file_twice_is_a_note_not_an_error(tmp_path, capsys):
    """``--load f --load f`` (a notebook's cell run twice, on the command line): the second registration of
    the same module.class replaces the first with a warning; the command runs."""
    import warnings as _w

    from frictionlab import unregister_law
    from frictionlab.cli import main

    f = tmp_path / "my_twice_laws.py"
    f.write_text(LINEAR_LAW_FILE.format(cls="Twice", name="twice"))
    try:
        with _w.catch_warnings(record=True) as seen:
            _w.simplefilter("always")
            assert main(["--load", str(f), "--load", str(f), "laws"]) == 0
        assert any("'twice'" in str(w.message) and "again" in str(w.message) for w in seen)
        assert "twice" in capsys.readouterr().out
    finally:
        unregister_law("twice")


def test_a_loaded_law_file_leaves_no_bytecode_beside_it(tmp_path):
    """``--load f.py`` reads f.py and writes nothing beside it, also where Python writes bytecode (the default:
    PYTHONDONTWRITEBYTECODE unset), which would otherwise leave a __pycache__ folder in the user's folder."""
    f = tmp_path / "my_quiet_laws.py"
    f.write_text(LINEAR_LAW_FILE.format(cls="Quiet", name="quiet"))
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    done = subprocess.run([sys.executable, "-m", "frictionlab", "--load", str(f), "laws"], env=env, cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and "quiet" in done.stdout, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["my_quiet_laws.py"]
