"""compare as named stages: run or skip a stage by name, continue a comparison later, same numbers."""
import pytest

import frictionlab as fl
from frictionlab.core.errors import ParameterError
from frictionlab.pipeline.comparison import run_stages
from frictionlab.pipeline.stages import STAGES

KW = dict(laws=["coulomb", "wear"], datasets=["incline-oil-a100", "incline-oil-a200"], replicates=20, jobs=1)


@pytest.fixture(scope="module")
def whole():
    return fl.compare(**KW)


def test_the_stages_are_named_in_order():
    assert [s.name for s in STAGES] == ["fit", "rank", "equivalence", "transfer", "tolerance", "accuracy", "bootstrap",
                                        "answer"]


def test_a_comparison_run_in_two_steps_equals_one_run(whole):
    first = fl.compare(**KW, stages=["fit", "rank"])
    assert first.fits and first.ranking and first.equivalence == () and first.answers == ()
    assert set(first.timings) == {"fit", "rank"}
    later = run_stages(first, ["equivalence", "transfer", "accuracy", "answer"])
    assert [(e.dataset, e.law_a, e.law_b, e.status, e.verdict, e.explanation) for e in later.equivalence] == [
        (e.dataset, e.law_a, e.law_b, e.status, e.verdict, e.explanation) for e in whole.equivalence]
    timed = lambda short: {k: v for k, v in short.items() if k != "accuracy"}  # noqa: E731  its times are measured
    assert [timed(a.short) for a in later.answers] == [timed(a.short) for a in whole.answers]
    assert [a.accuracy != "" for a in later.answers] == [a.accuracy != "" for a in whole.answers]
    assert [(t.group, t.status) for t in later.transfer] == [(t.group, t.status) for t in whole.transfer]
    assert set(whole.timings) == {"fit", "rank", "equivalence", "transfer", "accuracy", "answer"}  # no bootstrap,
    # no tolerance


def test_a_stage_is_skipped_by_leaving_it_out(whole):
    c = fl.compare(**KW, stages=["fit", "rank", "answer"])
    assert c.equivalence == () and c.transfer == () and len(c.answers) == len(whole.answers)
    assert [r.aic for r in c.ranking] == [r.aic for r in whole.ranking]


def test_settings_can_be_changed_for_a_later_stage(whole):
    c = run_stages(whole, ["bootstrap"], bootstrap=3)
    assert c.settings["bootstrap"] == 3 and whole.settings["bootstrap"] == 0 and "bootstrap" in c.timings
    assert c.bootstrap or c.bootstrap_skipped


def test_an_unknown_stage_is_a_clear_error():
    with pytest.raises(ParameterError, match="unknown stage 'fits'; the stages are fit, rank, equivalence"):
        fl.compare(**KW, stages=["fits"])
