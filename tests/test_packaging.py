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


def test_license_citation_changelog_and_typing_marker_ship():
    import yaml  # installed with the docs tools of the test extra

    assert "MIT License" in (ROOT / "LICENSE").read_text()
    assert tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["license"] == {"text": "MIT"}
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0" and cff["type"] == "software" and cff["license"] == "MIT"
    paper = cff["references"][0]
    assert (paper["journal"], paper["volume"], paper["start"], paper["year"]) == ("Scientific Reports", 7, 40102, 2017)
    assert paper["doi"] == "10.1038/srep40102" and paper["authors"][0]["family-names"] == "Arakawa"
    assert "\n## Unreleased\n" in (ROOT / "CHANGELOG.md").read_text()
    assert (ROOT / "frictionlab" / "py.typed").exists()
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    assert "py.typed" in data["frictionlab"]


def test_the_installed_package_carries_its_typing_marker():
    from importlib import resources

    assert resources.files("frictionlab").joinpath("py.typed").is_file()
