"""``frictionlab datasets``: list the built-in datasets, show one, start one of your own, rebuild the generated ones."""
from __future__ import annotations

import filecmp
import os
import shutil
import tempfile
from pathlib import Path


def add_parser(sub):
    from ..cli import subcommand
    from ..io.template import KINDS

    p = subcommand(sub, "datasets", help="list, show, import (raw laboratory records), template (start your own) or rebuild datasets",
                   description="Datasets are a CSV of columns plus a TOML of the same name that gives units, noise, "
                               "the scene and the provenance. 'datasets template KIND' writes a commented pair to "
                               "start from.",
                   examples="""  frictionlab datasets                       # the same as 'datasets list'
  frictionlab datasets show impact-golf-v28
  frictionlab datasets template impact --name my-impact --out .   # my-impact.toml + my-impact.csv
  frictionlab datasets import velstep experiment.txt --name exp --out data/   # one dataset per velocity step
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
    rb.add_argument("--slide-hold-slide", action="store_true",
                    help="rebuild the synthetic slide-hold-slide record (default folder: ./examples/slide-hold-slide)")
    rb.set_defaults(func=_rebuild)


def _add_import(acts):
    from ..cli import subcommand

    imp = subcommand(acts, "import", help="turn a raw laboratory record into datasets, one per velocity step",
                     description="Read a raw record and write measured datasets (NAME.toml + NAME.csv). FORMAT "
                                 "velstep: by default whitespace-, tab- or comma-separated Time(s) Displ(microns) Friction "
                                 "EffectiveNormalstress(MPa) (the records of the steadystate routine, Giacomel et al. "
                                 "2024), any number of velocity steps and holds. The displacement is segmented into "
                                 "straight pieces (optimal partitioning: the data choose the number of steps); each "
                                 "step's time is the kink of a continuous two-line fit, its velocities are fitted "
                                 "values, and a table of both with their standard errors is printed. One dataset per "
                                 "step (NAME-step1, NAME-step2, ...; NAME alone for one step) starts at a steady state "
                                 "the data show (the first new steady-state point after the step before, found as "
                                 "the steadystate routine does) and ends in the steady part after its step; --joint writes one dataset with every step, for "
                                 "a joint fit across steps. A jump of displacement without a change of velocity (a "
                                 "transducer reset) is stitched and reported. The machine stiffness is a start "
                                 "estimated from friction's loading after each step unless given. --columns reads "
                                 "any other lab's layout: which column is time, displacement and friction (or shear "
                                 "and normal stress, friction = shear / normal), each with its unit; tab-, comma-, "
                                 "semicolon- or space-separated, lines before the header and rows of text after it "
                                 "skipped; UTF-8 or UTF-16 text.",
                     examples="""  frictionlab datasets import velstep experiment.txt --name exp13 --out data/ \\
      --source 'my lab, run 13' --license CC-BY-4.0 --citation 'me et al. (2026)'
  frictionlab datasets import velstep experiment.txt --name exp13 --joint --out data/
  frictionlab datasets import velstep part1.txt part2.txt part3.txt --name exp13 --out data/
  frictionlab fit rate-state-aging data/exp13-step1.toml
  frictionlab datasets import velstep run.csv --name run --columns \\
      'time=Time ms, displacement=LP_disp mm, shear=Tau MPa, normal=SigmaN MPa'""")
    imp.add_argument("format", choices=("velstep",), metavar="FORMAT", help="raw format: velstep")
    imp.add_argument("raw", type=Path, nargs="+", metavar="RAWFILE", help="the raw record; several files of one "
                     "experiment (slices of one recording, in any order) are joined by time into one record")
    imp.add_argument("--name", required=True, help="dataset name, and file name: NAME-step1, ... for several steps")
    imp.add_argument("--out", type=Path, default=Path("."), help="folder to write into (default: here)")
    imp.add_argument("--joint", action="store_true", help="one dataset holding every step of the record (a joint "
                     "fit of a, b and Dc across steps) instead of one per step")
    imp.add_argument("--steps", type=int, metavar="N", help="check: the number of velocity steps expected (an error "
                                                           "names what was found when it differs)")
    imp.add_argument("--columns", metavar="SPEC", help="the record's own layout: \"time=NAME UNIT, "
                     "displacement=NAME UNIT, friction=NAME\" or with \"shear=NAME UNIT, normal=NAME UNIT\" instead "
                     "of friction (NAME: the header's name, quoted when it holds spaces, or #N for the N-th column; "
                     "UNIT: e.g. s, ms, um, mm, MPa, kN); default: the steadystate routine's four columns")
    imp.add_argument("--stiffness", help="start for the machine stiffness per unit normal stress, e.g. '0.01 1/um' "
                                         "(default: estimated from friction's loading after each step)")
    imp.add_argument("--source", default="", help="where the record comes from (default: its path)")
    imp.add_argument("--license", default="", help="the record's license, e.g. MIT")
    imp.add_argument("--citation", default="", help="what to cite")
    imp.add_argument("--force", action="store_true", help="replace existing files")
    imp.set_defaults(func=_import)


def _import(args) -> int:
    import math
    import shlex

    from ..core.errors import OutputError, ParameterError
    from ..core.files import atomic_files
    from ..core.names import check_name
    from ..core.units import to_si
    from ..io.dataset import from_meta
    from ..io.layout import parse_columns
    from ..io.velstep import analyse, dataset_toml, parts, summary, write_csv

    check_name(args.name, "datasets import --name", OutputError)  # before any path is made of it
    if args.steps is not None and not 1 <= args.steps <= 10_000:
        raise ParameterError(f"--steps: {args.steps} steps; expected a number from 1 to 10000")
    k = to_si(args.stiffness, "1/m", "--stiffness") if args.stiffness is not None else None
    if k is not None and not (k > 0 and math.isfinite(k)):
        raise ParameterError(f"--stiffness: {args.stiffness!r} must be a positive stiffness per unit normal stress, "
                             "e.g. '0.01 1/um'")
    layout = parse_columns(args.columns, "--columns") if args.columns is not None else None
    if not args.out.is_dir():
        raise OutputError(f"{args.out}: folder does not exist")
    from ..io.velstep_join import read_joined

    raw = read_joined(args.raw, columns=layout)
    imp = analyse(raw, args.name, joint=args.joint, stiffness=k, steps=args.steps)
    files, pairs = {}, []
    for w in imp.windows:
        paths = args.out / f"{w.name}.toml", args.out / f"{w.name}.csv"
        for p in paths:
            if any(p.resolve() == r.resolve() for r in args.raw):
                raise OutputError(f"{p}: would overwrite the raw record; choose another --name or --out")
            if os.path.lexists(p) and not args.force:
                raise OutputError(f"{p}: exists; choose another --name or --out, or pass --force")
        command = "frictionlab datasets import velstep " + " ".join(shlex.quote(a) for a in (
            *(r.name for r in args.raw), "--name", args.name)) + (" --joint" if args.joint else "") + (
            f" --columns {shlex.quote(layout.text())}" if layout else "") + (
            f" --stiffness {shlex.quote(args.stiffness)}" if k else "")
        toml = dataset_toml(imp, w, source=args.source, license=args.license, citation=args.citation,
                            command=command)
        meta, cols = parts(imp, w, toml, rows=20_000)
        from_meta(meta, paths[0], raw=cols)  # the pair loads before it is written
        files[paths[1]] = lambda fh, w=w: write_csv(fh, imp, w)
        files[paths[0]] = lambda fh, toml=toml: fh.write(toml)
        pairs.append((w, paths))
    with atomic_files(list(files), force=args.force) as staged:  # every file of every step, or none
        for write, tmp in zip(files.values(), staged):
            with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
                write(fh)
    for line in summary(imp):
        print(line)
    for w, (toml_path, csv_path) in pairs:
        v = " -> ".join(f"{x * 1e6:.4g}" for x in w.velocities)
        print(f"wrote {_shown(toml_path)} and {_shown(csv_path)}: {raw.span(w.a, w.b).split(' of ')[0]} ({w.b - w.a} samples), "
              f"{v} um/s, k start {w.stiffness * 1e-6:.3g} 1/um ({w.stiffness_from}; fitted with the law)"
              + (f"; the window {w.start_note}" if w.start_note else ""))
    return 0


def _shown(path: Path) -> str:
    """A path as the user would write it: relative to the current folder when it lies below it."""
    rel = os.path.relpath(path)
    return str(path) if rel.startswith("..") else rel


def _list(args) -> int:
    from ..core.table import render
    from ..io import external
    from ..io.dataset import available_names, builtin_dir, load_dataset

    rows = []
    for name in available_names():
        d = load_dataset(name)
        rows.append({"name": d.name, "kind": d.kind, "points": len(d), "observable": d.observable,
                     "provenance": d.provenance.kind, "source": _short(d.provenance.source)})
    print(render(rows))
    here = external.present()
    print(f"\n{len(rows)} datasets: {len(rows) - len(here)} in {builtin_dir()}"
          + (f", {len(here)} measured records present in {', '.join(map(str, external.raw_dirs()))}" if here else "")
          + "; 'frictionlab datasets show NAME' for details, 'frictionlab datasets template KIND' to start your own.")
    missing = [n for n in external.RECORDS if n not in here]
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
    from ..io.datagen import GENERATORS, KNOWN_TRUTH, KNOWN_TRUTH_DIR, SLIDE_HOLD_SLIDE, SLIDE_HOLD_SLIDE_DIR, rebuild
    from ..io.dataset import builtin_dir

    generators = KNOWN_TRUTH if args.known_truth else SLIDE_HOLD_SLIDE if args.slide_hold_slide else GENERATORS
    home = ((args.out or KNOWN_TRUTH_DIR) if args.known_truth else
            (args.out or SLIDE_HOLD_SLIDE_DIR) if args.slide_hold_slide else builtin_dir())
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
