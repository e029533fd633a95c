"""Work-precision: error against a reference versus median run time, per method and tolerance.

See ``run_bench``; the ``frictionlab bench`` command writes its diagrams and tables.
"""
from __future__ import annotations

import os
import platform
from importlib import metadata


def cpu_model() -> str:
    """CPU model name from /proc/cpuinfo (Linux), else platform.processor()."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.lower().startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown CPU"


def environment() -> dict:
    """Hardware and package versions, for stating next to any timing."""
    versions = {"python": platform.python_version()}
    for pkg in ("frictionlab", "numpy", "scipy", "matplotlib", "numba"):
        try:
            versions[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            pass
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return {"cpu": cpu_model(), "cores": cores, "platform": platform.platform(), "versions": versions}
