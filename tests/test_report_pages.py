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


def test_a_figure_on_several_pages_is_drawn_once(comparison, tmp_path, monkeypatch):
    from frictionlab import report

    drawn = []

    def draw():
        import io

        import matplotlib.figure

        drawn.append(1)
        buf = io.BytesIO()
        matplotlib.figure.Figure(figsize=(1, 1)).savefig(buf, format="png")
        return buf.getvalue()

    pages_of = report._pages

    def with_shared(c, extra):  # every page shows one picture (one key), as the index and a group page can
        for path, sections, figdir in pages_of(c, extra):
            sections[0].fig("shared.png", "one picture on every page", draw, key=("shared", 1))
            yield path, sections, figdir

    monkeypatch.setattr(pages, "GROUP_PAGES_AT", 2)
    monkeypatch.setattr(report, "_pages", with_shared)
    out = write_report(comparison, tmp_path / "r")
    assert len(drawn) == 1
    folders = ["figures"] + [f"figures/{g}" for g in pages.groups_of(comparison)]
    assert all((out / f / "shared.png").read_bytes() == (out / "figures" / "shared.png").read_bytes() for f in folders)
    for html in [out / "report.html", *(out / "groups").glob("*.html")]:
        assert "one picture on every page" in html.read_text()


def test_a_group_page_opens_on_its_dataset_fits_drawn_once(comparison, tmp_path, monkeypatch):
    """A group's page (no series finding) shows the fit figure of its dataset on its first screen: the picture its
    'Fits' section shows too, drawn once for both; the index keeps the panel of every group."""
    from frictionlab.report import figures

    calls = []
    real = figures.fit_figure
    monkeypatch.setattr(figures, "fit_figure", lambda d, *a: calls.append(d.name) or real(d, *a))
    monkeypatch.setattr(pages, "GROUP_PAGES_AT", 2)
    out = write_report(comparison, tmp_path / "r")
    md = (out / "groups" / "kharaz2001.md").read_text()
    first, details = md.split("## Summary", 1)
    assert "fit-kharaz2001-spin.png" in first and "finding.png" not in first
    assert "fit-kharaz2001-spin.png" in details
    assert sorted(calls) == sorted(set(calls))  # each dataset's fit figure drawn once
    assert (out / "figures" / "finding.png").exists() and not (out / "figures" / "kharaz2001" / "finding.png").exists()
    golf = (out / "groups" / "impact-golf.md").read_text()
    assert "finding.png" in golf  # the series' slip panel is the golf group's own figure
