"""``frictionlab record RAWFILE...``: a raw experiment fitted as the field asks of it: each step from a window
that starts at a steady state, one parameter set across the steps tested per state law, the whole record as
one history."""
from __future__ import annotations

import math


def add_parser(sub):
    from ..cli import ListAction, subcommand

    p = subcommand(sub, "record", help="fit a raw multi-step record: per step, one set across steps, as one history",
                   description="Read a raw velocity-step record (several files of one experiment are joined by "
                               "time), cut it into one window per step, each starting at a steady state the data "
                               "show (the steadystate routine's test), fit each state law to each step, test one "
                               "set of a, b, Dc across the steps against per-step sets (likelihood ratio, "
                               "delta-AIC, delta-BIC), fit the whole record as one load-point history, and print "
                               "the first screen: does one parameter set describe the up and the down steps, for "
                               "which law. Holds are simulated through (a hold's stop and re-slide share a window).",
                   examples="""  frictionlab record velstep1_TR2_exp013_sepiolite.txt velstep2_TR2_exp013_sepiolite.txt \\
      velstep3_TR2_exp013_sepiolite.txt --name sepiolite-exp013
  frictionlab record experiment.txt --laws rate-state-slip --no-joint""")
    p.add_argument("raw", nargs="+", metavar="RAWFILE", help="the raw record (several files: slices of one recording)")
    p.add_argument("--name", default="record", help="the record's name (its step windows: NAME-step1, ...)")
    p.add_argument("--laws", "--law", action=ListAction, default=[], metavar="NAME",
                   help="state laws to fit (default: every registered state law the velocity-step fit serves: aging, "
                        "slip, PRZ, Nagata; another, e.g. rate-state-aging2, by the general path)")
    p.add_argument("--no-joint", action="store_true", help="skip the whole-record fit (the slowest part)")
    p.add_argument("--fit-timeout", type=float, metavar="SECONDS", help="time budget of each fit")
    p.set_defaults(func=run)


def run(args) -> int:
    from pathlib import Path

    from ..core.errors import ParameterError
    from ..core.names import check_name
    from ..inference.velstep.record_steps import answer, fit_steps, state_laws
    from ..io.velstep import summary
    from ..io.velstep_join import read_joined
    from ..report.record_screen import screen

    check_name(args.name, "record --name", ParameterError)
    laws = args.laws or state_laws(fitted_only=True)
    unknown = [n for n in laws if n not in state_laws()]
    if unknown:
        raise ParameterError(f"--laws: {', '.join(unknown)} is not a state law of the quasi-static slider; "
                             f"expected one of {', '.join(state_laws())}")
    if args.fit_timeout is not None and not (args.fit_timeout > 0 and math.isfinite(args.fit_timeout)):
        raise ParameterError(f"--fit-timeout: {args.fit_timeout!r}; expected a positive number of seconds")
    raw = read_joined([Path(p) for p in args.raw])
    steps, datasets, imp = step_datasets(raw, args.name)
    joint = None if args.no_joint else whole_dataset(raw, args.name)
    results = [fit_steps(law, datasets, joint=joint[0] if joint else None, timeout=args.fit_timeout) for law in laws]
    title = summary(imp)[0]
    note = f", from {joint[1]}" if joint else ""
    for line in screen(title, steps, results, answer(results, [s["direction"] for s in steps]), note):
        print(line)
    return 0


def _dataset(imp, w):
    from ..io.dataset import from_meta
    from ..io.velstep import dataset_toml, parts

    toml = dataset_toml(imp, w, command="frictionlab record")
    meta, cols = parts(imp, w, toml)
    return from_meta(meta, imp.raw.path, raw=cols)


def step_datasets(raw, name: str):
    """(step descriptions, step-window Datasets in memory, the import) of a raw record."""
    from ..core.errors import DatasetError
    from ..io.velstep import analyse

    imp = analyse(raw, name)
    if not imp.windows:
        raise DatasetError(f"{raw.path}: no step has a window that starts at a steady state: "
                           + "; ".join(imp.notes))
    steps, datasets = [], []
    for w in imp.windows:
        v = w.velocities
        direction = "hold" if 0.0 in v[1:] else ("up" if v[1] > v[0] else "down")
        steps.append(dict(name=w.name, label=" -> ".join(f"{x * 1e6:.3g}" for x in v), direction=direction,
                          window=f"{w.b - w.a} samples, t = {raw.t[w.a]:.10g} to {raw.t[w.b - 1]:.10g} s",
                          note=w.start_note))
        datasets.append(_dataset(imp, w))
    return steps, datasets, imp


def whole_dataset(raw, name: str):
    """(the whole-record Dataset, where it starts) of a raw record."""
    from ..io.velstep import analyse

    imp = analyse(raw, name, joint=True)
    w = imp.windows[0]
    return _dataset(imp, w), f"t = {raw.t[w.a]:.10g} s, its first steady state"
