"""``frictionlab datasets``: list the built-in datasets, show one, start one of your own, rebuild the generated ones."""
from __future__ import annotations

import filecmp
import shutil
import tempfile
from pathlib import Path


def add_parser(sub):
    from ..cli import subcommand
    from ..io.template import KINDS

    p = subcommand(sub, "datasets", help="list, show, start (template) or rebuild datasets",
                   description="Datasets are a CSV of columns plus a TOML of the same name that gives units, noise, "
                               "the scene and the provenance. 'datasets template KIND' writes a commented pair to "
                               "start from.",
                   examples="""  frictionlab datasets                       # the same as 'datasets list'
  frictionlab datasets show impact-golf-v28
  frictionlab datasets template impact --name my-impact --out .   # my-impact.toml + my-impact.csv
  frictionlab datasets rebuild --check""")
    p.set_defaults(func=_list)
    acts = p.add_subparsers(dest="action", metavar="ACTION")
    ls = subcommand(acts, "list", help="list the built-in datasets (the default)",
                    description="List the built-in datasets: kind, points, observable, provenance and source.",
                    examples="  frictionlab datasets list")
    ls.set_defaults(func=_list)
    show = subcommand(acts, "show", help="describe one dataset in readable units",
                      description="Describe one dataset: columns and units, noise, the scene in readable units "
                                  "(g, mm, us, deg, rpm), fixed and reported values, and its provenance.",
                      examples="""  frictionlab datasets show impact-golf-v28
  frictionlab datasets show ./my-impact.toml""")
    show.add_argument("name", metavar="NAME_OR_TOML", help="built-in dataset name or TOML path")
    show.set_defaults(func=_show)
    tpl = subcommand(acts, "template", help="write a commented TOML + CSV pair to start a dataset from",
                     description="Write NAME.toml and NAME.csv for a dataset of KIND: every field commented, "
                                 "example rows computed from a law (labelled synthetic) to be replaced with your "
                                 "data. The pair loads as it is: 'frictionlab datasets show NAME.toml'.",
                     examples="""  frictionlab datasets template impact
  frictionlab datasets template incline --name slide --out data/""")
    tpl.add_argument("kind", choices=KINDS, metavar="KIND", help=f"one of {', '.join(KINDS)}")
    tpl.add_argument("--name", default="my-data", help="dataset and file name (default: my-data)")
    tpl.add_argument("--out", type=Path, default=Path("."), help="folder to write into (default: here)")
    tpl.add_argument("--force", action="store_true", help="replace existing files")
    tpl.set_defaults(func=_template)
    rb = subcommand(acts, "rebuild", help="regenerate the generated built-in (or known-truth) datasets",
                    description="Regenerate every generated built-in dataset from its command and seed; with "
                                "--known-truth, the known-truth datasets of examples/known-truth instead.",
                    examples="""  frictionlab datasets rebuild --check     # exit 1 if any committed file differs
  frictionlab datasets rebuild --out /tmp/data
  frictionlab datasets rebuild --known-truth --check""")
    rb.add_argument("--out", type=Path, help="rebuild into this folder instead of the built-in one")
    rb.add_argument("--check", action="store_true", help="rebuild into a temporary folder and compare with the "
                    "committed files; exit 1 if any differs")
    rb.add_argument("--known-truth", action="store_true",
                    help="rebuild the known-truth datasets (default folder: ./examples/known-truth) instead of the "
                         "built-in ones")
    rb.set_defaults(func=_rebuild)


def _list(args) -> int:
    from ..core.table import render
    from ..io.dataset import builtin_dir, builtin_names, load_dataset

    rows = []
    for name in builtin_names():
        d = load_dataset(name)
        rows.append({"name": d.name, "kind": d.kind, "points": len(d), "observable": d.observable,
                     "provenance": d.provenance.kind, "source": _short(d.provenance.source)})
    print(render(rows))
    print(f"\n{len(rows)} datasets in {builtin_dir()}; 'frictionlab datasets show NAME' for details, "
          "'frictionlab datasets template KIND' to start your own.")
    return 0


def _short(s: str, n: int = 70) -> str:
    return s if len(s) <= n else s[: n - 3] + "..."


