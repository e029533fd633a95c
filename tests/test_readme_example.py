"""The README's notebook-style library session runs as written, and gives what it says."""
import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def library_session() -> str:
    text = README.read_text()
    start = text.index("As a library (SI in, SI out)")
    return re.search(r"```python\n(.*?)```", text[start:], re.S).group(1)


def test_readme_library_session_runs(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    ns = {}
    exec(compile(library_session(), "README.md", "exec"), ns)
    assert "[[Variables]]" in capsys.readouterr().out
    r = ns["result"]
    assert repr(r).startswith("<FitResult wear [series] on impact-golf-v28: lam = ") and len(repr(r)) < 200
    assert ns["result"].minimizer_result.params["lam"].value == r.value("lam")
    assert abs(r.lmfit_params["lam"].stderr - r.stderr("lam")) < 1e-9 * r.stderr("lam")
    ranking, best = ns["ranking"], ns["best"]
    assert {"dataset", "law", "solver", "rank", "rmse", "rmse_unit", "aic"} <= set(ranking.columns)
    assert list(best["candidate"]) == ["wear [series]"] and set(best["rmse_unit"]) == {"rad/s"}
    params = ns["params"]
    assert set(params["unit"]) == {"Pa s/m", ""} and (params["value"] > 0).all()
    assert "<table" in r._repr_html_() and "<table" in ns["comparison"]._repr_html_()
    assert len(repr(ns["comparison"])) < 300
    assert (tmp_path / "my-report" / "report.html").exists()
