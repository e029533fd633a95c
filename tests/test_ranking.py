"""Ranking: statistics arithmetic, ties, groups, and known-truth rankings on synthetic data."""
import math

import attrs
import pytest
from _fit_helpers import TRUTH, incline_scene, synthetic

from frictionlab import compare
from frictionlab.inference.verdicts.ranking import COLUMNS, RankRow, _rank, rank_groups, to_csv


def row(ds, law, aic, solver="exact", n=20, k=1, status="ok"):
    """A row whose -2 ln L is aic - 2k (known sigma)."""
    return RankRow(ds, law, solver, n, k, 1.0, 1.0, 1.0, aic, aic + 0.1, aic + 1.0, status=status,
                   likelihood="known", neg2loglik=aic - 2 * k, k_lik=k)


def test_delta_weights_and_competition_ranks_with_ties():
    rows = _rank([row("d", "a", 10.0), row("d", "b", 10.004), row("d", "c", 12.0), row("d", "x", math.nan,
                                                                                    status="failed")], tie=0.01)
    by = {r.law: r for r in rows}
    assert by["a"].rank == 1 and by["b"].rank == 1 and by["c"].rank == 3 and by["x"].rank is None
    assert by["a"].status == by["b"].status == "tied" and by["x"].status == "failed"
    assert by["c"].status == "indistinguishable" and by["c"].tied_with == ("b [exact]",)  # within delta-AIC < 2 of b
    assert by["a"].delta_aic == 0 and by["c"].delta_aic == pytest.approx(2.0)
    assert sum(r.akaike_weight for r in rows if r.rank) == pytest.approx(1.0)
    assert by["c"].akaike_weight / by["a"].akaike_weight == pytest.approx(math.exp(-1.0))
    assert by["a"].tied_with == ("b [exact]",)


def test_akaike_weights_compare_the_candidates_that_fit_and_say_so():
    """A weight is reported with what it compares, and never for a candidate that fails its fit tests."""
    rows = _rank([attrs.evolve(row("d", "a", 10.0), fits=True), attrs.evolve(row("d", "b", 11.0), fits=True),
                  attrs.evolve(row("d", "c", 5.0), fits=False)], tie=0.01)
    by = {r.law: r for r in rows}
    assert by["c"].rank == 1 and math.isnan(by["c"].akaike_weight) and by["c"].weight_among == ()
    assert by["a"].akaike_weight + by["b"].akaike_weight == pytest.approx(1.0)
    assert by["a"].weight_among == ("a [exact]", "b [exact]")
    assert by["a"].weight_text == f"Akaike weight {by['a'].akaike_weight:.2f} among a [exact], b [exact] (the candidates that fit)"
    assert by["c"].weight_text.startswith("no Akaike weight: it fails its fit tests")
    alone = _rank([attrs.evolve(row("d", "a", 10.0), fits=True), attrs.evolve(row("d", "c", 5.0), fits=False)], 0.01)
    assert next(r for r in alone if r.law == "a").weight_text == "Akaike weight 1 by construction: the only candidate that fits"
    none = _rank([attrs.evolve(row("d", "a", 10.0), fits=False), attrs.evolve(row("d", "c", 5.0), fits=False)], 0.01)
    assert all(math.isnan(r.akaike_weight) for r in none) and [r.rank for r in none] == [1, 2]


def test_groups_sum_aic_and_mark_incomplete_candidates():
    rows = _rank([row("d1", "a", 10.0), row("d1", "b", 14.0), row("d1", "a", 9.0, solver="series")], 0.01)
    rows += _rank([row("d2", "a", 5.0, solver="ode"), row("d2", "b", 4.0)], 0.01)
    assert rank_groups(rows, {"d1": "impact", "d2": "incline"}) == []  # nothing declared: no sum over datasets
    assert rank_groups(rows, named={"d1": "d1", "d2": "d2"}) == []  # one-dataset groups: no second ranking
    groups = rank_groups(rows, named={"d1": "pair", "d2": "pair"})  # a group the datasets declare
    allg = {(r.law, r.solver): r for r in groups if r.dataset == "pair"}
    assert allg[("a", "exact+ode")].aic == pytest.approx(15.0)  # exact and ode count as one candidate
    assert allg[("b", "exact")].aic == pytest.approx(18.0)
    assert allg[("a", "exact+ode")].rank == 1 and allg[("b", "exact")].rank == 2
    assert allg[("a", "series")].status == "incomplete" and "d2" in allg[("a", "series")].reason
    assert allg[("a", "exact+ode")].n_points == 40 and allg[("a", "exact+ode")].n_params == 2


def test_csv_has_the_documented_columns():
    failed = attrs.evolve(row("d", "b", math.nan, status="failed"), reason="did not converge")
    text = to_csv(_rank([row("d", "a", 1.0), failed], 0.01))
    lines = text.splitlines()
    assert lines[0] == ",".join(COLUMNS) == ("dataset,law,solver,n_points,n_params,rss,rmse,redchi,likelihood,aic,"
                                            "aicc,bic,delta_aic,akaike_weight,weight_among,rank,status,chi2_p,runs_p,"
                                            "lag1,fits,flags,at_bounds,reason")
    assert lines[2].endswith(",,failed,,,,,,,did not converge")  # no rank, no numbers for a failed fit, its reason


