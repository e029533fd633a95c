"""The compiled kernels a comparison runs, compiled (or read from numba's on-disk cache) once in the parent before
its pool forks, so that the forked workers inherit them instead of each compiling the same kernels: on a fresh
install every worker would otherwise pay the compilation (about 9 CPU s for the quasi-static slider, 13 for the
sliding phases), and on a warm one each would read the cache. Each warm-up is one tiny call of the kernel with the
argument types the fits use (one signature per kernel), and does nothing without numba.
"""
from __future__ import annotations

import importlib.util
from collections.abc import Iterable

import numpy as np


def warm_kernels(fits: Iterable[tuple[str, str]]) -> None:
    """Compile, here, the kernels that ``fits`` run: (law name, dataset kind) pairs, e.g. ('wear', 'impact')."""
    if importlib.util.find_spec("numba") is None:
        return
    fits = set(fits)
    spring = {law for law, kind in fits if kind == "spring-slider"}
    if spring:
        _quasistatic(spring)
    if any(kind in ("impact", "incline") for _, kind in fits):
        _sliding_phase({law for law, kind in fits if kind in ("impact", "incline")})


def _quasistatic(laws: set[str]) -> None:
    from ..inference.velstep.kernel import all_sums
    from ..solve import quasistatic

    codes = {quasistatic.LAWS[n] for n in laws & quasistatic.FITTED}
    if not codes:
        return
    code = max(codes, key=lambda c: len(quasistatic.EXTRA.get(c, ())))  # one solve compiles every law code;
    load = quasistatic.Load(np.array([0.0, 1.0]), np.array([1.0, 3.0]))  # a law's extra column, the extra sums
    t = np.linspace(0.0, 2.0, 5)
    sol = quasistatic.solve(code, 0.01, 0.012, 10.0, 0.01, load, t, 1e-6, sensitivities=True, c=0.5)
    n = t.size
    all_sums(np.zeros(n), 0.0, sol.m, sol.S, np.ones(n), np.zeros(n), np.ones(n), np.linalg.qr(np.ones((n, 1)))[0])


def _sliding_phase(laws: set[str]) -> None:
    from ..physics.scene import HalfSineArea, Scene
    from ..solve import compiled
    from ..solve.batch import simulate_batch

    if not (laws & {"coulomb", "area-rate", "wear", "couette"}) or not compiled.available():
        return
    scene = Scene(kind="impact", mass=0.046, u0=10.0, duration=5e-4, radius=0.0213,
                  area=HalfSineArea(1.5e-4, 5e-4), effects=frozenset({"spin"}))
    simulate_batch("wear", [scene], {"lam": 1e6}, solver="DOP853", n=5)
