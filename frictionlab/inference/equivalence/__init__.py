"""Can the data tell two laws apart: the discrimination test of a pair, equivalence within a margin, the Holm
family of a report, shared qualitative features, the paper's decomposition, and one parameter set across
conditions (transfer)."""
