"""``frictionlab simulate LAW DATASET``: one law on one dataset's scene, as a table, CSV or figure.

Law parameters come from the law's defaults, then the dataset's [fixed] values, then --param
(values with units, e.g. lam='1.81e6 Pa s/m'; a dimensional value must say its unit). The CSV
holds SI columns t,u,v,omega,theta,force (omega and theta only where the scene spins; A, N and a law's
states as state_NAME where the plan built them); for an
impact-outcome dataset it holds one row per impact. Outputs are written only after the whole
simulation and figure succeeded, so a failed run writes nothing.
"""
from __future__ import annotations

import math
import os
from pathlib import Path

from ..core.errors import OutputError, ParameterError, SolverError

RPM = 60.0 / (2.0 * math.pi)
PLOT_POINTS = 501


MAX_POINTS = 1_000_000  # simulated times written by --points
MIN_RTOL = 1e-14  # tighter than this, the ODE solvers give up on round-off


def add_parser(sub):
    from ..cli import ListAction, subcommand

    p = subcommand(sub, "simulate", help="simulate a law on a dataset's scene",
                   description="Simulate LAW on the scene of DATASET (built-in name or TOML path): a summary on "
                               "screen, the series as CSV (--out) and a figure with the data (--plot).",
                   examples="""  frictionlab simulate wear impact-golf-v28 --param lam='1.81e6 Pa s/m' --solver exact
  frictionlab simulate wear impact-golf-v28 --param lam='1.81e6 Pa s/m' --solver series --plot s.png --y omega
  frictionlab simulate couette incline-oil-a100 --param eta='0.1 Pa s',h='80 um' --out v.csv""")
    p.add_argument("law", metavar="LAW", help="registered law name (see 'frictionlab laws'), as in 'fit'")
    p.add_argument("dataset", metavar="DATASET", nargs="?", help="built-in dataset name or path to its TOML")
    p.add_argument("--law", dest="old_law", metavar="NAME",
                   help="the earlier form 'simulate DATASET --law NAME', still accepted (with a note)")
    p.add_argument("--param", action=ListAction, default=[], metavar="NAME=VALUE",
                   help="law parameter with its unit, e.g. lam='1.81e6 Pa s/m' or mu=0.2")
    p.add_argument("--solver", default="ode", help="exact, series, ode or ode:METHOD (default: ode, i.e. LSODA)")
    p.add_argument("--rtol", type=float, default=1e-10, help="relative tolerance of the ode solver (default 1e-10, as fl.simulate; "
                        "a fit's solves default to 1e-6, 'fit --rtol')")
    p.add_argument("--points", type=int, metavar="N",
                   help="write N evenly spaced times over the scene's duration instead of the dataset's times")
    p.add_argument("--out", type=Path, metavar="FILE.csv", help="write the simulated series (SI) as CSV")
    p.add_argument("--plot", type=Path, metavar="FILE.png", help="write a figure of the observable with the data")
    p.add_argument("--y", metavar="COLUMN", help="plot this simulated column instead of the dataset's observable "
                   "(e.g. omega for the spin of a dataset that fits theta; the CSV's column names)")
    p.set_defaults(func=run)


def _law_and_dataset(args) -> str:
    """'simulate LAW DATASET' (as 'fit LAW DATASET'), or the earlier 'simulate DATASET --law LAW' with a note;
    sets args.dataset and returns the law's name."""
    import sys

    if args.old_law is not None:
        if args.dataset is not None:
            raise ParameterError(f"simulate: the law is given twice ({args.law!r} and --law {args.old_law!r}); "
                                 "write 'frictionlab simulate LAW DATASET'")
        if not args.quiet:
            print(f"note: 'simulate {args.law} --law {args.old_law}' is the earlier form; write 'frictionlab simulate "
                  f"{args.old_law} {args.law}' (the law first, as in 'fit')", file=sys.stderr)
        args.dataset = args.law
        return args.old_law
    if args.dataset is None:
        raise ParameterError(f"simulate: expected a law and a dataset ('frictionlab simulate LAW DATASET'), got only "
                             f"{args.law!r}")
    return args.law


