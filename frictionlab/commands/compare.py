"""``frictionlab compare``: fit every law to every dataset, rank, test the equivalence, write a report."""
from __future__ import annotations

import os
from pathlib import Path

from ..core.errors import FitError, OutputError, ParameterError
from ..core.progress import Progress
from .fit import FIT_TIMEOUT, fit_timeout

#: Default number of bootstrap resamples: about +15 s (idle) to +35 s (busy machine) on 2 cores for the
#: built-in datasets, on top of 35-60 s without it.
BOOTSTRAP_N = 150
#: The most replicates per law of the (sequential) equivalence test (the library's ``equivalence.REPLICATES``, kept here so that
#: ``--help`` imports no numerical package; a test checks that the two agree).
REPLICATES = 400
#: ODE tolerances at which ``--tolerance`` refits the ODE laws of one dataset for the report: a looser one
#: and a tighter one than the fits' default (predict.FIT_RTOL, 1e-6), so the report shows the default converged.
#: A robustness check beside the answer, run on demand: it changes no fit, ranking or verdict, and costs about a
#: tenth of a default comparison; the report says when it was not run and how to run it.
TOLERANCE_RTOLS = (1e-3, 1e-10)
MAX_JOBS = 64  # worker processes: more only forks processes that wait
MAX_BOOTSTRAP = 100_000  # resamples: far past where percentile intervals stop moving


