"""Render a report's report.html in headless Chromium and save screenshots, to look at as a reader would.

    python tools/screenshot.py REPORT_FOLDER_OR_HTML [--out DIR] [--height 1000 --height 4000] [--open]
    python tools/screenshot.py --readme [REPORT_FOLDER]
    python tools/screenshot.py --site SITE_FOLDER --out DIR
    python tools/screenshot.py --docs SITE_FOLDER --out DIR

Writes DIR/screen-<height>.png (default DIR: the report folder) for a 1400 px wide window of each
height: 1000 px is the first screen; --open opens every collapsible section first.
--readme runs ``frictionlab compare`` (the README's command 1) into a temporary folder (or takes the report
folder it wrote) and saves the first screen of its report as docs/images/first-screen.png, the README's
picture, with its answers table in docs/images/first-screen.json (tests/test_readme_picture.py fails when a
fresh run's table differs: then run this again).
--site saves the first screen of each page of a built documentation site (``mkdocs build --site-dir
SITE_FOLDER``) as DIR/<page>.png.
--docs saves five pages of a built site (DOCS_PAGES: the home page, the equations, the benchmarks' wide tables,
a gallery example and an API page) at 1400 and 800 px wide, 2000 px high, as DIR/<page>-<width>.png: what to
look at for tables or code cut off at the right edge. Needs Debian's ``chromium`` (apt-get install chromium).
"""
from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

WIDTH = 1400


def chromium() -> str | None:
    """The path of a Chromium binary, or None."""
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


_OPEN_ALL = "<script>document.querySelectorAll('details').forEach(function (d) { d.open = true; });</script>"


def screenshot(html: Path, png: Path, height: int = 1000, width: int = WIDTH, timeout: float = 120.0,
               open_all: bool = False) -> Path:
    """Save a ``width`` x ``height`` screenshot of ``html`` to ``png`` (a fresh browser profile each time);
    ``open_all`` opens every collapsible section first."""
    exe = chromium()
    if exe is None:
        raise RuntimeError("no chromium found: apt-get install -y chromium")
    with tempfile.TemporaryDirectory(prefix="frictionlab-chromium-") as profile:
        if open_all:
            probe = Path(profile) / "open.html"
            probe.write_text(Path(html).read_text(encoding="utf-8").replace("</body>", _OPEN_ALL + "</body>"),
                             encoding="utf-8")
            html = probe
        cmd = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
               "--disable-background-networking", "--disable-component-update", "--disable-sync",
               "--hide-scrollbars", f"--user-data-dir={profile}/p", f"--screenshot={Path(png).resolve()}",
               f"--window-size={width},{height}", Path(html).resolve().as_uri()]
        subprocess.run(cmd, check=True, timeout=timeout, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    if not Path(png).exists():
        raise RuntimeError(f"chromium wrote no screenshot for {html}")
    return Path(png)


#: Reports where the first screen's verdict table and figure are, as JSON in <body data-layout>.
_MEASURE = """<script>window.addEventListener("load", function () {
  var box = function (q) { var e = document.querySelector(q); if (!e) return null;
    var r = e.getBoundingClientRect(); return {top: r.top, bottom: r.bottom, width: r.width, height: r.height}; };
  document.body.dataset.layout = JSON.stringify({table: box("section.first table"), figure: box("section.first img"),
    window: {width: window.innerWidth, height: window.innerHeight}});
});</script>"""


#: Every table with every collapsible section open: its columns, its width and its box's (CSS px).
_TABLES = """<script>window.addEventListener("load", function () {
  document.querySelectorAll("details").forEach(function (d) { d.open = true; });
  document.body.dataset.layout = JSON.stringify(Array.prototype.map.call(document.querySelectorAll("table"),
    function (t) { return {columns: t.rows[0].cells.length, width: t.getBoundingClientRect().width,
                           box: t.parentElement.clientWidth}; }));
});</script>"""


def first_screen_layout(html: Path, height: int = 1000, width: int = WIDTH, timeout: float = 120.0) -> dict:
    """Where the verdict table and the finding figure sit in a ``width`` x ``height`` window (CSS px)."""
    return laid_out(html, _MEASURE, height, width, timeout)


def table_widths(html: Path, width: int = WIDTH, timeout: float = 120.0) -> list[dict]:
    """Each table of the page in a ``width`` px wide window, every section open: {columns, width, box} (CSS px;
    box: the width of the box it lies in, which scrolls what is wider)."""
    return laid_out(html, _TABLES, 1000, width, timeout)


def laid_out(html: Path, script: str, height: int, width: int, timeout: float = 120.0):
    """What ``script`` (run once the page has loaded) writes as JSON into <body data-layout>."""
    import json
    import re

    exe = chromium()
    if exe is None:
        raise RuntimeError("no chromium found: apt-get install -y chromium")
    with tempfile.TemporaryDirectory(prefix="frictionlab-chromium-") as profile:
        probe = Path(profile) / "probe.html"
        probe.write_text(Path(html).read_text(encoding="utf-8").replace("</body>", script + "</body>"),
                         encoding="utf-8")
        cmd = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
               "--disable-background-networking", "--disable-component-update", "--disable-sync",
               "--hide-scrollbars", f"--user-data-dir={profile}/p", f"--window-size={width},{height}",
               "--virtual-time-budget=5000", "--dump-dom", probe.as_uri()]
        dom = subprocess.run(cmd, check=True, timeout=timeout, capture_output=True, text=True).stdout
    m = re.search(r'data-layout="([^"]*)"', dom)
    if not m:
        raise RuntimeError("chromium did not lay the page out (no data-layout in the dumped DOM)")
    import html as _html

    return json.loads(_html.unescape(m.group(1)))


