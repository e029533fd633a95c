"""The documentation's gallery of worked examples: a MkDocs hook that runs every script in examples/gallery/
when the site is built and makes one page per script, with its code, what it printed and its figures.

An example is a Python script in the manner of sphinx-gallery: its module docstring (a ``# Title`` line, then
Markdown) opens the page; a line ``# %%`` starts a new cell, whose leading comment lines are Markdown text and
whose remaining lines are code. The cells run in order in one namespace, in a fresh temporary folder, in a
fresh Python process (``MPLBACKEND=Agg``); after each cell its open matplotlib figures are saved as PNG and
closed, and what it printed is kept. A script that raises, or takes longer than ``TIMEOUT`` seconds, fails
the build with its traceback.

    python tools/docs_gallery.py examples/gallery/golf_claim.py OUT   # run one example as the build does
"""
from __future__ import annotations

import html
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "gallery"
TIMEOUT = 600  # seconds one example may take on a loaded 2-core machine
JOBS = 2  # examples run at once
CELL = re.compile(r"^# %%.*$", re.M)
CHILD = "--child"  # the first argument of the process run_example starts


def split_cells(source: str) -> tuple[str, list[tuple[str, str]]]:
    """(the module docstring, [(Markdown text, code)] of each cell) of an example's source."""
    doc = re.match(r'\s*r?(?:"""|\'\'\')(.*?)(?:"""|\'\'\')\s*\n', source, re.S)
    if doc is None:
        raise ValueError("an example opens with a docstring whose first line is '# Title'")
    body = source[doc.end():]
    cells = []
    for chunk in CELL.split(body):
        lines = chunk.strip("\n").splitlines()
        text = []
        while lines and (lines[0].startswith("# ") or lines[0] == "#"):
            text.append(lines.pop(0)[2:])
        code = "\n".join(lines).strip("\n")
        if text or code:
            cells.append(("\n".join(text), code))
    return doc.group(1).strip(), cells


def run_cells(script: Path, out: Path) -> list[dict]:
    """Run the cells of ``script`` here (the child process's side): [{"stdout", "figures"}] per cell, the
    figures saved into ``out``."""
    import contextlib
    import io

    _, cells = split_cells(script.read_text(encoding="utf-8"))
    namespace = {"__name__": "__main__", "__file__": str(script)}
    results = []
    for i, (_, code) in enumerate(cells):
        buffer = io.StringIO()
        with contextlib.redirect_stdout(buffer):
            exec(compile(code, f"{script.name} (cell {i + 1})", "exec"), namespace)
        figures = []
        if "matplotlib.pyplot" in sys.modules:
            plt = sys.modules["matplotlib.pyplot"]
            for number in plt.get_fignums():
                png = out / f"{script.stem}-{i + 1}-{number}.png"
                plt.figure(number).savefig(png, dpi=100)
                figures.append(png.name)
            plt.close("all")
        results.append({"stdout": buffer.getvalue(), "figures": figures})
    return results


def run_example(script: Path, out: Path, timeout: float = TIMEOUT) -> list[dict]:
    """Run ``script`` in a fresh process and temporary folder; its cells' output (figures in ``out``).
    Raises RuntimeError with the script's traceback when it fails."""
    out.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONHASHSEED="0")
    env.pop("PYTHONPATH", None)
    with tempfile.TemporaryDirectory(prefix="frictionlab-gallery-") as work:
        try:
            done = subprocess.run([sys.executable, str(Path(__file__).resolve()), CHILD, str(script.resolve()),
                                   str(out.resolve())], cwd=work, env=env, capture_output=True, text=True,
                                  timeout=timeout)
        except subprocess.TimeoutExpired:
            raise RuntimeError(f"gallery example {script.name} took longer than {timeout:.0f} s") from None
    if done.returncode != 0:
        raise RuntimeError(f"gallery example {script.name} failed:\n{done.stderr[-4000:]}")
    return json.loads((out / f"{script.stem}.json").read_text(encoding="utf-8"))


