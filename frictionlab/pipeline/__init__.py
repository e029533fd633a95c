"""The jobs: ``compare`` (fit, rank, equivalence, transfer, bootstrap, tolerance, answer, as named
stages over one ``Comparison``) and ``bench`` (work-precision). Above inference, below report."""