@pytest.mark.parametrize("law", sorted(TRUTH))
def test_known_truth_on_the_impact_scene(law):
    """Data from each built-in law plus 1% noise: its own law ranks first (wear and couette tie, having
    one form), and the generating parameters are recovered within 3 reported standard errors."""
    fixed = {"eta": TRUTH["couette"]["eta"]} if law == "couette" else None
    ds = synthetic(law, TRUTH[law], fixed=fixed, seed=7)
    c = compare(datasets=[ds], equivalence=False)
    ranked = [r for r in c.ranking if r.rank is not None]
    twins = {"wear", "couette"}
    merged = "wear = couette"  # one closed-form family, one candidate
    assert {r.law for r in ranked} == set(TRUTH) - twins | {merged}  # every law fitted
    first = {r.law for r in ranked if r.rank == 1}
    assert first == ({merged} if law in twins else {law})
    top = next(r for r in ranked if r.rank == 1)
    assert top.fits and top.akaike_weight == max(r.akaike_weight for r in ranked if r.fits)
    assert all(math.isnan(r.akaike_weight) and not r.weight_among for r in ranked if r.fits is False)
    own = c.fit_for(ds.name, law, "exact")
    for name, value in TRUTH[law].items():
        p = own.params[name]
        if p.vary:
            assert abs(p.value - value) <= 3 * p.stderr, (name, p.value, p.stderr)
    # solver is a dimension: the paper's series is ranked beside the exact solution where it applies
    assert any(r.solver == "series" for r in ranked)


def test_known_truth_on_an_incline_and_coulomb_cannot_level_off():
    ds = synthetic("couette", TRUTH["couette"] | {"h": 4e-5}, incline_scene(), n=40, fixed={"eta": 0.1})
    c = compare(datasets=[ds], equivalence=False)
    by = {r.law: r for r in c.ranking}
    assert by["wear = couette"].rank == 1 and by["wear = couette"].fits
    assert by["coulomb"].delta_aic > 50  # constant acceleration cannot approach a terminal speed
    assert by["area-rate"].rank == by["coulomb"].rank  # dA/dt = 0: area-rate is Coulomb here


def test_parallel_comparison_gives_the_same_results():
    ds = synthetic("wear", TRUTH["wear"], seed=8, n=16)
    one = compare(laws=["wear", "coulomb"], datasets=[ds], jobs=1)
    two = compare(laws=["wear", "coulomb"], datasets=[ds], jobs=2)
    assert [(r.candidate, r.rank) for r in one.ranking] == [(r.candidate, r.rank) for r in two.ranking]
    assert [r.aic for r in one.ranking] == pytest.approx([r.aic for r in two.ranking], rel=1e-12)


def test_one_curve_of_an_unflagged_and_a_flagged_law_is_one_row_with_both_flags():
    """Coulomb and an area-rate whose eta' has no effect predict one curve; the flagged area-rate ranks as
    merely indistinguishable from the unflagged Coulomb (a flag breaks a tie), yet in the table they are one
    row: 'same curve', not 'indistinguishable' from nobody, and area-rate's flag stays on it, as its own."""
    from frictionlab.report.ranking import candidate_table

    flagged = attrs.evolve(row("d", "area-rate", 10.0), flags=("slip reaches 7e6 times the starting speed",))
    rows = _rank([row("d", "coulomb", 10.0), flagged, row("d", "wear", 30.0)], tie=0.01)
    assert {r.law: r.status for r in rows} == {"coulomb": "indistinguishable", "area-rate": "indistinguishable",
                                                "wear": "ok"}
    labels = {("coulomb", "exact"): "coulomb = area-rate", ("area-rate", "exact"): "coulomb = area-rate"}
    headers, table = candidate_table(rows, "cm_tangential_cor", labels)
    status = {r[1]: r[-1] for r in table}
    assert set(status) == {"coulomb = area-rate [exact]", "wear [exact]"}
    assert status["coulomb = area-rate [exact]"] == \
        "same curve; FLAG (area-rate only): slip reaches 7e6 times the starting speed"


def test_one_family_is_represented_by_its_simplest_member_where_they_reach_one_minimum():
    """Wear and Couette fitted to one dataset reach one minimum; which lands a round-off lower decides nothing."""
    from _fit_helpers import impact_scene

    from frictionlab import fit
    from frictionlab.inference.verdicts.ranking import merge_identical

    data = synthetic("wear", TRUTH["wear"], impact_scene(), name="one-family")
    w, c = fit("wear", data, solver="exact"), fit("couette", data, solver="exact")
    for pair in ((w, c), (c, w)):
        ((best, members, _),) = merge_identical(list(pair))
        assert best.law == "wear" and members == ("wear", "couette")
    worse = attrs.evolve(w, stats=attrs.evolve(w.stats, aic=w.stats.aic + 1.0, chisqr=w.stats.chisqr + 1.0))
    ((best, _, _),) = merge_identical([worse, c])
    assert best.law == "couette"  # a member clearly lower stands for the family
