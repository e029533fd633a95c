"""Bootstrap: determinism by seed, executors (local, threads, Dask) give identical numbers, tables."""
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from frictionlab.core.errors import FrictionLabError, ParameterError
from frictionlab.inference.resampling.bootstrap import bootstrap, law_fit
from frictionlab.inference.resampling.ranking_bootstrap import bootstrap_ranking, parameter_table, ranking_table

DS = "incline-oil-a100"  # synthetic Couette data, eta fixed: h is the one fitted parameter


@pytest.fixture(scope="module")
def local():
    return bootstrap(law_fit("couette", solver="exact"), DS, n=12, seed=11)


def test_residual_bootstrap_interval_covers_the_fit(local):
    assert local.names == ("h",) and local.n_ok == 12 and not local.failures
    lo, hi = local.interval("h")
    h = local.base.value("h")
    assert lo < h < hi
    # the bootstrap spread agrees with lmfit's standard error to within a factor of two
    assert 0.5 < local.std("h") / local.base.stderr("h") < 2.0
    row = parameter_table(local)[0]
    assert row["parameter"] == "h" and row["unit"] == "m" and row["ci_low"] == lo and row["n_ok"] == 12


def test_same_seed_same_numbers_any_executor(local):
    again = bootstrap(law_fit("couette", solver="exact"), DS, n=12, seed=11, chunk=5)
    assert np.array_equal(again.samples, local.samples)
    with ThreadPoolExecutor(2) as ex:
        threaded = bootstrap(law_fit("couette", solver="exact"), DS, n=12, seed=11, executor=ex, chunk=2)
    assert np.array_equal(threaded.samples, local.samples)
    other = bootstrap(law_fit("couette", solver="exact"), DS, n=12, seed=12)
    assert not np.array_equal(other.samples, local.samples)


def test_dask_local_cluster_matches_local_run(local):
    pytest.importorskip("dask")
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = bootstrap(law_fit("couette", solver="exact"), DS, n=12, seed=11, executor=client, chunk=3)
        via_executor = bootstrap(law_fit("couette", solver="exact"), DS, n=12, seed=11,
                                 executor=client.get_executor(), chunk=4)
    assert np.array_equal(remote.samples, local.samples)
    assert np.array_equal(via_executor.samples, local.samples)


def test_case_resampling_and_ranking_table():
    rb = bootstrap_ranking(["couette", "coulomb"], DS, n=6, seed=3)
    assert rb.n_ranked == 6
    rows = ranking_table(rb)
    assert [r["law"] for r in rows] == ["couette", "coulomb"]  # Coulomb cannot level off
    assert rows[0]["first_fraction"] == 1.0 and rows[0]["ci_low"] > 0.5
    assert sum(r["first_count"] for r in rows) == 6
    table = parameter_table(rb)
    assert {r["law"] for r in table} == {"couette", "coulomb"}


def test_equivalent_laws_split_first_place():
    """Wear and Couette are the same model on a constant area: ties are split, not broken by noise."""
    rb = bootstrap_ranking(["couette", "wear"], DS, n=4, seed=5)
    assert rb.fraction("couette") == pytest.approx(0.5) and rb.fraction("wear") == pytest.approx(0.5)


def test_bad_arguments_are_one_line_errors():
    with pytest.raises(ParameterError):
        bootstrap(law_fit("couette"), DS, n=0)
    with pytest.raises(ParameterError):
        bootstrap(law_fit("couette"), DS, n=3, method="jackknife")
    with pytest.raises(FrictionLabError):
        bootstrap(law_fit("couette"), "no-such-dataset", n=3)


def test_case_resamples_repeat_times_and_the_ode_solver_takes_them():
    import attrs

    from frictionlab import load_dataset

    dry = load_dataset("incline-dry-d10")
    dry = attrs.evolve(dry, columns={k: v[::4] for k, v in dry.columns.items()})
    b = bootstrap(law_fit("wear", solver="ode"), dry, n=3, seed=1, method="case")
    assert b.n_ok == 3 and not b.failures


def test_candidates_are_labelled_by_solver_and_reuse_given_fits():
    from frictionlab import fit

    base = [fit("couette", DS, solver="exact"), fit("couette", DS, solver="ode")]
    rb = bootstrap_ranking([law_fit("couette", "exact"), law_fit("couette", "ode")], DS, n=3, seed=2, bases=base)
    assert rb.laws == ("couette [exact]", "couette [ode]")
    assert rb.results["couette [exact]"].base is base[0]
    rows = ranking_table(rb)
    assert {(r["candidate"], r["law"], r["solver"]) for r in rows} == {("couette [exact]", "couette", "exact"),
                                                                        ("couette [ode]", "couette", "ode")}
    with pytest.raises(ParameterError, match="differ"):
        bootstrap_ranking([law_fit("couette", "exact"), law_fit("couette", "exact")], DS, n=2)


def test_slow_datasets_are_left_out_with_the_reason_and_the_flag():
    """An impact-outcome set simulates every impact at each evaluation: not bootstrapped by default."""
    from frictionlab import fit
    from frictionlab.inference.resampling.ranking_bootstrap import bootstrap_fits

    f = fit("wear", "impact-outcome-synthetic")
    done, skipped = bootstrap_fits([f], 5)
    assert done == [] and "impact-outcome set" in skipped[f.datasets[0]] and "--bootstrap-all" in skipped[f.datasets[0]]


def test_a_replicate_refit_without_error_analysis_has_the_full_fits_aic():
    """fit(errors=False, n_params=k) skips the Jacobian but counts k parameters: on an incline, where
    area-rate's eta' has no effect (dA/dt = 0), its AIC is the full analysis's, not that of every free one."""
    from frictionlab import fit, load_dataset

    ds = load_dataset("incline-oil-a200")
    full = fit("area-rate", ds)
    start = {p.key: p.value for p in full.params.values() if p.kind == "law" and p.vary}
    every = fit("area-rate", ds, initial=start, scan=0, n_starts=1, errors=False)
    counted = fit("area-rate", ds, initial=start, scan=0, n_starts=1, errors=False, n_params=full.stats.n_params)
    assert full.stats.n_params < every.stats.n_params  # the analysis found a parameter without effect
    assert counted.stats.aic == pytest.approx(full.stats.aic, rel=1e-9, abs=1e-9)
    assert every.stats.aic != pytest.approx(full.stats.aic, rel=1e-9, abs=1e-9)
    with pytest.raises(ParameterError, match="n_params"):
        fit("area-rate", ds, n_params=1)  # only with errors=False