def parse_params(law, items) -> dict[str, float]:
    """['lam=1.81e6 Pa s/m', 'mu=0.2'] -> SI floats, each converted against the law's parameter unit."""
    from ..core.units import to_si
    from .fit import _split

    out = {}
    for item, after in zip(items, list(items[1:]) + [""]):
        name, value = _split(item, "--param")
        if value[-1:].isdigit() and after[:1].isdigit() and "=" not in after:  # '--param h=80,5 um'
            raise ParameterError(f"--param {name}: {value + ',' + after!r}: a comma separates list items here; "
                                 f"write a decimal point ({value}.{after})")
        spec = law.spec(name)
        out[name] = to_si(value, spec.unit, f"--param {name}")
    return out


def run(args) -> int:
    from ..core.files import check_writable, write_files
    from ..io.dataset import load_dataset
    from ..physics.registry import get_law

    law = get_law(_law_and_dataset(args))
    params = parse_params(law, args.param)
    if not MIN_RTOL <= args.rtol < 1:
        raise SolverError(f"--rtol: rtol must be a number in (0, 1), at least {MIN_RTOL:g} (a float resolves "
                          f"about 2e-16), got {args.rtol:g}")
    if args.points is not None and not 2 <= args.points <= MAX_POINTS:
        raise ParameterError(f"--points must be between 2 and {MAX_POINTS}, got {args.points}")
    ds = load_dataset(args.dataset)
    for path in (args.out, args.plot):
        if path is not None:
            check_writable(path)
    if args.out is not None and args.plot is not None and os.path.realpath(args.out) == os.path.realpath(args.plot):
        raise OutputError(f"{args.out}: --out and --plot name the same file; give two paths")
    from ..core.progress import Progress

    with Progress("simulate", quiet=args.quiet, delay=2.0) as bar:  # a quick run stays silent
        if ds.kind == "impact-outcome":
            bar(0, 1, f"solving {len(ds)} impacts of {ds.name}")
            text, summary, figure = _outcomes(law, ds, params, args)
        else:
            text, summary, figure = _series(law, ds, params, args, bar)
        bar(1, 1, "done")
    written = [p for p in (args.plot, args.out) if p is not None]
    if written:  # both outputs or neither
        write_files({p: figure if p is args.plot else text for p in written}, force=True)
    print(summary)
    for p in written:
        print(f"wrote {p}")
    return 0


def _params_text(law, p) -> str:
    return ", ".join(f"{s.name} = {p[s.name]:.6g}" + (f" {s.unit}" if s.unit else "") for s in law.params)


# --- time series ---------------------------------------------------------------------------------
def _solving(bar, what: str, t_end: float):
    """A context in which every ODE step tells ``bar`` the simulated time reached (per mille of t_end)."""
    import time

    from ..core.display import fmt_time
    from ..solve.solvers.ode import watching

    state = {"t": 0.0, "at": -1e9}

    def tick(t):
        now = time.monotonic()
        state["t"] = min(max(state["t"], float(t)), t_end)  # a step may probe past the end: report at most t_end
        if now - state["at"] >= 0.25:
            state["at"] = now
            bar(int(1000 * min(state["t"] / t_end, 1.0)), 1000,
                f"{what}: t = {fmt_time(state['t'], t_end)} of {fmt_time(t_end)} simulated")
    bar(0, 1000, what)
    return watching(tick)


def _series(law, ds, params, args, bar=lambda *a: None):
    import numpy as np

    from ..solve.solvers import simulate

    scene = ds.scene
    if scene is None:
        simulate(law, ds, params, solver=args.solver, rtol=args.rtol)  # raises the loader's one-line error
    t_end = max(float(scene.duration), float(ds.t[-1]))
    t = np.linspace(0.0, t_end, args.points) if args.points else ds.t
    with _solving(bar, f"solving {law.name} on {ds.name}", t_end):
        tr = simulate(law, ds, params, solver=args.solver, rtol=args.rtol, t=t)
    p = law.resolve({**{k: v for k, v in ds.fixed.items() if k in law.param_names}, **params})
    summary = _summary(law, ds, tr, p)
    figure = None
    if args.plot is not None:
        fine = tr
        if len(t) < PLOT_POINTS:  # a smooth curve; any solver warning was already given for the run above
            import warnings

            with warnings.catch_warnings(), _solving(bar, f"solving at {PLOT_POINTS} times for the plot", t_end):
                warnings.simplefilter("ignore")
                fine = simulate(law, ds, params, solver=args.solver, rtol=args.rtol,
                                t=np.linspace(0.0, t_end, PLOT_POINTS))
        figure = _series_figure(ds, fine, f"{law.name} [{tr.solver}]: {_params_text(law, p)}", args.y)
    return _csv(tr, "spin" in scene.effects), summary, figure


