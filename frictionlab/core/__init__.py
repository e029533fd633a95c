"""Ground floor, imported by every layer above: errors, units at the edges, safe files, display units,
terminal tables, progress and the process pool. Imports nothing else of frictionlab."""

__version__ = "0.1.0"  # the package version; ``frictionlab.__version__`` re-exports it