def _values(table: dict) -> str:
    """'omega_peak = 6700 rpm, b = 0.81' for a TOML table (strings as written, numbers plainly)."""
    out = []
    for k, v in table.items():
        if isinstance(v, dict):
            out.append(f"{k}: {_values(v)}")
        else:
            out.append(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}")
    return ", ".join(out)


def _show(args) -> int:
    from ..core.display import describe, quantity_text
    from ..io.dataset import load_dataset

    d = load_dataset(args.name)
    pv = d.provenance
    print(f"{d.name}: {d.kind}, {len(d)} {'impacts' if d.kind == 'impact-outcome' else 'points'}, "
          f"fitted column {d.observable} [{d.units[d.observable] or 'plain number'}]")
    print(f"  file:        {d.path}")
    if d.description:
        print(f"  description: {d.description}")
    print("  columns:     " + ", ".join(f"{c} [{u or '-'}]" for c, u in d.units.items()))
    def sd(c, v):
        return f"{c} ± {quantity_text(v * _to_file_unit(d, c), d.units.get(c, ''))}" if d.units.get(c) else f"{c} ± {v:.4g}"

    values = ", ".join(sd(c, v) for c, v in d.noise.items() if d.noise_kind != "none")
    print(f"  noise:       {d.noise_kind}{': ' + values if values else ''} ({d.noise_note})")
    if d.stated:
        from ..io.noise import STATED

        print("  stated:      " + ", ".join(f"{k} = {quantity_text(v, STATED[k])} ± {quantity_text(p, STATED[k])}"
                                            for k, (v, p) in d.stated.items()))
    print(f"  provenance:  {pv.kind}; {pv.source}")
    if pv.method:
        print(f"  method:      {pv.method}")
    if pv.command:
        print(f"  regenerate:  {pv.command}" + (f" (seed {pv.seed})" if pv.seed is not None else ""))
    if pv.truth:
        print(f"  truth:       {_values(pv.truth)}")
    if d.fixed:
        print("  fixed:       " + ", ".join(f"{k} = {quantity_text(v, d.fixed_units.get(k, ''))}"
                                            for k, v in d.fixed.items()))
    if d.reported:
        print(f"  reported:    {_values(d.reported)}")
    if d.scene is not None:
        lines = describe(d.scene)
        print(f"  scene:       {lines[0]}")
        for line in lines[1:]:
            print("             " + line)
    return 0


def _to_file_unit(d, column: str) -> float:
    """Factor from SI to the unit the dataset's file uses for ``column``."""
    from ..core.units import unit_factor
    from ..io.dataset import COLUMN_SI

    return 1.0 / unit_factor(d.units[column], COLUMN_SI.get(column, ""), column)


def _template(args) -> int:
    from ..core.errors import OutputError
    from ..core.files import atomic_write_text
    from ..core.names import check_name
    from ..io.template import template

    check_name(args.name, "datasets template --name", OutputError)  # before any path is made of it
    if not args.out.is_dir():
        raise OutputError(f"{args.out}: folder does not exist")
    toml_path, csv_path = args.out / f"{args.name}.toml", args.out / f"{args.name}.csv"
    for p in (toml_path, csv_path):
        if p.exists() and not args.force:
            raise OutputError(f"{p}: exists; choose another --name or --out, or pass --force")
    toml, csv = template(args.kind, args.name)
    atomic_write_text(csv_path, csv)
    atomic_write_text(toml_path, toml)
    print(f"wrote {toml_path} and {csv_path}: replace the example rows with your data, then "
          f"'frictionlab datasets show {toml_path}'")
    return 0


def _rebuild(args) -> int:
    from ..io.datagen import GENERATORS, KNOWN_TRUTH, KNOWN_TRUTH_DIR, rebuild
    from ..io.dataset import builtin_dir

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
    from ..core.errors import OutputError

    out = args.out or home
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{out}: cannot create the output folder: {exc.strerror or exc}") from None
    from ..core.files import output_lock

    with output_lock(out), tempfile.TemporaryDirectory(dir=out) as tmp:  # one rebuild of a folder at a time
        written = rebuild(Path(tmp), generators)
        for p in written:  # all generated first, then moved: no half-rebuilt folder
            shutil.move(str(p), out / p.name)
    print(f"wrote {len(written)} files to {out}")
    return 0
