"""The installed package contains every subpackage: setuptools finds them (pyproject lists none by hand)."""
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_setuptools_finds_every_subpackage_the_laws_and_the_data():
    from setuptools import find_packages

    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert list(cfg["packages"]) == ["find"], "packages are found, not listed"
    found = set(find_packages(where=str(ROOT), **cfg["packages"]["find"]))
    on_disk = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "frictionlab").rglob("__init__.py")}
    assert found == on_disk
    assert {"frictionlab.laws", "frictionlab.data", "frictionlab.inference.velstep"} <= found


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
