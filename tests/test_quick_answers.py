"""The quick answers of the command line (--help, --version, an unknown law or dataset name, an output folder that
exists) are given without importing the numerics: no scipy, matplotlib, numba or lmfit in the process after them.
Their time is measured by benchmarks/bench_startup.py, not here."""
import json
import subprocess
import sys

import pytest

HEAVY = ("scipy", "matplotlib", "numba", "lmfit", "pint")
CODE = """
import json, sys
from frictionlab.cli import main
try:
    rc = main(sys.argv[1:])
except SystemExit as exc:
    rc = exc.code
print(json.dumps([rc, [m for m in {heavy!r} if m in sys.modules]]), file=sys.stderr)
"""


def _run(args, cwd):
    out = subprocess.run([sys.executable, "-c", CODE.format(heavy=HEAVY), *args], capture_output=True, text=True,
                         cwd=cwd, timeout=120, check=False)
    *said, last = out.stderr.strip().splitlines()
    rc, heavy = json.loads(last)
    return rc, heavy, out.stdout + "\n".join(said)


@pytest.mark.parametrize("args, rc, said", [
    (["--help"], 0, "Compare friction laws"),
    (["--version"], 0, "frictionlab "),
    (["fit", "no-such-law", "impact-golf-v28"], 2, "unknown law 'no-such-law'; registered laws: "),
    (["compare", "--laws", "wear,no-such-law", "--out", "R"], 2, "unknown law 'no-such-law'"),
    (["fit", "wear", "no-such-data"], 2, "unknown dataset 'no-such-data'; built-in: "),
    (["compare", "--data", "no-such-data", "--out", "R"], 2, "unknown dataset 'no-such-data'"),
    (["compare", "--out", "exists"], 2, "exists: output folder exists; choose another --out or pass --force"),
])
def test_a_quick_answer_imports_none_of_the_numerics(args, rc, said, tmp_path):
    (tmp_path / "exists").mkdir()
    got_rc, heavy, text = _run(args, tmp_path)
    assert (got_rc, heavy) == (rc, [])
    assert said in text


def test_a_known_law_goes_past_the_quick_check(tmp_path):
    """The same checks let a right name through: the run goes on to import what it needs (here, to refuse the
    existing output folder after reading the law's names)."""
    (tmp_path / "exists").mkdir()
    rc, _, text = _run(["compare", "--laws", "wear", "--data", "impact-golf-v28", "--out", "exists"], tmp_path)
    assert rc == 2 and "output folder exists" in text and "unknown" not in text
