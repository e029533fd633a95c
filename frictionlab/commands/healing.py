"""``frictionlab healing DATASET``: the healing table of a slide-hold-slide record beside each state law's."""
from __future__ import annotations


def add_parser(sub):
    from ..cli import ListAction, subcommand

    p = subcommand(sub, "healing", help="the healing table of a slide-hold-slide record, with each law's prediction",
                   description="Read a spring-slider dataset whose load point holds (velocity 0 between two sliding "
                               "pieces: a raw record imported with 'datasets import velstep --joint', or a "
                               "synthetic one) and print the healing table a laboratory reports: per hold its "
                               "length, the steady friction before it and the peak minus steady friction on "
                               "re-sliding; the healing per decade of hold time with its 95% interval; beside it "
                               "each state law's table from the law fitted to the whole record (and, for a "
                               "synthetic record, from its generating law and parameters).",
                   examples="""  frictionlab healing examples/slide-hold-slide/kt-slide-hold-slide.toml
  frictionlab healing data/shs.toml --laws rate-state-aging
  frictionlab datasets rebuild --slide-hold-slide    # the synthetic record again, from its generator""")
    p.add_argument("dataset", metavar="DATASET", help="built-in dataset name or TOML path")
    p.add_argument("--laws", "--law", action=ListAction, default=[], metavar="NAME",
                   help="state laws to fit and predict with (default: every registered state law the velocity-step "
                        "fit serves: aging, slip, PRZ, Nagata; another, e.g. rate-state-aging2, by the general "
                        "path)")
    p.add_argument("--fit-timeout", type=float, metavar="SECONDS", help="time budget of each fit")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..core.errors import ParameterError
    from ..inference.fitting.fit import fit
    from ..inference.velstep.healing import lines, of_dataset
    from ..inference.velstep.record_steps import state_laws
    from ..io.dataset import load_dataset

    laws = args.laws or state_laws(fitted_only=True)
    unknown = [n for n in laws if n not in state_laws()]
    if unknown:
        raise ParameterError(f"--laws: {', '.join(unknown)} is not a state law of the quasi-static slider; "
                             f"expected one of {', '.join(state_laws())}")
    d = load_dataset(args.dataset)
    tables = [of_dataset(d)]
    notes = []
    truth = d.provenance.truth
    if d.provenance.kind == "synthetic" and truth.get("law") in state_laws():
        tables.append(of_dataset(d, _truth_mu(d, truth), f"truth: {truth['law'].replace('rate-state-', '')}"))
    for law in laws:
        f = fit(law, d, timeout=args.fit_timeout)
        if not f.ok:
            notes.append(f"{law}: the fit {f.status} ({f.reason}): no prediction")
            continue
        tables.append(of_dataset(d, f.per_dataset[0].model, law.replace("rate-state-", "") + ", best parameters"))
        p = {k: v.value for k, v in f.params.items() if v.kind == "law"}
        extra = "".join(f", {k} = {p[k]:.4g}" for k in ("c",) if k in p)  # Nagata's c
        notes.append(f"{law} at its best parameters on the whole record: a = {p['a']:.4g}, b = {p['b']:.4g}, Dc = "
                     f"{p['Dc'] * 1e6:.4g} um{extra}; {f.goodness.short if f.goodness is not None else ''}".rstrip("; "))
    print(f"{d.name} ({d.provenance.kind}): {len(tables[0].holds)} holds; healing = peak friction on re-sliding "
          "(largest 5-sample running mean) minus the steady friction before the hold (the line through the second "
          "half of the sliding before it, at the hold's start)")
    for line in lines(tables):
        print(line)
    for n in notes:
        print(f"  {n}")
    return 0


def _truth_mu(d, truth: dict):
    """The generating law's friction without noise at the dataset's times."""
    from ..core.units import to_si
    from ..solve.solvers import simulate

    params = {k: to_si(v, "m" if k == "Dc" else "", f"provenance.truth.{k}") for k, v in truth.items()
              if k in ("mu0", "a", "b", "Dc")}
    return simulate(truth["law"], d.scene, params, t=d.t, rtol=1e-10).load
