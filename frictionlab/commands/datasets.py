"""``frictionlab datasets``: list the built-in datasets, show one, or rebuild the generated ones."""
from __future__ import annotations

import filecmp
import shutil
import tempfile
from pathlib import Path

from ..dataset import builtin_dir, builtin_names, load_dataset
from ..table import render


def add_parser(sub):
    p = sub.add_parser("datasets", help="list, show or rebuild the built-in datasets")
    p.add_argument("action", nargs="?", choices=("list", "show", "rebuild"), default="list")
    p.add_argument("name", nargs="?", help="dataset name or TOML path (for show)")
    p.add_argument("--out", type=Path, help="rebuild into this folder instead of the built-in one")
    p.add_argument("--check", action="store_true", help="rebuild into a temporary folder and compare with the "
                   "committed files; exit 1 if any differs")
    p.add_argument("--known-truth", action="store_true",
                   help="rebuild the known-truth datasets (default folder: ./examples/known-truth) instead of the "
                        "built-in ones")
    p.set_defaults(func=run)


def run(args) -> int:
    if args.action == "rebuild":
        return _rebuild(args)
    if args.action == "show":
        return _show(args.name)
    rows = []
    for name in builtin_names():
        d = load_dataset(name)
        rows.append({"name": d.name, "kind": d.kind, "points": len(d), "observable": d.observable,
                     "provenance": d.provenance.kind, "source": _short(d.provenance.source)})
    print(render(rows))
    print(f"\n{len(rows)} datasets in {builtin_dir()}; 'frictionlab datasets show NAME' for details.")
    return 0


def _short(s: str, n: int = 70) -> str:
    return s if len(s) <= n else s[: n - 3] + "..."


def _show(name) -> int:
    from ..errors import DatasetError

    if not name:
        raise DatasetError("datasets show needs a dataset name or TOML path")
    d = load_dataset(name)
    print(f"{d.name}: {d.kind}, {len(d)} points, observable {d.observable} [{d.units[d.observable]}]")
    print(f"  file:        {d.path}")
    print(f"  description: {d.description}")
    print(f"  provenance:  {d.provenance.kind}; {d.provenance.source}")
    if d.provenance.method:
        print(f"  method:      {d.provenance.method}")
    if d.provenance.command:
        print(f"  regenerate:  {d.provenance.command}" + (f" (seed {d.provenance.seed})" if d.provenance.seed is not None else ""))
    if d.provenance.truth:
        print(f"  truth:       {d.provenance.truth}")
    if d.fixed:
        print(f"  fixed:       {d.fixed} (SI)")
    if d.reported:
        print(f"  reported:    {d.reported}")
    if d.scene is not None:
        print(f"  scene:       {d.scene}")
    return 0


def _rebuild(args) -> int:
    from ..datagen import GENERATORS, KNOWN_TRUTH, KNOWN_TRUTH_DIR, rebuild

    generators = KNOWN_TRUTH if args.known_truth else GENERATORS
    home = (args.out or KNOWN_TRUTH_DIR) if args.known_truth else builtin_dir()
    if args.check:
        with tempfile.TemporaryDirectory() as tmp:
            written = rebuild(Path(tmp), generators)
            differ = [p.name for p in written
                      if not (home / p.name).exists() or not filecmp.cmp(p, home / p.name, shallow=False)]
        if differ:
            print(f"differ from the committed files: {', '.join(differ)}")
            return 1
        print(f"{len(written)} generated files equal the committed ones in {home}")
        return 0
    from ..errors import OutputError

    out = args.out or home
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{out}: cannot create the output folder: {exc.strerror or exc}") from None
    with tempfile.TemporaryDirectory(dir=out) as tmp:
        written = rebuild(Path(tmp), generators)
        for p in written:  # all generated first, then moved: no half-rebuilt folder
            shutil.move(str(p), out / p.name)
    print(f"wrote {len(written)} files to {out}")
    return 0
