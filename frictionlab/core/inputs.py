"""What a command reads, so that its outputs keep clear of it.

While a command runs (``inputs_of_run``), every file read through ``core.files`` and every file named
by ``note_input`` (a ``--load`` plugin) is recorded by its real path; ``check_apart`` refuses an output
that is (by path, or as a hard link of it), contains or lies inside one of them. ``core.files`` checks every output path with it before
writing (``check_writable``, ``outfolder.check_target``), so ``--force`` never removes what the run reads.
"""
from __future__ import annotations

import os
from contextlib import contextmanager

from .errors import OutputError

_runs: list[set[str]] = []  # while a command runs (inputs_of_run), the real paths of the files it read


@contextmanager
def inputs_of_run():
    """Collect, for the block (one command), the real path of every file read through core.files or
    named by ``note_input``; outputs checked in the block (``check_apart``) must keep clear of them."""
    _runs.append(set())
    try:
        yield _runs[-1]
    finally:
        _runs.pop()


def note_input(path) -> None:
    """Record ``path`` as read by the running command (a plugin file, a dataset)."""
    if _runs:
        _runs[-1].add(os.path.realpath(path))


def _stat(path: str):
    try:
        return os.stat(path)
    except (OSError, ValueError):
        return None


def check_apart(path, inputs=()) -> None:
    """Raise OutputError if the output ``path`` (real path) is, contains or lies inside a file the running
    command reads (see inputs_of_run) or one of ``inputs``: a run never writes over, into or instead of
    what it reads, and ``--force`` never removes it."""
    real = os.path.realpath(path)
    read = set(_runs[-1] if _runs else ()) | {os.path.realpath(p) for p in inputs}
    mine = _stat(real)
    for inp in sorted(read):
        how = ("is" if inp == real else "contains" if inp.startswith(real.rstrip(os.sep) + os.sep)
               else "lies inside" if real.startswith(inp + os.sep) else "")
        if not how and mine is not None and (theirs := _stat(inp)) is not None and os.path.samestat(mine, theirs):
            how = "is (a hard link of)"
        if how:
            raise OutputError(f"{path}: this output {how} {inp}, which the run reads; choose another output path")
