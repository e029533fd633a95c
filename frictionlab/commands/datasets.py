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
                     description="Write NAME.toml and NAME.csv for a dataset of KIND: every field and every "
                                 "observable commented, the [noise] kinds (known, estimated, none), materials and "
                                 "compliance examples where they apply, and example rows computed from a law "
                                 "(labelled synthetic) to be replaced with your data. The pair loads as it is: "
                                 "'frictionlab datasets show NAME.toml'.",
                     examples="""  frictionlab datasets template impact
  frictionlab datasets template spring-slider --name velstep --out data/
  frictionlab datasets template incline --name slide --out data/""")
    tpl.add_argument("kind", choices=KINDS, metavar="KIND", help=f"one of {', '.join(KINDS)}")
    tpl.add_argument("--name", default="my-data", help="dataset and file name (default: my-data)")
    tpl.add_argument("--out", type=Path, default=Path("."), help="folder to write into (default: here)")
    tpl.add_argument("--force", action="store_true", help="replace existing files")
    tpl.set_defaults(func=_template)
    _add_import(acts)
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


def _add_import(acts):
    from ..cli import subcommand

    imp = subcommand(acts, "import", help="turn a raw laboratory record into a dataset (velocity steps)",
                     description="Read a raw record and write NAME.toml and NAME.csv, a measured dataset. FORMAT "
                                 "velstep: whitespace-separated Time(s) Displ(microns) Friction "
                                 "EffectiveNormalstress(MPa), one velocity step per file (the sliced records of the "
                                 "steadystate routine, Giacomel et al. 2024). The load-point velocities and step time "
                                 "come from the displacement record; the machine stiffness is estimated from the "
                                 "loading after the step unless given (fit it with --free spring.stiffness).",
                     examples="""  frictionlab datasets import velstep velstep1.txt --name velstep1 --out data/ \\
      --source 'pgiacomel/steadystate, velstep1_TR2_exp013_sepiolite.txt' --license MIT \\
      --citation 'Giacomel et al., Geosphere (2024), doi:10.1130/GES02739.1'
  frictionlab fit rate-state-aging data/velstep1.toml --free spring.stiffness='0.0005 1/um:1 1/um'""")
    imp.add_argument("format", choices=("velstep",), metavar="FORMAT", help="raw format: velstep")
    imp.add_argument("raw", type=Path, metavar="RAWFILE", help="the raw record")
    imp.add_argument("--name", required=True, help="dataset and file name")
    imp.add_argument("--out", type=Path, default=Path("."), help="folder to write into (default: here)")
    imp.add_argument("--points", type=int, default=600, help="samples to keep (default 600)")
    imp.add_argument("--steps", type=int, default=1, help="velocity steps in the record (default 1)")
    imp.add_argument("--detrend", action="store_true", help="remove friction's slip trend, a straight line in "
                     "displacement fitted before the step (default: keep the record as measured)")
    imp.add_argument("--stiffness", help="machine stiffness per unit normal stress, e.g. '0.01 1/um' (default: "
                                         "estimated from the loading after the step)")
    imp.add_argument("--source", default="", help="where the record comes from (default: its path)")
    imp.add_argument("--license", default="", help="the record's license, e.g. MIT")
    imp.add_argument("--citation", default="", help="what to cite")
    imp.add_argument("--force", action="store_true", help="replace existing files")
    imp.set_defaults(func=_import)


def _import(args) -> int:
    import shlex

    from ..core.errors import OutputError, ParameterError
    from ..core.files import write_files
    from ..core.names import check_name
    from ..core.units import to_si
    from ..io.dataset import load_dataset
    from ..io.velstep import velstep_dataset

    check_name(args.name, "datasets import --name", OutputError)  # before any path is made of it
    if not 10 <= args.points <= 100_000 or not 1 <= args.steps <= 50:
        raise ParameterError("datasets import: --points must be 10 to 100000 and --steps 1 to 50")
    if not args.out.is_dir():
        raise OutputError(f"{args.out}: folder does not exist")
    paths = args.out / f"{args.name}.toml", args.out / f"{args.name}.csv"
    if any(p.resolve() == args.raw.resolve() for p in paths):
        raise OutputError(f"{args.raw}: the output would overwrite the raw record; choose another --name or --out")
    for p in paths:
        if p.exists() and not args.force:
            raise OutputError(f"{p}: exists; choose another --name or --out, or pass --force")
    k = to_si(args.stiffness, "1/m", "--stiffness") if args.stiffness else None
    command = "frictionlab datasets import velstep " + " ".join(shlex.quote(a) for a in (
        args.raw.name, "--name", args.name, "--points", str(args.points), "--steps", str(args.steps))) + (
        " --detrend" if args.detrend else "") + (f" --stiffness {shlex.quote(args.stiffness)}" if k else "")
    toml, csv, imp = velstep_dataset(args.raw, args.name, steps=args.steps, points=args.points,
                                     detrend=args.detrend, stiffness=k, source=args.source,
                                     license=args.license, citation=args.citation, command=command)
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:  # the pair must load before it is written
        (Path(tmp) / paths[0].name).write_text(toml)
        (Path(tmp) / paths[1].name).write_text(csv)
        load_dataset(Path(tmp) / paths[0].name)
    write_files({paths[0]: toml, paths[1]: csv}, force=args.force)  # both or neither
    v = " -> ".join(f"{x * 1e6:g} um/s" for x in imp.velocities)
    print(f"wrote {paths[0]} and {paths[1]}: {len(imp.index)} samples, load point {v} (step at "
          f"{', '.join(f'{t:.6g} s' for t in imp.step_times)}), k = {imp.stiffness * 1e-6:.3g} 1/um "
          f"({'stated' if imp.stiffness_stated else 'estimated; fit it with --free spring.stiffness'})")
    return 0


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
    from ..io import external

    here = external.present()
    missing = sorted(set(external.RECORDS) - set(here))
    if here:
        print(f"measured records present in {', '.join(map(str, external.raw_dirs()))}: {', '.join(here)}")
    if missing:
        print(f"measured records not in the repository (license of their source; see 'datasets show NAME' for where "
              f"to place them): {', '.join(missing)}")
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
    print(f"  noise:       {d.noise_kind} ({d.noise_note}){': ' + values if values else ''}")
    if d.stated:
        from ..io.noise import STATED

        print("  stated:      " + ", ".join(f"{k} = {quantity_text(v, STATED[k])} ± {quantity_text(p, STATED[k])}"
                                            for k, (v, p) in d.stated.items()))
    if d.time_zero:
        print(f"  time zero:   t = 0 at {d.time_zero:.10g} s of the file's clock (subtracted from column t)")
    print(f"  provenance:  {pv.kind}; {pv.source}")
    if pv.license:
        print(f"  license:     {pv.license}")
    if pv.citation:
        print(f"  cite:        {pv.citation}")
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
    from ..core.files import write_files
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
    write_files({toml_path: toml, csv_path: csv}, force=args.force)  # both or neither
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
    created = not out.exists()
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{out}: cannot create the output folder: {exc.strerror or exc}") from None
    from ..core.files import output_lock

    try:
        with output_lock(out), tempfile.TemporaryDirectory(dir=out) as tmp:  # one rebuild of a folder at a time
            written = rebuild(Path(tmp), generators)
            for p in written:  # all generated first, then moved: no half-rebuilt folder
                shutil.move(str(p), out / p.name)
    except BaseException:  # an error, ^C, SIGTERM, SIGHUP: the folder this run created goes too
        if created:
            shutil.rmtree(out, ignore_errors=True)
        raise
    print(f"wrote {len(written)} files to {out}")
    return 0
