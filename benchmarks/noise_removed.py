"""Do verdicts depend on a declared sigma? The known-truth folder compared twice: as generated (true sigma
declared, kind = known) and with every [noise] table removed (sigma estimated from the data).

    python benchmarks/noise_removed.py [--folder examples/known-truth] [--jobs 1]

Prints, per dataset group, whether the best law, its fit verdict, the equivalence verdicts and the transfer
verdict agree, and how many equivalence tests and per-fit verdicts agree. Exit 1 if a group's answer differs.
"""
from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path


def _run(files, out: Path, jobs: int) -> dict:
    subprocess.run([sys.executable, "-m", "frictionlab.cli", "compare", "--data", *map(str, files), "--out", str(out),
                    "--force", "-q", "--bootstrap", "0", "--no-tolerance", "--jobs", str(jobs)], check=True,
                   stdout=subprocess.DEVNULL)
    return json.loads((out / "results.json").read_text())


def _answers(r: dict) -> dict:
    return {a["group"]: (a["best"], a["fits"], a["equivalence"], a.get("equivalence_series"),
                         (a.get("short") or {}).get("transfer", "").split(" (")[0]) for a in r["answers"]}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--folder", type=Path, default=Path("examples/known-truth"))
    p.add_argument("--jobs", type=int, default=1)
    a = p.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        stripped = tmp / "data"
        stripped.mkdir()
        for f in a.folder.glob("*"):
            shutil.copy(f, stripped / f.name)
        for toml in stripped.glob("*.toml"):
            text = re.sub(r"\n\[noise\]\n(?:[^\[\n][^\n]*\n)*", "\n", toml.read_text())
            toml.write_text(text)
        known = _run(sorted(a.folder.glob("*.toml")), tmp / "known", a.jobs)
        est = _run(sorted(stripped.glob("*.toml")), tmp / "estimated", a.jobs)
    ka, kb = _answers(known), _answers(est)
    same = True
    for g in ka:
        ok = ka[g] == kb.get(g)
        same &= ok
        print(f"{g}: {'same' if ok else 'DIFFERENT'}: {ka[g]}" + ("" if ok else f" / estimated: {kb.get(g)}"))
    ea = {(e["dataset"], e["law_a"], e["solver_a"], e["law_b"]): e.get("verdict") for e in known["equivalence"]}
    eb = {(e["dataset"], e["law_a"], e["solver_a"], e["law_b"]): e.get("verdict") for e in est["equivalence"]}
    print(f"equivalence verdicts agreeing: {sum(ea[k] == eb.get(k) for k in ea)} of {len(ea)}")
    fa = {(f["dataset"], f["law"], f["solver"]): (f.get("goodness") or {}).get("fits") for f in known["fits"]}
    fb = {(f["dataset"], f["law"], f["solver"]): (f.get("goodness") or {}).get("fits") for f in est["fits"]}
    diff = [k for k in fa if fa[k] != fb.get(k)]
    print(f"per-fit verdicts agreeing: {len(fa) - len(diff)} of {len(fa)}" + (f"; differing: {diff}" if diff else ""))
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
