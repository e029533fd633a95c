"""Where a dataset's numbers come from: the ``[provenance]`` table (measured, reported, reconstructed, synthetic)."""
from __future__ import annotations

import attrs

from ..core.errors import DatasetError

PROVENANCE_KINDS = ("measured", "reported", "reconstructed", "synthetic")
#: What a provenance source names when its numbers come from the project's seed paper (Arakawa, "An analytical
#: model of dynamic sliding friction during impact", Sci. Rep. 7, 2017): every part must appear.
SEED_PAPER = ("Arakawa", "Sci. Rep.", "2017")


@attrs.frozen
class Provenance:
    kind: str  # measured | reported | reconstructed | synthetic
    source: str
    method: str = ""
    command: str = ""
    seed: int | None = None
    truth: dict = attrs.field(factory=dict)  # generating law and parameters, for synthetic data
    license: str = ""  # the data's license as the source states it (e.g. "MIT")
    citation: str = ""  # what to cite when using the data

    @property
    def seed_paper(self) -> bool:
        """Whether these numbers come from the seed paper (its source cites it, SEED_PAPER) and are not made up:
        only then may a report speak of 'the paper' about them. Decided by the declared source, not the name."""
        return self.kind != "synthetic" and all(part in self.source for part in SEED_PAPER)


def _provenance(p, path) -> Provenance:
    if not isinstance(p, dict):
        raise DatasetError(f"{path}: missing required table [provenance] (kind = {' | '.join(PROVENANCE_KINDS)})")
    extra = set(p) - {"kind", "source", "method", "command", "seed", "truth", "license", "citation"}
    if extra:
        raise DatasetError(f"{path}: [provenance] has unknown key(s) {sorted(extra)}; "
                           "known: kind, source, method, command, seed, truth, license, citation")
    kind = p.get("kind")
    if kind not in PROVENANCE_KINDS:
        raise DatasetError(f"{path}: provenance.kind = {kind!r}, expected one of {', '.join(PROVENANCE_KINDS)}")
    if not isinstance(p.get("source"), str) or not p["source"]:
        raise DatasetError(f"{path}: provenance.source must name where the data come from")
    if kind in ("reconstructed", "synthetic") and not p.get("command"):
        raise DatasetError(f"{path}: provenance.command must give the command that regenerates {kind} data")
    for key in ("method", "command", "license", "citation"):
        if not isinstance(p.get(key, ""), str):
            raise DatasetError(f"{path}: provenance.{key} must be a string")
    seed = p.get("seed")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int)):
        raise DatasetError(f"{path}: provenance.seed must be an integer, got {seed!r}")
    if not isinstance(p.get("truth", {}), dict):
        raise DatasetError(f"{path}: provenance.truth must be a table")
    return Provenance(kind=kind, source=p["source"], method=p.get("method", ""), command=p.get("command", ""),
                      seed=p.get("seed"), truth=p.get("truth", {}), license=p.get("license", ""),
                      citation=p.get("citation", ""))