def page(script: Path, results: list[dict]) -> str:
    """The Markdown page of an example: its text, code, printed output and figures, cell by cell."""
    doc, cells = split_cells(script.read_text(encoding="utf-8"))
    parts = [doc, f"*This example ran when the site was built. Its script: [{script.name}]({script.name}).*"]
    for (text, code), result in zip(cells, results):
        if text:
            parts.append(text)
        if code:
            parts.append(f"```python\n{code}\n```")
        if result["stdout"].strip():
            parts.append('<div class="gallery-output" markdown>\n\n```text\n'
                         f"{result['stdout'].rstrip()}\n```\n\n</div>")
        for png in result["figures"]:
            parts.append(f'<figure class="gallery-figure" markdown>\n![A figure made by {script.name}]({png})\n'
                         "</figure>")
    return "\n\n".join(parts) + "\n"


def title(script: Path) -> str:
    doc, _ = split_cells(script.read_text(encoding="utf-8"))
    return doc.splitlines()[0].lstrip("# ").strip()


def index(entries: list[tuple[Path, list[dict]]]) -> str:
    """The gallery's front page: a card per example, with its first figure."""
    cards = []
    for script, results in entries:
        figures = [png for r in results for png in r["figures"]]
        picture = f'<img src="{figures[0]}" alt="">' if figures else ""
        cards.append(f'<a href="{script.stem}/">{picture}<br>{html.escape(title(script))}</a>')
    return ("# Gallery of worked examples\n\nEach example is a script in `examples/gallery/` of the repository, "
            "run when this site is built: its code, what it printed and the figures it drew are on its page, "
            "made by the code of this version. Run one yourself with `python examples/gallery/NAME.py`.\n\n"
            '<div class="gallery-cards">\n' + "\n".join(cards) + "\n</div>\n")


#: The order of the gallery's front page (any other example follows, by name).
ORDER = ("golf_claim", "own_impact", "accuracy_cost", "velocity_step", "lab_record", "register_law", "equivalence",
         "dask_compare")


def examples() -> list[Path]:
    """The gallery's scripts, in ORDER then by name."""
    def place(p: Path) -> tuple[int, str]:
        return (ORDER.index(p.stem) if p.stem in ORDER else len(ORDER), p.stem)

    return sorted(EXAMPLES.glob("*.py"), key=place)


def on_files(files, config):
    """MkDocs hook: run every example and add its page, script and figures to the site under gallery/."""
    from concurrent.futures import ThreadPoolExecutor

    from mkdocs.exceptions import PluginError
    from mkdocs.structure.files import File

    scripts = examples()
    with tempfile.TemporaryDirectory(prefix="frictionlab-gallery-out-") as tmp, \
            ThreadPoolExecutor(max_workers=JOBS) as pool:  # each example runs in its own process
        out = Path(tmp)
        runs = [pool.submit(run_example, script, out) for script in scripts]
        try:
            entries = [(script, run.result()) for script, run in zip(scripts, runs)]
        except RuntimeError as exc:
            raise PluginError(str(exc)) from None
        for script, results in entries:
            files.append(File.generated(config, f"gallery/{script.stem}.md", content=page(script, results)))
            files.append(File.generated(config, f"gallery/{script.name}", content=script.read_bytes()))
            for png in (p for r in results for p in r["figures"]):
                files.append(File.generated(config, f"gallery/{png}", content=(out / png).read_bytes()))
    files.append(File.generated(config, "gallery/index.md", content=index(entries)))
    return files


if __name__ == "__main__":
    if sys.argv[1:2] == [CHILD]:  # the child process of run_example, in its temporary folder
        script, out = Path(sys.argv[2]), Path(sys.argv[3])
        out.mkdir(parents=True, exist_ok=True)
        sys.path.insert(0, str(script.parent))
        (out / f"{script.stem}.json").write_text(json.dumps(run_cells(script, out)), encoding="utf-8")
    else:  # one example run as the build runs it: a fresh process in a temporary folder, its figures in OUT
        for cell in run_example(Path(sys.argv[1]), Path(sys.argv[2])):
            print(cell["stdout"], end="")