ROOT = Path(__file__).resolve().parents[1]
README_PICTURE = ROOT / "docs" / "images" / "first-screen.png"


README_ROWS = README_PICTURE.with_suffix(".json")
#: Columns of the first screen's answers table that vary from run to run (CPU-time ratios): not compared.
TIMED_COLUMNS = ("what accuracy costs",)
README_COMMAND = ["compare", "--quiet"]


def first_screen_rows(report_md: Path) -> dict:
    """The answers table of a report's first screen (``report.md``), without TIMED_COLUMNS:
    {"columns": [...], "rows": [[...], ...]}."""
    text = Path(report_md).read_text(encoding="utf-8").split("## Answers", 1)[1]
    table = [line for line in text.split("\n\n| ", 1)[1].split("\n\n", 1)[0].splitlines()]
    cells = [[c.strip() for c in ("| " + line if i == 0 else line).strip().strip("|").split(" | ")]
             for i, line in enumerate(table) if not line.startswith("|---")]
    keep = [i for i, name in enumerate(cells[0]) if name not in TIMED_COLUMNS]
    return {"columns": [cells[0][i] for i in keep], "rows": [[row[i] for i in keep] for row in cells[1:]]}


def run_readme_job(folder: Path) -> Path:
    """Run the README's main job (``frictionlab compare``) into ``folder``/report; the report folder."""
    exe = Path(sys.executable).parent / "frictionlab"
    subprocess.run([str(exe) if exe.exists() else "frictionlab", *README_COMMAND, "--out", f"{folder}/report"],
                   check=True, cwd=folder, stdout=subprocess.DEVNULL)
    return Path(folder) / "report"


def readme_picture(png: Path = README_PICTURE, report: Path | None = None) -> Path:
    """Save the first screen (1400 x 1000 px) of the README's main job's report as ``png``, and its answers table
    (less TIMED_COLUMNS) beside it as JSON, which tests/test_readme_picture.py compares with a fresh run.
    ``report``: a report folder that job wrote with the current code; None runs it in a temporary folder."""
    import json

    with tempfile.TemporaryDirectory(prefix="frictionlab-readme-") as tmp:
        folder = Path(report) if report is not None else run_readme_job(Path(tmp))
        png.parent.mkdir(parents=True, exist_ok=True)
        screenshot(folder / "report.html", png)
        png.with_suffix(".json").write_text(json.dumps(first_screen_rows(folder / "report.md"), indent=1,
                                                       ensure_ascii=False) + "\n", encoding="utf-8")
        return png


def site_pictures(site: Path, out: Path, height: int = 1000) -> list[Path]:
    """The first screen of every page of a built documentation site, as out/<page path with '-'>.png."""
    out.mkdir(parents=True, exist_ok=True)
    done = []
    for page in sorted(site.rglob("index.html")):
        rel = page.parent.relative_to(site)
        if rel.parts and rel.parts[0] in ("search", "assets"):
            continue
        name = "-".join(rel.parts) or "home"
        done.append(screenshot(page, out / f"{name}.png", height))
    return done


#: The pages --docs renders: one of each kind of content (text, maths, wide tables, a gallery example, API).
DOCS_PAGES = ("", "science/equations", "benchmarks", "gallery/golf_claim", "api/results")
DOCS_WIDTHS = (1400, 800)


def docs_pictures(site: Path, out: Path, height: int = 2000) -> list[Path]:
    """DOCS_PAGES of a built site at each of DOCS_WIDTHS, as out/<page>-<width>.png."""
    out.mkdir(parents=True, exist_ok=True)
    done = []
    for rel in DOCS_PAGES:
        page = site / rel / "index.html"
        if not page.exists():
            raise FileNotFoundError(f"{page}: no such page in the built site (mkdocs build --site-dir {site})")
        for width in DOCS_WIDTHS:
            done.append(screenshot(page, out / f"{rel.replace('/', '-') or 'home'}-{width}.png", height, width))
    return done


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("report", type=Path, nargs="?", help="a report folder or its report.html")
    ap.add_argument("--readme", action="store_true", help="make the README's picture, docs/images/first-screen.png")
    ap.add_argument("--site", type=Path, help="a built documentation site: the first screen of each page")
    ap.add_argument("--docs", type=Path, help="a built documentation site: five pages at 1400 and 800 px wide")
    ap.add_argument("--out", type=Path, help="folder for the PNGs (default: the report folder)")
    ap.add_argument("--height", type=int, action="append", help="window height in px (repeatable; default 1000)")
    ap.add_argument("--open", action="store_true", help="open every collapsible section (screen-open-<height>.png)")
    args = ap.parse_args(argv)
    if args.readme:
        print(readme_picture(report=args.report))
        return 0
    if args.site:
        for png in site_pictures(args.site, args.out or Path("site-screens"), (args.height or [1000])[0]):
            print(png)
        return 0
    if args.docs:
        for png in docs_pictures(args.docs, args.out or Path("site-screens"), (args.height or [2000])[0]):
            print(png)
        return 0
    if args.report is None:
        ap.error("give a report folder, --readme, --site or --docs")
    html = args.report / "report.html" if args.report.is_dir() else args.report
    out = args.out or html.parent
    out.mkdir(parents=True, exist_ok=True)
    for h in args.height or [1000]:
        png = screenshot(html, out / f"screen-{'open-' if args.open else ''}{h}.png", h, open_all=args.open)
        print(png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