def _csv(tr, spins: bool) -> str:
    """The trajectory's CSV (SI); without a spin state, no rotation columns (all zeros, and 'theta' would read
    as a rate-and-state theta, which is the column state_theta)."""
    if spins:
        return tr.csv_text()
    cols = {k: v for k, v in tr.columns().items() if k not in ("omega", "theta")}
    lines = [",".join(cols)] + [",".join(f"{x:.17g}" for x in row) for row in zip(*cols.values())]
    return "\n".join(lines) + "\n"


def _summary(law, ds, tr, p) -> str:
    import numpy as np

    from ..core.display import fmt_time

    T = float(tr.t[-1])
    lines = [f"{law.name} on {ds.name} ({tr.solver}): {_params_text(law, p)}"]
    if np.any(tr.omega != 0) or "omega" in (ds.observable, *ds.columns):
        i = int(np.argmax(np.abs(tr.omega)))
        lines.append(f"  peak spin      {tr.omega[i] * RPM:.6g} rpm at t = {fmt_time(tr.t[i], T)}")
    else:
        i = int(np.argmax(np.abs(tr.v)))
        lines.append(f"  peak velocity  {tr.v[i]:.6g} m/s at t = {fmt_time(tr.t[i], T)}")
    spin = (f"spin {tr.omega[-1] * RPM:.6g} rpm, theta {math.degrees(tr.theta[-1]):.6g} deg, "
            if "spin" in ds.scene.effects else "")
    lines.append(f"  at t = {fmt_time(T, T)}: slip u = {tr.u[-1]:.6g} m/s, v = {tr.v[-1]:.6g} m/s, {spin}"
                 f"force {tr.force[-1]:.6g} N" + "".join(f", {k} {v[-1]:.6g} (SI)" for k, v in tr.columns().items()
                                                       if k.startswith("state_")))
    if tr.solver == "series":
        from ..solve.solvers.series import slip_zero

        t = np.linspace(0.0, T, 20001)
        tz = slip_zero(t, simulate_series_slip(law, ds, p, t))
        lines.append("  slip           " + (
            "the truncated series' slip stays positive" if tz is None else
            f"the truncated series' slip crosses zero at t = {fmt_time(tz, T)} and turns negative: the series is "
            "not a solution of the equation of motion, so nothing stops it there and its friction reverses"))
    else:
        lines.append("  stick          " + ("slip never reached zero" if tr.stick_time is None else
                                            f"slip reached zero at t = {fmt_time(tr.stick_time, T)}"))
    b = tr.info.get("b")
    if b is not None:
        lines.append(f"  series b       {b:.4g}")
    return "\n".join(lines)


def simulate_series_slip(law, ds, p, t) -> np.ndarray:
    """The series solution's slip at times t (for where it crosses zero)."""
    import warnings

    from ..solve.solvers import simulate

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the accuracy warning was given for the run itself
        return simulate(law, ds, p, solver="series", t=t).u


def _series_figure(ds, tr, title, y: str | None = None) -> bytes:
    """The simulated column ``y`` (default the dataset's observable) against time, with the dataset's
    column of that name where it has one."""
    from ..core.display import NAMES, time_unit, unit
    from ..report.figures import _plt, _png

    plt = _plt()
    obs = y or ds.observable
    cols = tr.columns()
    if obs not in cols and obs != "mu":
        raise ParameterError(f"--y {obs}: the simulation has no such column; choose from {', '.join(cols)}")
    uname, uf = unit(obs)
    tname, tf = time_unit(float(tr.t[-1]))
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot(tr.t * tf, tr[obs] * uf, color="#1b9e77", lw=1.8, label="simulated")
    if obs in ds.columns:
        sigma = ds.noise.get(obs, 0.0)
        ax.errorbar(ds.t * tf, ds.columns[obs] * uf, yerr=sigma * uf, fmt="o", ms=3.5, color="k", ecolor="0.6",
                    lw=0.8, label=f"{ds.name} ({ds.provenance.kind})")
    ax.set_xlabel(f"time [{tname}]")
    ax.set_ylabel(f"{NAMES.get(obs, obs)} [{uname}]")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _png(fig)