def add_parser(sub):
    from ..cli import ListAction, subcommand

    p = subcommand(sub, "compare", help="compare laws on datasets and write a report folder",
                   description="Fit every law to every dataset (default: the laws of each dataset's kind, the "
                               "four mission laws on impacts and inclines and rate-and-state aging, slip, PRZ and Nagata on "
                               "spring-sliders, on every built-in dataset and measured record present), rank them, test the paper's equivalence claim, and write report.md, "
                               "report.html, figures/, ranking.csv and results.json. Two defaults differ from "
                               "the library's fl.compare(), which runs only what it is asked for: --bootstrap "
                               f"{BOOTSTRAP_N} (API bootstrap=0) and --fit-timeout {FIT_TIMEOUT:g} s (API "
                               "fit_timeout=None). The tolerance check runs only with --tolerance.",
                   examples="""  frictionlab compare                          # each kind's laws on every built-in dataset into ./report
  frictionlab compare --laws wear,area-rate --data impact-golf-v28 --out golf
  frictionlab compare --data my.toml --data impact-golf-v61 --solver exact --solver series
  frictionlab compare --tolerance --out full    # also refit the ODE laws at other solver tolerances
  frictionlab compare --laws rate-state-aging,rate-state-slip --data spring-slider-small-step \
      --pairs rate-state-aging:rate-state-slip --bootstrap-all --out steps   # aging against slip
  frictionlab compare --bootstrap 0 --quiet --out quick   # fastest, no progress lines""")
    p.add_argument("--laws", "--law", action=ListAction, metavar="NAME", help="law names, or 'all' for every registered law "
                   "(default by dataset kind: coulomb, area-rate, wear, couette on impacts and inclines; "
                   "rate-state-aging, rate-state-slip, rate-state-prz on spring-sliders)")
    p.add_argument("--data", action=ListAction, nargs="+", metavar="NAME_OR_TOML",
                   help="datasets, several after one --data (e.g. a shell glob), comma-separated or repeated "
                        "(default: every built-in dataset and every measured record present)")
    p.add_argument("--solver", "--solvers", action=ListAction, metavar="SOLVER",
                   help="exact, series, ode[:METHOD] or auto (default: exact where a closed form exists else ode, "
                        "plus series where it applies)")
    p.add_argument("--free", action=ListAction, default=[], metavar="NAME=LO:HI",
                   help="fit a scene quantity per dataset within bounds, with units, e.g. u0='5 m/s:31 m/s'")
    p.add_argument("--out", type=Path, default=Path("report"), help="report folder (default: ./report)")
    p.add_argument("--force", action="store_true", help="replace an existing report folder")
    p.add_argument("--jobs", type=int, default=min(os.cpu_count() or 1, 4),
                   help="worker processes (default: number of CPUs, at most 4)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run the fits, refits, tests, bootstrap and figures on the Dask cluster whose scheduler is "
                        "at ADDRESS (e.g. tcp://10.0.0.5:8786; needs pip install 'frictionlab[dask]'); --jobs is "
                        "then unused")
    p.add_argument("--pairs", "--pair", action=ListAction, metavar="LAW:LAW",
                   help="the pairs of laws whose equivalence is tested, e.g. rate-state-aging:rate-state-slip "
                        "(default: wear:area-rate, wear:couette, coulomb:wear, where both laws are compared)")
    from ..core.cluster import CONNECT_TIMEOUT, TASK_TIMEOUT, WAIT_WORKERS

    p.add_argument("--connect-timeout", type=fit_timeout, default=CONNECT_TIMEOUT, metavar="SECONDS",
                   help=f"with --scheduler: how long the scheduler has to answer (default {CONNECT_TIMEOUT:g})")
    p.add_argument("--wait-workers", type=fit_timeout, default=WAIT_WORKERS, metavar="SECONDS",
                   help="with --scheduler: how long to wait for a worker when the cluster has none, at the start or "
                        f"after its last worker is lost (default {WAIT_WORKERS:g})")
    p.add_argument("--task-timeout", type=fit_timeout, default=TASK_TIMEOUT, metavar="SECONDS",
                   help="with --scheduler: how long one task (a dataset's fits, tests and bootstrap, or a batch of "
                        f"figures) may run on a worker (default {TASK_TIMEOUT:g})")
    p.add_argument("--no-equivalence", action="store_true", help="skip the equivalence (discrimination) tests")
    p.add_argument("--replicates", type=int, default=REPLICATES, metavar="R",
                   help=f"the most replicate datasets per law in the equivalence test's sequential parametric bootstrap "
                        f"(default: {REPLICATES}; at least 20; sampling stops in batches of 20 once the verdict is "
                        "clear; the Monte-Carlo error of each p-value is reported)")
    p.add_argument("--margin", default=None, metavar="DELTA",
                   help="the equivalence margin: two laws are 'equivalent within delta' when an upper 95%% bound of "
                        "the RMS distance of their best curves lies below delta; a multiple of each dataset's noise "
                        "sigma (e.g. 2, the default 1) or a quantity in the observable's unit (e.g. '150 rpm')")
    p.add_argument("--family", choices=("report", "group"), default="report",
                   help="the family whose error rate the tests keep: 'report' (default: Holm over every hypothesis "
                        "of the report's equivalence tests) or 'group' (Holm within each dataset group only)")
    p.add_argument("--no-transfer", dest="transfer", action="store_false",
                   help="skip predicting across the datasets of a group and the shared-parameter fits")
    p.add_argument("--bootstrap", type=int, default=BOOTSTRAP_N, metavar="N",
                   help=f"parametric replicates per dataset for confidence intervals and first-place shares "
                        f"(default: {BOOTSTRAP_N}; 0: none; fl.compare() defaults to 0)")
    p.add_argument("--seed", type=int, default=0,
                   help="seed of the bootstrap resamples and of the equivalence test's replicates (default: 0)")
    p.add_argument("--bootstrap-all", action="store_true",
                   help="also bootstrap, and run the equivalence test on, the slow datasets: where a law needs the "
                        "ODE solver, and impact-outcome sets (minutes per 100 resamples)")
    p.add_argument("--tolerance", dest="tolerance", action="store_true", default=False,
                   help="also refit the ODE laws of one dataset at other solver tolerances "
                        f"({' and '.join(f'{r:.0e}'.replace('e-0', 'e-') for r in TOLERANCE_RTOLS)}): a robustness "
                        "check beside the answer, changing no verdict (default: not run, and the report says so)")
    p.add_argument("--no-accuracy", dest="accuracy", action="store_false",
                   help="skip 'what accuracy costs' (each solver's error and time against the most accurate one, per "
                        "law and dataset; by default it runs where it is cheap, and everywhere with --tolerance)")
    p.add_argument("--no-tolerance", dest="tolerance", action="store_false",
                   help="do not run the tolerance check (the default; kept for older scripts)")
    p.add_argument("--fit-timeout", type=fit_timeout, default=FIT_TIMEOUT, metavar="SECONDS",
                   help="time budget of each fit and refit; a fit past it is a failed row with that reason, a "
                        f"refit a failed replicate (default {FIT_TIMEOUT:g})")
    p.set_defaults(func=run)


