"""Lazy imports: the command line's help and a law plugin's import do not load the numerical stack,
and the package's public names resolve exactly as the eager imports did."""
import subprocess
import sys

import pytest

import frictionlab as fl

HEAVY = ("numpy", "scipy", "lmfit", "matplotlib", "pandas", "pint")


def _loaded_after(code: str) -> set[str]:
    probe = f"import sys\n{code}\nprint(' '.join(m for m in {HEAVY!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return set(out.stdout.split())


def test_help_loads_no_numerical_package():
    code = "from frictionlab.cli import main\nimport contextlib, io\nwith contextlib.redirect_stdout(io.StringIO()):\n    main(['--help'])"
    assert _loaded_after(code) == set()


def test_laws_and_plugins_need_numpy_only():
    assert _loaded_after("from frictionlab import FrictionLaw, ParamSpec, register_law") <= {"numpy"}
    code = "from frictionlab.cli import main\nimport contextlib, io\nwith contextlib.redirect_stdout(io.StringIO()):\n    main(['laws'])"
    assert _loaded_after(code) == {"numpy"}


@pytest.mark.parametrize("name", fl.__all__)
def test_public_names_resolve(name):
    value = getattr(fl, name)
    assert getattr(value, "__name__", name) == name or name == "__version__"


def test_predict_stays_the_function_after_its_module_is_imported():
    import importlib

    importlib.import_module("frictionlab.inference.fitting.predict")
    assert callable(fl.predict) and fl.predict.__module__ == "frictionlab.inference.fitting.predict"
    assert fl.predict is importlib.import_module("frictionlab.inference.fitting.fit").predict


def test_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        fl.nonsense  # noqa: B018


def _blas_env_seen(tmp_path, env: dict) -> dict:
    """The BLAS thread variables as a plugin loaded by ``python -m frictionlab --load`` sees them."""
    import json
    import os

    plugin = tmp_path / "probe.py"
    plugin.write_text("import json, os\nfrom frictionlab.cli import BLAS_THREADS\n"
                      "print(json.dumps({k: os.environ.get(k) for k in BLAS_THREADS}))\n")
    full = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                                                                "OMP_NUM_THREADS")} | env
    out = subprocess.run([sys.executable, "-m", "frictionlab", "--load", str(plugin), "laws"], capture_output=True,
                         text=True, check=True, env=full)
    return json.loads(out.stdout.splitlines()[0])


def test_the_command_line_runs_blas_on_one_thread_unless_told(tmp_path):
    # the entry point sets them before numpy is first imported (the help test above: importing the CLI loads none)
    assert _blas_env_seen(tmp_path, {}) == {"OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
                                             "OMP_NUM_THREADS": "1"}
    seen = _blas_env_seen(tmp_path, {"OPENBLAS_NUM_THREADS": "2"})
    assert seen["OPENBLAS_NUM_THREADS"] == "2" and seen["MKL_NUM_THREADS"] == "1"
