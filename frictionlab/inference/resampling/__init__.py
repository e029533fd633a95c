"""Parametric replicates: the bootstrap of parameters and of the ranking."""
