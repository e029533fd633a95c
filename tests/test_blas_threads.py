"""A library call computes with one BLAS thread and gives the caller's setting back (frictionlab.core.blas)."""
from __future__ import annotations

import pytest

threadpoolctl = pytest.importorskip("threadpoolctl")

import frictionlab as fl  # noqa: E402
from frictionlab.core.blas import one_blas_thread  # noqa: E402


def blas_threads() -> set[int]:
    return {i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"}


def test_a_call_sees_one_thread_and_the_caller_gets_its_setting_back():
    if not blas_threads():
        pytest.skip("no BLAS library that threadpoolctl knows is loaded")
    seen = []
    nested = one_blas_thread(lambda: seen.append(blas_threads()))
    outer = one_blas_thread(lambda: (seen.append(blas_threads()), nested()))
    with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
        assert blas_threads() == {2}
        outer()
        assert blas_threads() == {2}
        with pytest.raises(ZeroDivisionError):
            one_blas_thread(lambda: 1 / 0)()
        assert blas_threads() == {2}
    assert seen == [{1}, {1}]


@pytest.mark.parametrize("name", ["fit", "compare", "analyze_equivalence", "load_dataset"])
def test_the_library_calls_that_compute_are_limited(name):
    fn = getattr(fl, name)
    assert fn.__wrapped__.__name__ == name and fn.__doc__ == fn.__wrapped__.__doc__


def test_a_fit_runs_with_one_thread_whatever_the_caller_set(monkeypatch):
    from frictionlab.inference.fitting import fit as fitting

    seen = []
    real = fitting.make_target

    def spy(*args, **kwargs):
        seen.append(blas_threads())
        return real(*args, **kwargs)

    monkeypatch.setattr(fitting, "make_target", spy)
    with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
        fl.fit("coulomb", "incline-dry-d10")
    assert seen and all(s == {1} for s in seen)
