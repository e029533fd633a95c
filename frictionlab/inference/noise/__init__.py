"""The noise of a series: correlated noise models estimated with the fit and the likelihoods they give (AR(1):
``ar1``; AR(p) / ARMA(1,1) chosen by the data: ``arp``, per rate group: ``record``; the law-fit test of bands after
a step: ``misfit``)."""
