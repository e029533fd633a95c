"""``frictionlab bench``: work-precision diagrams and tables for every scene kind."""
from __future__ import annotations

import sys


def add_parser(sub):
    from ..cli import subcommand

    p = subcommand(sub, "bench", help="work-precision diagrams (error vs time) for every solver and tolerance",
                   examples="""  frictionlab bench --quick --out bench-quick     # a smoke run, about a minute
  frictionlab bench --out bench --force           # the full study, about 25 minutes""",
                   description="Solve each scene kind with RK45, DOP853, LSODA, Radau and BDF at rtol 1e-3..1e-12, "
                                   "the closed form, the paper's series and the batch engine; write one PNG per scene "
                                   "kind plus workprecision.csv/.md and environment.json (hardware, versions); "
                                   "then fit laws at each tolerance (fit_tolerance.csv): fitted values, error bars, "
                                   "fit time and whether the ranking changes.")
    p.add_argument("--out", default="bench", help="output folder, written whole or not at all (default: bench)")
    p.add_argument("--quick", action="store_true", help="3 tolerances, 3 repeats, small batches (a smoke run)")
    p.add_argument("--force", action="store_true", help="replace an existing output folder")
    p.add_argument("--no-fits", dest="fits", action="store_false",
                   help="skip the study of what the tolerance does to fitted parameters, error bars, time and ranking")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..pipeline.bench import run_bench
    from ..pipeline.benchplot import write_bench

    _check_out(args)
    import datetime as _dt

    def progress(msg):
        if not args.quiet:
            print(f"{_dt.datetime.now():%Y-%m-%d %H:%M:%S} bench: {msg}", file=sys.stderr, flush=True)

    result = run_bench(quick=args.quick, fits=args.fits, progress=progress)
    files = write_bench(args.out, result, force=args.force)
    env = result["env"]
    print(f"wrote {args.out}/: {', '.join(files)}")
    print(f"hardware: {env['cpu']}, {env['cores']} cores; "
          + ", ".join(f"{k} {v}" for k, v in env["versions"].items()))
    return 0


def _check_out(args):
    """Fail before the (long) measurement if the output folder cannot be written."""
    from pathlib import Path

    from ..core.errors import OutputError

    path = Path(args.out)
    if path.exists() and not args.force:
        raise OutputError(f"{path}: output folder exists; choose another --out or pass --force")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.exists():
        raise OutputError(f"{path}: parent folder {parent} does not exist")
