"""The default laws of ``compare`` are chosen by dataset kind: the seed paper's four on impacts and inclines,
rate-and-state (aging, slip, PRZ, Nagata) on spring-slider velocity steps; named laws go to every dataset as before."""
from __future__ import annotations

from types import SimpleNamespace

from frictionlab.commands.compare import laws_lines
from frictionlab.io.dataset import load_dataset
from frictionlab.pipeline.planning import plan_fits
from frictionlab.pipeline.settings import DEFAULT_LAWS, Settings, default_laws_by_kind
from frictionlab.report.summary import _laws_text

RS = ("rate-state-aging", "rate-state-slip", "rate-state-prz", "rate-state-nagata")


def test_the_default_laws_of_each_kind():
    by_kind = default_laws_by_kind(["impact", "spring-slider", "incline", "spring-slider"])
    assert by_kind == {"impact": DEFAULT_LAWS, "spring-slider": RS, "incline": DEFAULT_LAWS}


def test_the_plan_fits_each_dataset_with_the_laws_of_its_kind_and_named_laws_everywhere():
    dss = [load_dataset(n) for n in ("spring-slider-aging", "incline-oil-a100", "impact-golf-v28")]
    by_kind = default_laws_by_kind(d.kind for d in dss)
    laws = tuple(dict.fromkeys(n for v in by_kind.values() for n in v))
    fitted = {}
    for law, ds, _, _ in plan_fits(laws, dss, None, {}, by_kind).tasks:
        fitted.setdefault(ds.name, set()).add(law)
    assert fitted == {"spring-slider-aging": set(RS), "incline-oil-a100": set(DEFAULT_LAWS),
                      "impact-golf-v28": set(DEFAULT_LAWS)}
    named = plan_fits(("coulomb", "rate-state-aging"), dss, None, {})  # --laws: every law on every dataset
    assert {(law, ds.name) for law, ds, _, _ in named.tasks} >= {("rate-state-aging", "spring-slider-aging"),
                                                                  ("coulomb", "incline-oil-a100")}


def test_the_command_line_and_the_report_say_which_laws_went_to_which_kind():
    by_kind = default_laws_by_kind(["impact", "incline", "spring-slider"])
    s = Settings(laws=DEFAULT_LAWS + RS, by_kind=by_kind)
    assert s.as_dict()["laws_by_kind"]["spring-slider"] == list(RS)
    c = SimpleNamespace(options=s, settings=s.as_dict(), laws=s.laws,
                        datasets=[SimpleNamespace(kind=k) for k in ("impact", "incline", "spring-slider")])
    assert laws_lines(c) == ["laws by dataset kind (the default): coulomb, area-rate, wear, couette on impact, "
                             "incline; rate-state-aging, rate-state-slip, rate-state-prz, rate-state-nagata on "
                             "spring-slider"]
    assert _laws_text(c) == ("coulomb, area-rate, wear, couette on impact, incline datasets; rate-state-aging, "
                             "rate-state-slip, rate-state-prz, rate-state-nagata on spring-slider datasets")
    named = SimpleNamespace(options=Settings(laws=("coulomb",)), settings={}, laws=("coulomb",), datasets=c.datasets)
    assert laws_lines(named) == [] and _laws_text(named) == "coulomb"


def test_pairs_of_the_default_laws_are_pairs_within_one_kind():
    from frictionlab.commands.compare import parse_pairs
    from frictionlab.core.errors import FrictionLabError

    assert parse_pairs(["rate-state-aging:rate-state-slip"], None) == (("rate-state-aging", "rate-state-slip"),)
    import pytest

    with pytest.raises(FrictionLabError, match="rate-state-aging is not among the compared laws"):
        parse_pairs(["rate-state-aging:wear"], None)
