"""Fitting a law to a dataset: targets and predictions, the lmfit model with scaled parameters, starts and
refits, the result with its statistics, progress and time budgets, tidy frames and notebook plots."""