def run(args) -> int:
    from .early import check_datasets, check_laws, check_out

    parent = args.out.parent if str(args.out.parent) else Path(".")
    if not parent.is_dir():
        raise OutputError(f"{args.out}: cannot write: {parent} is not an existing folder")
    check_laws(args.laws, args.load)  # the quick refusals, before the numerics are imported
    check_datasets(args.data or ())
    check_out(args.out, args.force, args.data or ())
    from ..core.cluster import Waits, check_address, close, connect, quiet_logs

    if args.scheduler is not None:
        check_address(args.scheduler)  # a malformed address refused before any work or connection
    from ..io.dataset import available_names, load_dataset
    from .fit import parse_free

    if not 1 <= args.jobs <= MAX_JOBS:
        raise OutputError(f"--jobs must be between 1 and {MAX_JOBS}, got {args.jobs}")
    if not 0 <= args.bootstrap <= MAX_BOOTSTRAP:
        raise ParameterError(f"--bootstrap must be 0 (none) or a number of resamples up to {MAX_BOOTSTRAP}, "
                             f"got {args.bootstrap}")
    if args.seed < 0:
        raise ParameterError(f"--seed must be a non-negative integer, got {args.seed}")
    from ..inference.equivalence.discrimination import MIN_REPLICATES

    if args.replicates < MIN_REPLICATES:
        raise ParameterError(f"--replicates must be at least {MIN_REPLICATES}, got {args.replicates}")
    free = parse_free(args.free)
    from ..inference.equivalence.margin import parse_margin

    margin = parse_margin(args.margin, "--margin")
    if args.no_equivalence and (args.margin is not None or args.pairs):
        raise ParameterError(f"{'--margin' if args.margin is not None else '--pairs'} applies to the equivalence "
                             "tests, which --no-equivalence skips; drop one of the two")
    pairs = parse_pairs(args.pairs, args.laws or None) if args.pairs else None
    datasets = [load_dataset(d) for d in args.data or available_names()]  # read first: --out keeps clear of them
    if not args.no_equivalence:
        margin.check(datasets)
    args.margin = margin
    if args.scheduler is None:
        return _run(args, free, pairs, datasets, None)
    waits = Waits(connect=args.connect_timeout, workers=args.wait_workers, task=args.task_timeout,
                  say=None if args.quiet else _say)
    with quiet_logs(args.debug):  # distributed's own log is not the user's to read, unless --debug
        client = connect(args.scheduler, waits)
        try:
            return _run(args, free, pairs, datasets, client)
        finally:
            close(client, waits)


def _say(text: str) -> None:
    """A wait on the cluster, said as a progress line."""
    import sys

    from ..core.progress import _stamp

    print(f"{_stamp()} compare: {text}", file=sys.stderr, flush=True)


def parse_pairs(items, laws) -> tuple[tuple[str, str], ...]:
    """--pairs 'wear:area-rate' ... -> (('wear', 'area-rate'), ...): registered names, two different laws, both
    among the compared ``laws`` (None: the default laws of every dataset kind), each pair once."""
    from ..physics.registry import get_law
    from ..pipeline.settings import DEFAULT_LAWS_BY_KIND, check_pairs, select_laws

    # the laws compared together: the named ones, or the default laws of each dataset kind (a pair of laws from
    # two kinds' defaults is never fitted on one dataset)
    groups = [set(select_laws(laws))] + ([{get_law(n).name for n in v} for v in DEFAULT_LAWS_BY_KIND.values()]
                                         if laws is None else [])
    return check_pairs(items, groups, "--pairs", "--laws")


