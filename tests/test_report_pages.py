"""A comparison of many dataset groups is written as an index page and one page per group."""
import json

import pytest

from frictionlab.report import pages, write_report


@pytest.fixture(scope="module")
def comparison():
    from frictionlab.pipeline.comparison import compare

    return compare(laws=["wear", "coulomb"], datasets=["incline-oil-a100", "incline-oil-a200", "impact-golf-v28",
                                                      "kharaz2001-spin"], bootstrap=0)


def test_many_groups_make_an_index_and_a_page_per_group(comparison, tmp_path, monkeypatch):
    groups = pages.groups_of(comparison)
    assert set(groups) == {"incline-oil", "impact-golf", "kharaz2001"}
    monkeypatch.setattr(pages, "GROUP_PAGES_AT", 2)
    out = write_report(comparison, tmp_path / "r")
    index = (out / "report.html").read_text()
    for g in groups:
        assert f'href="groups/{g}.html"' in index
        page = (out / "groups" / f"{g}.html").read_text()
        others = [n for h, names in groups.items() if h != g for n in names]
        assert all(n in page for n in groups[g]) and not any(n in page for n in others)
        assert 'href="../report.html"' in page
        assert (out / "groups" / f"{g}.md").read_text().count(f"../figures/{g}/") >= 1
        assert list((out / "figures" / g).glob("*.png"))
    assert "groups/impact-golf.md" in (out / "report.md").read_text()
    whole = json.loads((out / "results.json").read_text())
    assert {f["dataset"] for f in whole["fits"]} >= {"incline-oil-a100", "impact-golf-v28"}


def test_few_groups_stay_one_page(comparison, tmp_path):
    out = write_report(comparison, tmp_path / "r")
    assert not (out / "groups").exists() and "groups/" not in (out / "report.html").read_text()


def test_restrict_keeps_one_group(comparison):
    r = pages.restrict(comparison, ["impact-golf-v28"], "impact-golf")
    assert [d.name for d in r.datasets] == ["impact-golf-v28"]
    assert {f.datasets for f in r.fits} == {("impact-golf-v28",)} and {a.group for a in r.answers} == {"impact-golf"}
    assert all(e.dataset == "impact-golf-v28" for e in r.equivalence)
