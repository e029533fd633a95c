"""The installed package contains every subpackage (pyproject lists them explicitly)."""
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_subpackage_is_listed_in_pyproject():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(cfg["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "frictionlab").rglob("__init__.py")}
    assert found <= listed, f"not listed in pyproject: {sorted(found - listed)}"
    assert cfg["package-dir"]["frictionlab.laws"] == "laws"
    assert cfg["package-dir"]["frictionlab.data"] == "datasets"
