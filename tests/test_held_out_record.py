"""A held-out measured velocity step: the second basalt step of the BRAVA experiment b819 in the steadystate
repository (Giacomel et al. 2024, MIT; ``velstep7_BRAVA_expb819_basalt.txt``, pgiacomel/steadystate commit
e7876f4), read where it was placed (``../shared/data/steadystate`` or FRICTIONLAB_RAW_DATA), never from the
repository. None of the project's choices were made on it: it imports as one 100 -> 300 um/s step, and the
default laws of a spring-slider are compared on it; a law must fit it, as one fits basalt-velstep4."""
from __future__ import annotations

import hashlib

import pytest

import frictionlab as fl
from frictionlab.cli import main
from frictionlab.io import external

FILE = "velstep7_BRAVA_expb819_basalt.txt"
SHA256 = "6e08dda5a038e23d701f9bd0d18f03e3efb998176571789126a429d057098a8b"


def _held_out():
    for folder in external.raw_dirs():
        path = folder / "steadystate" / FILE
        if path.is_file() and hashlib.sha256(path.read_bytes()).hexdigest() == SHA256:
            return path
    return None


PATH = _held_out()
pytestmark = pytest.mark.skipif(PATH is None, reason=f"the held-out basalt step {FILE} (pgiacomel/steadystate, "
                                                     "commit e7876f4) is not placed in ../shared/data/steadystate "
                                                     "(or FRICTIONLAB_RAW_DATA); it is not held in the repository")


def test_the_held_out_basalt_step_imports_as_one_step_and_a_law_fits_it(tmp_path, capsys):
    assert main(["datasets", "import", "velstep", str(PATH), "--name", "basalt-velstep7", "--out", str(tmp_path)]) == 0
    assert "1 velocity step" in capsys.readouterr().out
    data = fl.load_dataset(tmp_path / "basalt-velstep7.toml")
    assert data.provenance.kind == "measured"
    c = fl.compare(datasets=[data], bootstrap=0, equivalence=False, transfer=False)
    (answer,) = [a for a in c.answers if a.group == "basalt-velstep7"]
    assert answer.fits, answer.headline
