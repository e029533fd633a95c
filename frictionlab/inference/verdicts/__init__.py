"""How the laws rank and what the first screen says: the ranking by information criteria, the rules the report
quotes, and the verdict rows of each group of datasets."""
