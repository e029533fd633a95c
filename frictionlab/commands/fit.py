"""``frictionlab fit LAW DATASET...``: fit one law to one dataset or, jointly, to several."""
from __future__ import annotations

import json
from pathlib import Path

from ..core.errors import OutputError, ParameterError, SolverError
from ..physics.freeable import SCENE_QUANTITIES


def add_parser(sub):
    from ..cli import ListAction, subcommand

    p = subcommand(sub, "fit", help="fit a law to datasets (several datasets: a global fit)",
                   description="Fit LAW to one dataset, or to several at once with shared law parameters. Prints "
                               "the parameters with standard errors, the fit statistics and what the data cannot "
                               "determine.",
                   examples="""  frictionlab fit wear impact-golf-v28
  frictionlab fit wear impact-golf-v28 --solver series --json fit.json
  frictionlab fit area-rate impact-golf-v28 impact-golf-v61 --local mu       # a global fit, mu per dataset
  frictionlab fit couette incline-oil-a100 --fix eta='0.1 Pa s'
  frictionlab fit wear my.toml --free u0='8 m/s:14 m/s'
  frictionlab fit rate-state-aging my-velocity-step.toml --trend none --stiffness hold""")
    p.add_argument("law", help="registered law name (see 'frictionlab laws')")
    p.add_argument("datasets", nargs="+", metavar="DATASET", help="built-in dataset name or TOML path")
    p.add_argument("--solver", default="auto", help="auto (exact where a closed form exists, else ode), exact, "
                   "series, ode or ode:METHOD (default: auto)")
    p.add_argument("--free", action=ListAction, default=[], metavar="NAME=LO:HI[:START]",
                   help="fit a scene quantity per dataset within bounds, with units, e.g. u0='8 m/s:14 m/s'; "
                        f"names: {', '.join(SCENE_QUANTITIES)}")
    p.add_argument("--fix", action=ListAction, default=[], metavar="NAME=VALUE",
                   help="hold a law parameter, with its unit, e.g. eta='0.1 Pa s'")
    p.add_argument("--local", action=ListAction, default=[], metavar="NAME",
                   help="in a global fit, fit this law parameter separately per dataset")
    p.add_argument("--observable", help="fit this column instead of the dataset's observable (e.g. theta)")
    p.add_argument("--derive", choices=("poly9", "spline"), help="fit omega derived from the theta column")
    p.add_argument("--rtol", type=float, metavar="R",
                   help=f"relative tolerance of every ODE solve in the fit (default {FIT_RTOL:g}, the library's "
                        "FIT_RTOL: a fit solves the model hundreds of times; 'simulate' defaults to 1e-10 for one "
                        "solve; closed forms and the series ignore it)")
    p.add_argument("--trend", choices=("auto", "fit", "none"), default="auto",
                   help="velocity-step fits (rate-and-state on spring-slider data): fit a linear friction-vs-"
                        "displacement trend jointly with the law (auto: on measured data)")
    p.add_argument("--stiffness", choices=("auto", "fit", "hold"), default="auto",
                   help="velocity-step fits: fit the machine stiffness from the dataset's value (auto: on measured "
                        "data, or where --free names spring.stiffness) or hold it")
    p.add_argument("--json", type=Path, metavar="FILE", help="also write the result as JSON")
    p.add_argument("--fit-timeout", type=fit_timeout, default=FIT_TIMEOUT, metavar="SECONDS",
                   help=f"time budget of the fit; past it the fit fails with that reason (default {FIT_TIMEOUT:g})")
    p.set_defaults(func=run)


def _split(text: str, what: str) -> tuple[str, str]:
    name, sep, rest = text.partition("=")
    if not sep or not name.strip() or not rest.strip():
        raise ParameterError(f"{what} {text!r}: expected NAME=VALUE")
    return name.strip(), rest.strip()


def parse_free(items) -> dict:
    """'u0=8 m/s:14 m/s[:12 m/s]' -> {'u0': (8.0, 14.0[, 12.0])} in SI (``core.units.as_range``, as the API)."""
    from ..core.units import as_range

    out = {}
    for item in items:
        name, rest = _split(item, "--free")
        if name not in SCENE_QUANTITIES:
            raise ParameterError(f"--free {name}: not a scene quantity; choose from {', '.join(SCENE_QUANTITIES)}")
        if len(rest.split(":")) not in (2, 3):
            raise ParameterError(f"--free {item!r}: expected NAME=LOWER:UPPER or NAME=LOWER:UPPER:START")
        out[name] = as_range(rest, SCENE_QUANTITIES[name], f"--free {name}")
    return out


def fit_timeout(value: str) -> float:
    """--fit-timeout SECONDS: a positive number (argparse type)."""
    import argparse
    import math

    try:
        t = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {value!r}") from None
    if not 0 < t < math.inf:
        raise argparse.ArgumentTypeError(f"expected a positive number of seconds, got {value!r}")
    return t


#: Default time budget of one fit [s]: far above the slowest built-in fit (an ODE fit, seconds).
FIT_TIMEOUT = 900.0
FIT_RTOL = 1e-6  # inference.fitting.predict.FIT_RTOL, here without importing the numerical stack for --help


def parse_fix(law, items) -> dict:
    from ..core.units import to_si

    out = {}
    for item in items:
        name, rest = _split(item, "--fix")
        spec = law.spec(name)
        out[name] = law.resolve({name: to_si(rest, spec.unit, f"--fix {name}")})[name]  # bounds checked
    return out


def run(args) -> int:
    from .early import check_datasets, check_laws

    check_laws([args.law], args.load)  # before the numerics are imported
    check_datasets(args.datasets)
    from ..core.inputs import check_apart
    from ..core.workers import process_pool
    from ..io.dataset import load_dataset
    from ..pipeline.budget import fit_within_budget
    from ..physics.registry import get_law
    from ..report import fit_json as _fit_json

    law = get_law(args.law)
    if args.json and not args.json.parent.is_dir():  # before the work, not after
        raise OutputError(f"{args.json}: cannot write: folder {args.json.parent} does not exist")
    datasets = [load_dataset(d) for d in args.datasets]
    if args.json:
        check_apart(args.json)  # never over a file the fit reads
    options = dict(solver=args.solver, free=parse_free(args.free), fixed=parse_fix(law, args.fix), local=args.local,
                   observable=args.observable, derive=args.derive, timeout=args.fit_timeout, rtol=args.rtol)
    choice = {"fit": True, "none": False, "hold": False}
    options.update({k: choice[v] for k, v in (("trend", args.trend), ("stiffness", args.stiffness)) if v != "auto"})
    from ..core.progress import Progress
    from ..physics.registry import is_third_party

    with process_pool(1, "fit"), Progress("fit", quiet=args.quiet, delay=2.0) as bar:  # a quick fit stays silent
        if args.fit_timeout is None or not is_third_party(law):  # fitted here (not in a child): it can report
            options["progress"] = bar
        result = fit_within_budget(law, datasets, **options)
    if result.status == "skipped":  # asked for explicitly, an inapplicable solver is an error, not a skip
        raise SolverError(result.reason)
    print(result.summary())
    if args.json:
        from ..core.files import atomic_write_text
        from ..report import clean as _clean

        atomic_write_text(args.json, json.dumps(_clean(_fit_json(result)), indent=1, allow_nan=False) + "\n")
    if result.status == "failed":  # caused by the law, the data or the budget given: exit 2, as bad input
        from ..core.errors import FitError

        raise FitError(f"fit: {result.law} on {', '.join(result.datasets)} failed: {result.reason}")
    return 0
