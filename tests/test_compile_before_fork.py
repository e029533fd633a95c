"""The velocity-step kernels compiled in the parent before a pool forks (``comparison._import_before_fork``) are the
ones the fits call: compiling them there adds the one type signature each fit uses, and no fit adds another."""
from __future__ import annotations

import pytest

import frictionlab as fl

numba = pytest.importorskip("numba")


def test_the_signatures_compiled_ahead_are_the_ones_the_fits_use():
    from frictionlab.inference.velstep.kernel import basis_sums, compile_sums
    from frictionlab.solve import quasistatic_kernel as kernel
    from frictionlab.solve.quasistatic import compile_kernel

    compile_kernel()
    compile_sums()
    ahead = [tuple(f.signatures) for f in (kernel.integrate, basis_sums)]
    assert all(len(s) == 1 for s in ahead), ahead
    for law in ("rate-state-aging", "rate-state-nagata"):
        assert fl.fit(law, "spring-slider-aging").ok
    assert [tuple(f.signatures) for f in (kernel.integrate, basis_sums)] == ahead