# --- impact outcomes --------------------------------------------------------------------------------
OUTCOME_COLUMNS = ("speed", "incidence", "rebound_spin", "tangential_cor", "rebound_angle", "contact_time",
                   "restitution", "rolled")


def _outcomes(law, ds, params, args):
    """One row per impact: the summary shows the dataset's own observable (in its file's unit) beside the
    rebound spin and the contact point's e_T; the CSV holds every outcome the scene gives (SI)."""
    from ..core.table import render
    from ..report.figures import column_unit
    from ..solve.outcome import OUTCOMES, predict_outcomes

    out = predict_outcomes(law, ds, params, args.solver, rtol=args.rtol)
    p = law.resolve({**{k: v for k, v in ds.fixed.items() if k in law.param_names}, **params})
    obs = ds.observable
    ou, of = column_unit(ds, obs)
    shown = f"{obs} (the dataset's observable)" + (f" [{ou}]" if ou else "")
    rows = [{"speed [m/s]": out["speed"][i], "incidence [deg]": math.degrees(out["incidence"][i]),
             shown: out[obs][i] * of, "rebound spin [rpm]": out["rebound_spin"][i] * RPM,
             "e_T at the contact point": out["tangential_cor"][i], "rolled": bool(out["rolled"][i])}
            for i in range(len(out["speed"]))]
    if obs == "rebound_spin":
        rows = [{k: v for k, v in r.items() if k != "rebound spin [rpm]"} for r in rows]
    summary = f"{law.name} on {ds.name} ({args.solver}): {_params_text(law, p)}\n" + render(rows)
    cols = list(OUTCOME_COLUMNS) + [c for c in OUTCOMES if c in out and c not in OUTCOME_COLUMNS]
    lines = [",".join(cols)]
    for i in range(len(out["speed"])):
        lines.append(",".join(f"{float(out[c][i]):.17g}" if c != "rolled" else str(int(out[c][i])) for c in cols))
    figure = _outcome_figure(law, ds, p, args) if args.plot is not None else None
    return "\n".join(lines) + "\n", summary, figure


def _outcome_figure(law, ds, p, args) -> bytes:
    import numpy as np

    from ..report.figures import column_unit

    from ..report.figures import _plt, _png
    from ..solve.outcome import predict_outcomes

    plt = _plt()
    obs = ds.observable
    uname, uf = column_unit(ds, obs)
    fig, ax = plt.subplots(figsize=(7, 4.2))
    speeds = np.unique(ds.columns["speed"])
    inc = ds.columns["incidence"]
    grid = np.linspace(max(inc.min() - 0.05, 1e-3), min(inc.max() + 0.05, math.pi / 2 - 1e-3), 61)
    for k, v in enumerate(speeds):
        color = f"C{k}"
        model = predict_outcomes(law, ds.scene, p, args.solver, speed=np.full(grid.shape, v), incidence=grid,
                                 rtol=args.rtol)
        ax.plot(np.degrees(grid), model[obs] * uf, color=color, lw=1.6, label=f"{v:g} m/s, {law.name}")
        sel = ds.columns["speed"] == v
        ax.errorbar(np.degrees(inc[sel]), ds.y[sel] * uf, yerr=ds.sigma * uf, fmt="o", ms=3.5, color=color,
                    ecolor="0.6", lw=0.8)
    ref = "surface normal" if ds.scene.angle_reference == "normal" else "surface"
    ax.set_xlabel(f"incidence from the {ref} [deg]")
    ax.set_ylabel(f"{obs.replace('_', ' ')} [{uname}]")
    ax.set_title(f"{ds.name} ({ds.provenance.kind}): {law.name}, {_params_text(law, p)}", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _png(fig)
