"""The answer to the mission's question, one row per dataset group: what the report's first screen shows.

This module is the contract between the verdict layer (which fills the rows) and everything that
shows them (the report's first screen, the CLI's closing summary, ``results.json``). A row is
plain text and numbers, already decided: consumers render it, they never re-derive a verdict.

Groups: a dataset's ``group`` (TOML key ``group``; default: its name without the last
``-suffix``, so ``impact-golf-v28`` and ``impact-golf-v61`` form ``impact-golf``).
"""
from __future__ import annotations

import attrs

#: Keys of ``Answer.short``, in table order, with the long field each one summarizes.
SHORT = {"best": "headline", "goodness": "goodness", "equivalence": "equivalence",
         "threshold": "noise_threshold", "series": "series_vs_exact", "accuracy": "accuracy", "transfer": "transfer",
         "closer": "closer"}

#: The equivalence verdicts a row may carry: a test's (``equivalence.VERDICTS``) or none.
EQUIVALENCE = ("different", "equivalent within δ", "cannot tell at this noise", "both fail their fit tests",
               "not tested")


@attrs.frozen
class Answer:
    """One dataset group's answer. Every text field is one short sentence or phrase ("" when not applicable)."""

    group: str  # group label, e.g. "impact-golf"
    datasets: tuple[str, ...]  # member datasets that were fitted
    provenance: str  # measured | reported | reconstructed | synthetic | mixed
    best: str | None  # the best candidate ("wear = couette [exact]"), None when no law could be fitted
    fits: bool  # the best candidate passes the goodness-of-fit tests
    headline: str  # "best: X" or "no registered law describes these data (best of a poor set: X)"
    goodness: str  # how well the best fits, e.g. "chi2 p = 0.41, runs test p = 0.62"
    equivalence: str  # one of EQUIVALENCE: lambda A u against mu N + mu eta' dA/dt on this group
    noise_threshold: str  # e.g. "the two laws differ by more than the noise when sigma < 150 rpm"
    series_vs_exact: str  # e.g. "the series' spin falls because its slip crosses zero at 309 us"
    transfer: str = ""  # e.g. "one lambda serves both speeds: no (prediction error 12 sigma)"
    equivalence_series: str = ""  # one of EQUIVALENCE: the paper's series of lambda A u against mu N + mu eta' dA/dt
    qualitative: str = ""  # do the two laws' fitted curves share the data's features (one sentence)
    accuracy: str = ""  # what accuracy costs: each solver's error and time against the most accurate one
    closer: str = ""  # which of the two best laws is closer to the data, on one likelihood (``vuong``)
    details: dict = attrs.field(factory=dict)  # machine-readable numbers behind the texts (SI), for results.json
    #: a few words per cell with the decisive number, for the first screen's table and the CLI's closing lines;
    #: keys SHORT (filled by the producer of the matching long field; absent when it gave none)
    short: dict = attrs.field(factory=dict)

    def as_dict(self) -> dict:
        return attrs.asdict(self)

    def cell(self, key: str) -> str:
        """The short form of ``key`` (a SHORT key), else its long field, else ""."""
        return self.short.get(key) or getattr(self, SHORT[key]) or ""


def group_of(dataset) -> str:
    """The group a dataset belongs to: its declared ``group`` (TOML key), else its own name. Nothing is
    inferred from names: datasets are pooled only where their files say they belong together."""
    return getattr(dataset, "group", "") or dataset.name


def unfitted(answers) -> list[tuple[str, list[str], list[str]]]:
    """The groups without a fitted law, folded by reason: (reason, groups, the registered laws that would
    apply as their rows' headlines name them, e.g. 'rate-state-aging, rate-state-slip (--laws ...)')."""
    folded: dict[str, tuple[list, dict]] = {}
    for a in answers:
        if a.best is None:
            groups, hints = folded.setdefault(a.cell("best") or "no law could be fitted", ([], {}))
            groups.append(a.group)
            hint = a.headline.partition("registered laws that apply: ")[2]
            if hint:
                hints[hint] = None
    return [(reason, groups, list(hints)) for reason, (groups, hints) in folded.items()]