def _run(args, free, pairs, datasets, client) -> int:
    from ..core.files import output_lock
    from ..core.outfolder import check_target
    from ..core.workers import long_run_gc
    from ..pipeline.comparison import compare
    from ..report import write_report

    with output_lock(args.out), long_run_gc():  # a second run to the same --out fails now, not after the work
        check_target(args.out, args.force)
        with Progress("compare", quiet=args.quiet) as bar:
            result = compare(laws=args.laws or None, datasets=datasets, solvers=args.solver or None,
                             free=free, equivalence=not args.no_equivalence, jobs=args.jobs, progress=bar,
                             bootstrap=args.bootstrap, seed=args.seed, bootstrap_all=args.bootstrap_all,
                             tolerance=TOLERANCE_RTOLS if args.tolerance else (), fit_timeout=args.fit_timeout,
                             replicates=args.replicates, transfer=args.transfer, client=client,
                             margin=args.margin, family=args.family, accuracy=args.accuracy,
                             **({"pairs": pairs} if pairs else {}))
        if not any(f.ok for f in result.fits):  # nothing to compare: an error, and no report of it
            reasons = list(dict.fromkeys(f"{f.law} on {', '.join(f.datasets)}: {f.reason}" for f in result.fits
                                         if f.status == "failed"))
            raise FitError("compare: no fit succeeded: " + "; ".join(reasons[:3])
                           + (f" (and {len(reasons) - 3} more)" if len(reasons) > 3 else ""))
        with Progress("report", quiet=args.quiet) as bar:
            out = write_report(result, args.out, force=args.force, progress=bar, jobs=args.jobs, client=client)
    ok = sum(f.ok for f in result.fits)
    n_laws, n_data = len(result.laws), len(result.fitted_datasets)
    print(f"compared {n_laws} law{'s' * (n_laws != 1)} on {n_data} dataset{'s' * (n_data != 1)}: {ok} fits, "
          f"{sum(f.status == 'failed' for f in result.fits)} failed, {sum(f.status == 'skipped' for f in result.fits)} "
          f"skipped, {sum(e.ok for e in result.equivalence)} equivalence tests, in {result.wall_time:.1f} s")
    for line in laws_lines(result) + answer_lines(result):
        print(line)
    print(f"report: {out / 'report.html'} (also report.md, ranking.csv, results.json, figures/)")
    return 0


def laws_lines(c) -> list[str]:
    """Which laws were fitted on which kind of dataset, when that was chosen by kind (the default laws)."""
    from ..pipeline.settings import laws_groups

    groups = laws_groups(c.options.by_kind if c.options is not None else {},
                         {d.kind for d in c.datasets if d.kind != "contact-area"})
    return ["laws by dataset kind (the default): " + "; ".join(f"{', '.join(laws)} on {', '.join(k)}"
                                                               for laws, k in groups)] if groups else []


def answer_lines(c) -> list[str]:
    """The report's first screen in a few lines: per dataset group one line of the verdict layer's
    short answers (Comparison.answers; the full sentences are in the report and results.json);
    without answers, says so instead of inventing verdicts."""
    from ..inference.verdicts.answers import unfitted

    if not c.answers:
        return ["answers: none (the verdict layer filled no Comparison.answers); see the report's tables"]
    out = ["answers (full sentences in report.html and results.json):"]
    for a in c.answers:
        if a.best is None:  # groups without a fitted law: one line per reason below, as on the first screen
            continue
        eq = a.cell("equivalence")
        parts = [a.cell("best"), a.cell("goodness"),
                 f"lambda A u vs mu N + mu eta' dA/dt: {eq}" if eq and eq != "not tested" else "", a.cell("threshold"),
                 a.cell("series"), f"accuracy {a.short['accuracy']}" if a.short.get("accuracy") else "",
                 a.cell("transfer"), a.cell("closer")]
        out.append(f"  {a.group}: " + "; ".join(p for p in parts if p))
    out += [f"  {', '.join(groups)}: {reason}" + "".join(f"; registered laws that apply: {h}" for h in hints)
            for reason, groups, hints in unfitted(c.answers)]
    return out
