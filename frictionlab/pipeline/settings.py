"""What a comparison is asked to do: the laws, solvers and stage switches of ``compare``, checked once."""
from __future__ import annotations

from collections.abc import Sequence

import attrs
import numpy as np

from ..core.arguments import as_items
from ..core.errors import ParameterError
from ..inference.equivalence.discrimination import MIN_REPLICATES, PAIRS, REPLICATES
from ..inference.equivalence.margin import MARGIN
from ..physics.registry import available_laws, get_law

#: The laws ``compare`` fits by default on impacts and inclines: the four of the mission (the seed paper's
#: question). Other registered laws (stribeck, lugre, dahl, installed plugins) join when named or with "all".
DEFAULT_LAWS = ("coulomb", "area-rate", "wear", "couette")
#: Dataset kinds whose default laws are others: rate-and-state friction on velocity steps of a spring-slider, the
#: one-state laws the velocity-step fit serves (aging, slip, PRZ, and Nagata's with its c fitted with a, b, Dc).
#: The two-state laws join when named: the velocity-step fit does not serve their b2, Dc2, and a law fitted
#: through another model (no trend, stiffness or data-chosen noise) would be ranked against a different likelihood.
DEFAULT_LAWS_BY_KIND = {"spring-slider": ("rate-state-aging", "rate-state-slip", "rate-state-prz", "rate-state-nagata")}


def select_laws(laws: Sequence[str] | None) -> tuple[str, ...]:
    """Law names to compare: None -> DEFAULT_LAWS; "all" (alone or in the list) -> every registered law."""
    names = DEFAULT_LAWS if laws is None else tuple(as_items(laws, "compare: laws"))
    if "all" in names:
        names = tuple(available_laws()) + tuple(n for n in names if n != "all")
    return tuple(dict.fromkeys(get_law(n).name for n in names))


def check_pairs(items, groups, where: str = "compare: pairs", laws_option: str = "laws") -> tuple[tuple[str, str], ...]:
    """The pairs of laws whose equivalence is tested, from ``items``: 'LAW:LAW' strings or (law, law) pairs (one
    string is one pair). Each names two different registered laws compared together (both in one of ``groups``,
    sets of law names fitted on the same datasets); a pair named twice, in either order, is tested once (the first
    order kept: law A's series is tested on the first pair), so that it counts once in the family of hypotheses.
    A ParameterError (a TypeError for an item that is neither) names ``where`` and the pair."""
    from ..core.errors import FrictionLabError

    out: dict[frozenset, tuple[str, str]] = {}
    for item in as_items(items, where):
        if isinstance(item, str):
            a, sep, b = item.partition(":")
            if not sep or not a.strip() or not b.strip() or ":" in b:
                raise ParameterError(f"{where} {item!r}: expected LAW:LAW, e.g. wear:area-rate")
        elif isinstance(item, (tuple, list)) and len(item) == 2 and all(isinstance(x, str) for x in item):
            a, b = item
        else:
            raise TypeError(f"{where}: expected pairs of law names, ('wear', 'area-rate') or 'wear:area-rate', got "
                            f"{type(item).__name__} {item!r:.60}")
        try:
            a, b = get_law(a.strip()).name, get_law(b.strip()).name
        except FrictionLabError as exc:
            raise ParameterError(f"{where} {item!r}: {exc}") from None
        if a == b:
            raise ParameterError(f"{where} {item!r}: a law is always equivalent to itself; name two different laws")
        if not any({a, b} <= set(g) for g in groups):
            compared = next((set(g) for g in groups if b in g or a in g), set(groups[0]) if groups else set())
            missing = [x for x in (a, b) if x not in compared]
            raise ParameterError(f"{where} {item!r}: {', '.join(missing)} {'is' if len(missing) == 1 else 'are'} not "
                                 f"among the compared laws ({', '.join(sorted(compared))}); add "
                                 f"{'it' if len(missing) == 1 else 'them'} to {laws_option}")
        out.setdefault(frozenset((a, b)), (a, b))
    return tuple(out.values())


def laws_groups(by_kind: dict, kinds) -> list[tuple[tuple[str, ...], list[str]]]:
    """(laws, the dataset kinds they were fitted on) for the kinds present, from a kind -> laws mapping."""
    groups: dict[tuple, list[str]] = {}
    for kind, laws in by_kind.items():
        if kind in set(kinds):
            groups.setdefault(tuple(laws), []).append(kind)
    return list(groups.items())


