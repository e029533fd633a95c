"""Do two ``frictionlab compare`` runs agree? Fitted values of every fit, within their error bars.

    python benchmarks/compare_results.py BEFORE/results.json AFTER/results.json [--tol 1.0]

For each fit present in both (dataset, law, solver) and each fitted or derived parameter (such as
eta/h), prints the shift |after - before| in units of the larger of the two standard errors, and
each fit's status and chi-square. A parameter with an error bar on neither side is one the data do
not determine (eta and h apart, a parameter without effect): it is listed as such, not compared.
Exit 1 if a shift exceeds --tol standard errors, a fit's status changed, or a fit is missing on one
side (a failed or skipped fit before that is not listed after is only named: it had no values).
"""
from __future__ import annotations

import argparse
import json
import math
import sys


def fits_by_key(path: str) -> dict:
    with open(path) as fh:
        data = json.load(fh)
    return {(f["dataset"], f["law"], f["solver"]): f for f in data["fits"]}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--tol", type=float, default=1.0, help="largest shift allowed, in standard errors (default 1)")
    args = ap.parse_args()
    old, new = fits_by_key(args.before), fits_by_key(args.after)
    bad, gone = [], []
    for key in sorted(set(old) - set(new)):
        if old[key]["status"] == "ok":
            bad.append(f"missing after: {key}")
        else:  # nothing was fitted before either (a dataset now left out before fitting, with its reason)
            gone.append(f"{key} ({old[key]['status']} before)")
    added = sorted(set(new) - set(old))
    rows = []
    for key in sorted(set(old) & set(new)):
        a, b = old[key], new[key]
        if a["status"] != b["status"]:
            bad.append(f"{key}: status {a['status']} -> {b['status']} ({b.get('reason', '')})")
            continue
        if a["status"] != "ok":
            continue
        for name, pa in a["parameters"].items():
            pb = b["parameters"].get(name)
            if pb is None or not (pa.get("vary", True) or pa.get("kind") == "derived"):
                continue
            errs = [e for e in (pa.get("stderr"), pb.get("stderr")) if e is not None and math.isfinite(e) and e > 0]
            if not errs:
                rows.append((0.0, key, name, pa["value"], pb["value"], "undetermined"))
                continue
            z = abs(pb["value"] - pa["value"]) / max(errs)
            rows.append((z, key, name, pa["value"], pb["value"], "se"))
            if z > args.tol:
                bad.append(f"{key} {name}: {pa['value']:.6g} -> {pb['value']:.6g} ({z:.3g} se)")
        rows.append((0.0, key, "chi2", a["statistics"].get("chisqr"), b["statistics"].get("chisqr"), "info"))
    print(f"{'shift':>9}  {'dataset':24s} {'law':10s} {'solver':8s} {'param':10s} {'before':>13s} {'after':>13s}")
    for z, key, name, va, vb, unit in sorted(rows, key=lambda r: (-r[0], r[1], r[2])):
        shown = {"se": f"{z:.3g} se", "undetermined": "undeterm."}.get(unit, "")
        print(f"{shown:>9}  {key[0]:24s} {key[1]:10s} {key[2]:8s} {name:10s} {va:13.6g} {vb:13.6g}")
    n_par = sum(r[5] == "se" for r in rows)
    print(f"\n{len(set(old) & set(new))} fits compared, {n_par} determined parameters; largest shift "
          f"{max((r[0] for r in rows if r[5] == 'se'), default=0):.3g} standard errors")
    for key in added:
        print("new fit, not compared:", key)
    for line in gone:
        print("not fitted before, not listed after:", line)
    for line in bad:
        print("DIFFERS:", line)
    print("agree within" if not bad else "do NOT agree within", f"{args.tol:g} standard errors")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
