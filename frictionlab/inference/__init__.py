"""Inference: what a law predicts for a dataset, fitting with lmfit, goodness of fit, plausibility,
identifiability, ranking, the equivalence and transfer tests, the bootstrap, what tolerance costs, and
the verdicts of the first screen. Imports the layers below it, never ``pipeline`` or ``report``."""
