"""``frictionlab laws``: list the registered laws with parameters, units, bounds, needs and internal states."""
from __future__ import annotations


def add_parser(sub):
    from ..cli import subcommand

    p = subcommand(sub, "laws", help="list the registered friction laws",
                   description="List the registered friction laws: formula, what each needs (N, A, dA/dt, u), "
                               "citation, where it is defined, and its parameters with units, defaults and bounds.",
                   examples="""  frictionlab laws --brief
  frictionlab laws --load my_laws.py        # laws registered in your file appear in the list""")
    p.add_argument("--brief", action="store_true", help="one line per law")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..core.table import render
    from ..physics.law import QUANTITIES
    from ..physics.registry import available_laws, law_source

    laws = available_laws()
    if args.brief:
        print(render([{"law": n, "formula": law.formula, "requires": ", ".join(sorted(law.requires)),
                       "parameters": ", ".join(law.param_names), "states": ", ".join(law.state_names) or "-"}
                      for n, law in laws.items()]))
        return 0
    for name, law in laws.items():
        print(f"{name}: {law.formula}")
        print(f"  requires: {', '.join(f'{q} ({QUANTITIES[q]})' for q in sorted(law.requires))}")
        print(f"  citation: {law.citation}")
        print(f"  source:   {law_source(name)}")
        rows = [{"parameter": s.name, "unit": s.unit or "-", "default": s.default, "lower": s.lower, "upper": s.upper,
                 "scale": s.scale, "description": s.description} for s in law.params]
        print("    " + render(rows).replace("\n", "\n    "))
        if law.states:
            states = [{"state": s.name, "unit": s.unit or "-", "initial": s.initial, "scale": s.scale,
                       "description": s.description} for s in law.states]
            print("  internal states (integrated with the motion; ODE solver only):")
            print("    " + render(states).replace("\n", "\n    "))
        for a, b in law.ratio_only:
            print(f"  note: {a} and {b} enter only as {a}/{b}; fix one to identify the other")
        print()
    return 0