def default_laws_by_kind(kinds) -> dict[str, tuple[str, ...]]:
    """The default laws of each dataset kind in ``kinds`` (DEFAULT_LAWS_BY_KIND, else DEFAULT_LAWS)."""
    return {k: tuple(get_law(n).name for n in DEFAULT_LAWS_BY_KIND.get(k, DEFAULT_LAWS)) for k in dict.fromkeys(kinds)}


@attrs.frozen
class Settings:
    """The options of one comparison (see ``compare``), validated when made: SI, seconds, counts."""

    laws: tuple[str, ...]
    solvers: tuple[str, ...] | None = None
    free: dict = attrs.field(factory=dict)  # scene quantity -> (lower, upper) in SI
    equivalence: bool = True
    jobs: int = 1
    bootstrap: int = 0
    seed: int = 0
    bootstrap_all: bool = False
    tolerance: tuple[float, ...] = ()
    fit_timeout: float | None = None
    replicates: int = REPLICATES
    pairs: tuple = PAIRS
    transfer: bool = True
    margin: object = MARGIN  # the equivalence margin delta: a multiple of the noise or a quantity (inference.equivalence.margin)
    family: str = "report"  # the family a report's test p-values are adjusted in (equivalence_groups.FAMILIES)
    accuracy: bool = True  # what accuracy costs per law and dataset (inference.cost.accuracy; in full with tolerance)
    cluster: str = ""  # where the tasks ran when not on a local pool: "Dask cluster at ADDRESS (N workers)"
    by_kind: dict = attrs.field(factory=dict)  # dataset kind -> the laws fitted on it ({}: every law on every dataset)

    def __attrs_post_init__(self):
        from ..solve.solvers import parse_solver

        for s in self.solvers or ():
            if s != "auto":
                parse_solver(s)  # an unknown solver is an input error, before any work
        for name in ("bootstrap", "seed", "replicates"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 0:
                raise ParameterError(f"compare: {name} must be a non-negative integer, got {v!r}")
        if isinstance(self.jobs, bool) or not isinstance(self.jobs, (int, np.integer)) or self.jobs < 1:
            raise ParameterError(f"compare: jobs must be a whole number of worker processes, at least 1, got {self.jobs!r}")
        t = self.fit_timeout
        if t is not None and (isinstance(t, bool) or not isinstance(t, (int, float)) or not 0 < t < float("inf")):
            raise ParameterError(f"compare: fit_timeout must be a positive number of seconds, got {t!r}")
        from ..inference.equivalence.family import FAMILIES
        from ..inference.equivalence.margin import parse_margin

        object.__setattr__(self, "margin", parse_margin(self.margin, "compare: margin"))
        if self.family not in FAMILIES:
            raise ParameterError(f"compare: family must be one of {', '.join(FAMILIES)}, got {self.family!r}")
        for r in self.tolerance:
            if isinstance(r, bool) or not isinstance(r, (int, float)) or not 0 < r < 1:
                raise ParameterError(f"compare: every tolerance must be a number in (0, 1), got {r!r}")

    def check_replicates(self) -> None:
        if self.equivalence and self.replicates < MIN_REPLICATES:
            raise ParameterError(f"compare: replicates must be at least {MIN_REPLICATES}, got {self.replicates}")

    def fit_options(self) -> dict:
        """Options every refit of a stage shares: the freed scene quantities and the time budget."""
        return ({"free": dict(self.free)} if self.free else {}) | (
            {"timeout": self.fit_timeout} if self.fit_timeout else {})

    def as_dict(self) -> dict:
        """The settings as results.json records them."""
        return {"solvers": list(self.solvers) if self.solvers else "default", "jobs": self.jobs,
                "equivalence": self.equivalence, "free": {k: list(v) for k, v in self.free.items()},
                "bootstrap": int(self.bootstrap), "seed": int(self.seed), "bootstrap_all": bool(self.bootstrap_all),
                "tolerance": [float(r) for r in self.tolerance], "fit_timeout": self.fit_timeout,
                "replicates": int(self.replicates), "pairs": [list(p) for p in self.pairs],
                "transfer": bool(self.transfer), "margin": self.margin.as_text(), "family": self.family,
                "accuracy": bool(self.accuracy)} | ({"cluster": self.cluster} if self.cluster else {}) | (
                {"laws_by_kind": {k: list(v) for k, v in self.by_kind.items()}} if self.by_kind else {})
