"""The documentation: the site builds in strict mode (every warning an error), every page is in its nav,
and every example marked runnable in docs/*.md and README.md runs.

A runnable example is a fenced ``sh`` or ``python`` block with ``<!-- runnable -->`` on the line above it.
The blocks of one page run in order in one fresh temporary folder, each on its own: a ``sh`` block with
bash (``set -e``: every line must succeed) and the test environment's ``frictionlab`` first on the PATH, a
``python`` block as a script with the test environment's Python. ``<!-- runnable: file=NAME -->`` writes
the block to NAME in that folder instead, for later blocks to use.
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
BLOCK = re.compile(r"^<!-- runnable(?::\s*file=(?P<file>[\w.-]+))?\s*-->\n```(?P<lang>[\w-]+)[^\n]*\n(?P<code>.*?)^```\s*$",
                   re.M | re.S)
TIMEOUT = 300  # seconds a block may take on a loaded 2-core machine
BUILD_TIMEOUT = 1500  # seconds the site's build may take there: it runs the gallery's examples


def pages() -> list[Path]:
    return sorted(DOCS.rglob("*.md")) + [ROOT / "README.md"]


def runnable_blocks(text: str) -> list[tuple[str, str, str | None]]:
    """(language, code, file to write or None) of every block marked runnable, in order."""
    return [(m["lang"], m["code"], m["file"]) for m in BLOCK.finditer(text)]


def _env() -> dict:
    env = dict(os.environ)
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    env["MPLBACKEND"] = "Agg"
    env["NO_MKDOCS_2_WARNING"] = "1"  # the Material theme's notice about its successor, not a build warning
    env.pop("PYTHONPATH", None)
    return env


def run_page(page: Path, folder: Path) -> None:
    for i, (lang, code, file) in enumerate(runnable_blocks(page.read_text(encoding="utf-8")), 1):
        where = f"{page.name}, runnable block {i} ({lang})"
        if file:
            (folder / file).write_text(code, encoding="utf-8")
            continue
        if lang == "sh":
            cmd = ["bash", "-e", "-o", "pipefail", "-c", code]
        elif lang == "python":
            script = folder / f"block{i}.py"
            script.write_text(code, encoding="utf-8")
            cmd = [sys.executable, str(script)]
        else:
            raise AssertionError(f"{where}: only sh and python blocks can be runnable")
        out = subprocess.run(cmd, cwd=folder, env=_env(), capture_output=True, text=True, timeout=TIMEOUT)
        assert out.returncode == 0, f"{where} failed ({out.returncode}):\n{code}\n--- stdout\n{out.stdout[-3000:]}" \
                                    f"\n--- stderr\n{out.stderr[-3000:]}"


PAGES_WITH_EXAMPLES = [p for p in pages() if runnable_blocks(p.read_text(encoding="utf-8"))]


@pytest.mark.parametrize("page", PAGES_WITH_EXAMPLES, ids=lambda p: str(p.relative_to(ROOT)))
def test_runnable_examples_run(page, tmp_path):
    run_page(page, tmp_path)


def test_the_examples_are_found():
    readme = runnable_blocks((ROOT / "README.md").read_text(encoding="utf-8"))
    assert {lang for lang, _, _ in readme} == {"sh", "python"}
    assert len(PAGES_WITH_EXAMPLES) >= 8
    text = "<!-- runnable: file=a.py -->\n```python\nx = 1\n```\n\n```sh\nnot marked\n```\n<!-- runnable -->\n```sh\ntrue\n```\n"
    assert runnable_blocks(text) == [("python", "x = 1\n", "a.py"), ("sh", "true\n", None)]


def test_a_failing_example_fails(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("<!-- runnable -->\n```sh\nfrictionlab fit no-such-law impact-golf-v28\n```\n")
    with pytest.raises(AssertionError, match="no-such-law"):
        run_page(page, tmp_path)


def _nav_files(nav) -> list[str]:
    out = []
    for item in nav:
        value = next(iter(item.values())) if isinstance(item, dict) else item
        out += _nav_files(value) if isinstance(value, list) else [value]
    return out


def test_every_page_is_in_the_nav():
    import yaml

    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    listed = set(_nav_files(config["nav"]))
    present = {str(p.relative_to(DOCS)) for p in DOCS.rglob("*.md")}
    assert present - listed == set(), "add these pages to nav in mkdocs.yml"


def test_the_site_builds_in_strict_mode(tmp_path):
    pytest.importorskip("mkdocs", reason="the docs tools are in the test extra: pip install -e '.[test]'")
    pytest.importorskip("mkdocstrings", reason="the docs tools are in the test extra: pip install -e '.[test]'")
    out = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                         cwd=ROOT, env=_env(), capture_output=True, text=True, timeout=BUILD_TIMEOUT)
    assert out.returncode == 0, out.stderr[-5000:]
    assert not re.search(r"^WARNING", out.stderr, re.M), out.stderr[-5000:]
    index = (tmp_path / "site" / "index.html").read_text(encoding="utf-8")
    assert "frictionlab" in index
    api = (tmp_path / "site" / "api" / "results" / "index.html").read_text(encoding="utf-8")
    assert "fit" in api and "Fit every law to every dataset" in api  # rendered from the docstrings


def _gallery():
    import importlib.util

    spec = importlib.util.spec_from_file_location("docs_gallery", ROOT / "tools" / "docs_gallery.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_gallery_has_its_examples():
    gallery = _gallery()
    names = [p.stem for p in gallery.examples()]
    assert len(names) >= 8 and names[: len(gallery.ORDER)] == list(gallery.ORDER)
    for script in gallery.examples():
        doc, cells = gallery.split_cells(script.read_text(encoding="utf-8"))
        assert doc.startswith("# ") and len(cells) >= 2, script.name  # a title, then text and code cells


def test_a_gallery_example_runs_cell_by_cell_and_a_failing_one_fails(tmp_path):
    gallery = _gallery()
    good = tmp_path / "good.py"
    good.write_text('"""# Good\n\nText."""\n\n# %%\n# First.\nimport matplotlib.pyplot as plt\nprint("one")\n'
                    "plt.plot([0, 1])\n\n# %%\n# Second.\nprint('two')\n", encoding="utf-8")
    results = gallery.run_example(good, tmp_path / "out")
    assert [r["stdout"] for r in results] == ["one\n", "two\n"]
    assert results[0]["figures"] and (tmp_path / "out" / results[0]["figures"][0]).stat().st_size > 0
    page = gallery.page(good, results)
    assert "# Good" in page and "print(\"one\")" in page and "```text\none\n```" in page
    bad = tmp_path / "bad.py"
    bad.write_text('"""# Bad"""\n\n# %%\nraise ValueError("this example is broken")\n', encoding="utf-8")
    with pytest.raises(RuntimeError, match="this example is broken"):
        gallery.run_example(bad, tmp_path / "out")
