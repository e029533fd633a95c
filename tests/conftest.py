import compileall
import os
import signal
import subprocess
import sys
from pathlib import Path

import frictionlab
from frictionlab.cli import blas_one_thread

blas_one_thread()  # the suite computes with BLAS as the command line does (set before numpy is imported)

import matplotlib  # noqa: E402
import pytest  # noqa: E402

matplotlib.use("Agg")

# A suite started in the background (`cmd &` in a script) inherits SIGINT ignored, and so would every command
# it runs, so the tests of ^C would find it ignored; the suite takes SIGINT as a terminal delivers it, and so
# do the commands it starts (a handled signal is back to its default in a new program).
if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_configure(config):
    """Bytecode written and read back, as Python does by default: the suite starts some hundred commands, each
    a new interpreter, and where PYTHONDONTWRITEBYTECODE is set each would compile every module of the package it
    imports from source again (about 0.3 CPU s a command), and each worker would rewrite the asserts of every test
    module again at every run (about 10 CPU s). The package is compiled once, before the workers start."""
    sys.dont_write_bytecode = False  # this process and the workers write the bytecode of what they import
    if not hasattr(config, "workerinput"):  # the main process (xdist's workers are started after it)
        compileall.compile_dir(Path(frictionlab.__file__).parent, quiet=1)


@pytest.fixture(autouse=True, scope="session")
def _record_cache(tmp_path_factory):
    """The measured records' import cache of this test session, not the user's."""
    os.environ["XDG_CACHE_HOME"] = str(tmp_path_factory.mktemp("cache"))


@pytest.fixture
def run_cli():
    """Run ``python -m frictionlab ARGS`` in a subprocess; returns CompletedProcess."""

    def run(*args, cwd=None, env=None):
        full_env = {**os.environ, **(env or {})}
        return subprocess.run([sys.executable, "-m", "frictionlab", *map(str, args)], capture_output=True,
                              text=True, cwd=cwd, env=full_env, timeout=600)

    return run
