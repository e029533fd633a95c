"""The README's five-minute tour in Python runs as written and gives what it says (tests/test_docs.py runs
it too, as a script; here its results are checked)."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


def library_session() -> str:
    text = README.read_text()
    start = text.index("## A five-minute tour")
    return re.search(r"```python\n(.*?)```", text[start:], re.S).group(1)


def test_readme_is_short():
    assert len(README.read_text().splitlines()) <= 200


def test_readme_library_session_runs(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    ns = {}
    exec(compile(library_session(), "README.md", "exec"), ns)
    printed = capsys.readouterr().out
    assert "wear [series] on impact-golf-v28" in printed and "goodness of fit" in printed
    r = ns["result"]
    assert repr(r).startswith("<FitResult wear [series] on impact-golf-v28: lam = ") and len(repr(r)) < 200
    assert r.minimizer_result.params["lam"].value == r.value("lam")
    assert abs(r.lmfit_params["lam"].stderr - r.stderr("lam")) < 1e-9 * r.stderr("lam")
    ranking = ns["comparison"].to_dataframe()
    assert {"dataset", "law", "solver", "rank", "rmse", "rmse_unit", "aic", "fits"} <= set(ranking.columns)
    best = ranking[(ranking["rank"] == 1) & (ranking["dataset"] == "impact-golf-v28")]
    assert list(best["candidate"]) == ["wear [series]"] and set(best["rmse_unit"]) == {"rad"}  # fitted to theta
    assert "<table" in r._repr_html_() and "<table" in ns["comparison"]._repr_html_()
    assert (tmp_path / "fit.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "tour-report" / "report.html").exists()
