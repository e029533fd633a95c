"""Whether one fit can be trusted: goodness of fit (the law against the noise), plausibility of the fitted
values, and identifiability (parameters at bounds, correlated or without effect)."""
