import os
import subprocess
import sys

import matplotlib
import pytest

matplotlib.use("Agg")


@pytest.fixture
def run_cli():
    """Run ``python -m frictionlab ARGS`` in a subprocess; returns CompletedProcess."""

    def run(*args, cwd=None, env=None):
        full_env = {**os.environ, **(env or {})}
        return subprocess.run([sys.executable, "-m", "frictionlab", *map(str, args)], capture_output=True,
                              text=True, cwd=cwd, env=full_env, timeout=600)

    return run
