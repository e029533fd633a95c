"""Noise models of measured records: AR(p) / ARMA(1,1) chosen by the data (``arp``), per rate group (``record``)."""
