"""The noise of a series: correlated noise models estimated with the fit and the likelihoods they give."""
