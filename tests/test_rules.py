"""Every rule quoted as applied: each threshold the report prints is read back from the rendered report and
checked against the constant the code applies; the verdict sentences are whole parts that cannot run into one
another, on every dataset of the built-in and known-truth sets."""
import html
import re
from pathlib import Path

import pytest

from frictionlab import compare
from frictionlab.inference.equivalence import discrimination as eq
from frictionlab.inference.diagnostics import goodness as gd
from frictionlab.inference.diagnostics import identifiability as ident
from frictionlab.inference.diagnostics import plausibility as pl
from frictionlab.inference.verdicts import ranking as rk
from frictionlab.inference.verdicts import rules
from frictionlab.inference.equivalence import transfer as tr
from frictionlab.inference.equivalence.discrimination import sentence
from frictionlab.inference.equivalence.margin import MARGIN
from frictionlab.io.dataset import builtin_names
from frictionlab.report import build
from frictionlab.report.render import markdown
from frictionlab.report.first_screen import NOTES, note_parts

KT = Path(__file__).resolve().parent.parent / "examples" / "known-truth"
NUM = r"([0-9]+(?:\.[0-9]+)?(?:e-?[0-9]+)?)"

#: (what, pattern with one number, the constant it must equal); each must be found at least once in the report
THRESHOLDS = [
    ("a test's level in the fit rule", rf"has p ≥ {NUM}", lambda: gd.TEST_LEVEL),
    ("the transfer test's level", rf"one set serves when p ≥ {NUM}", lambda: tr.ALPHA),
    ("a failed test's level", rf"p = [0-9.e+-]+ < {NUM}", lambda: gd.TEST_LEVEL),
    ("the fit rule's family-wise level", rf"family-wise level of {NUM}", lambda: gd.FITS_LEVEL),
    ("a shared rank", rf"ΔAIC ≤ {NUM}", lambda: rk.TIE_AIC),
    ("a near tie", rf"ΔAIC < {NUM}", lambda: rk.NEAR_TIE),
    ("the tests' level", rf"α = {NUM}", lambda: eq.ALPHA),
    ("the threshold's chi-square", rf"χ² {NUM} \(about 50% power", lambda: eq.CRITICAL),
    ("the bound's level", rf"upper {NUM}% bound", lambda: 100 * (1 - eq.ALPHA)),
    ("the default margin", rf"δ = {NUM} × σ", lambda: MARGIN),
    ("the range flag", rf"exceeds {NUM}× the starting speed", lambda: pl.RANGE),
    ("the work flag", rf"beyond {NUM}% of its total work", lambda: 100 * pl.WORK_TOL),
    ("a parameter at a bound", rf"within {NUM}% of a nonzero bound", lambda: 100 * ident.AT_BOUND_REL),
    ("a strong correlation", rf"\|r\| > {NUM}", lambda: ident.CORRELATION_LIMIT),
]


@pytest.fixture(scope="module")
def every_set():
    """The built-in and known-truth sets in one comparison (few replicates: the texts, not the p-values, are tested)."""
    datasets = builtin_names() + sorted(str(p) for p in KT.glob("*.toml"))
    return compare(datasets=datasets, replicates=20, jobs=2)


@pytest.fixture(scope="module")
def report_md(every_set):
    """The report's Markdown, every section on one page (the texts write_report writes; no figure drawn)."""
    sections, _ = build(every_set)
    return html.unescape(markdown("report", sections))  # '<' is '&lt;' in Markdown


@pytest.mark.parametrize("what, pattern, constant", THRESHOLDS, ids=[t[0] for t in THRESHOLDS])
def test_every_threshold_printed_is_the_one_applied(report_md, what, pattern, constant):
    found = [float(m) for m in re.findall(pattern, report_md)]
    assert found, f"{what}: '{pattern}' is not in the report"
    assert all(v == pytest.approx(constant()) for v in found), (what, sorted(set(found)), constant())


def test_no_rule_is_quoted_with_a_threshold_the_code_does_not_apply(report_md):
    assert "p ≥ 0.01" not in report_md  # the fit rule's level is per test, 0.005 (0.01 family-wise)
    assert "≡" not in report_md  # no identity where the test answers different / within δ / cannot tell


def test_the_rule_texts_follow_their_constants(monkeypatch):
    """One source of truth: change a constant and the sentence that quotes it changes."""
    monkeypatch.setattr(gd, "TEST_LEVEL", 0.004)
    monkeypatch.setattr(rk, "NEAR_TIE", 3.0)
    assert "p ≥ 0.004" in rules.goodness() and "ΔAIC < 3" in rules.ties()


def test_verdict_sentences_are_whole_parts_on_every_dataset(every_set):
    """Each field of an answer is a labelled run of whole sentences, and says what its label says."""
    labels = {label: field for field, label in NOTES if label}
    for a in every_set.answers:
        if a.best is None:
            continue
        for part in note_parts(a):
            assert part.endswith("."), part
            for bad in (": .", "; .", ". .", "..", " ,", "  ", ":.", " : "):
                assert bad not in part, (bad, part)
            m = re.match(r"\*\*(.+?)\.\*\* (.)", part)
            if m is None:  # the headline: no label
                assert part.startswith(("Best: ", "No registered law", "Fit not testable", "Best:")), part
                continue
            label = m.group(1)
            text = part[len(label) + 6:]
            assert label in labels and sentence(text) == text, part  # whole sentences: a plain first word capital
            if label == "Noise threshold":
                assert "Qualitatively" not in text and ("χ² 3.84" in text or "same curve" in text), part
            if label == "Shared features":
                assert text.startswith("Qualitatively (do the fitted curves share"), part
            if label == "What accuracy costs":
                assert text.startswith(("Against the closed form", "Against the ODE", "Not run")), part


def test_every_equivalence_explanation_ends_on_its_verdict_or_says_there_is_no_test(every_set):
    for e in every_set.equivalence:
        if not e.ok:
            continue
        assert e.verdict in eq.VERDICTS
        if e.tested:
            assert f"So: {e.verdict}" in e.explanation, e.explanation
            assert "two-sided p" in e.explanation and "upper 95% bound" in e.explanation
        else:
            assert e.explanation.startswith("No test: ") and "two-sided p" not in e.explanation
        for bad in (". .", "..", ": .", "  "):
            assert bad not in e.explanation, (bad, e.explanation)


def test_an_akaike_weight_is_said_with_what_it_compares_and_never_for_a_failing_candidate(report_md, every_set):
    summary = report_md.split("## Summary", 1)[1].split("\n## ", 1)[0]
    weights = re.findall(r"Akaike weight [0-9.]+[^;)]*", summary)
    assert weights and all("among" in w or "the only candidate that fits" in w for w in weights), weights
    for line in summary.splitlines():
        if "top-ranked (does not fit)" in line and "Akaike" in line:
            assert "no Akaike weight" in line and not re.search(r"Akaike weight [0-9]", line), line
    for r in every_set.ranking:
        if r.fits is False:
            assert r.weight_text.startswith("no Akaike weight")
