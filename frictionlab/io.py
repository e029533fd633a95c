"""Writing outputs whole or not at all."""
from __future__ import annotations

import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

from .errors import OutputError


def check_writable(path) -> Path:
    """Raise OutputError unless a file can be written at ``path`` (its folder exists and is a folder)."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.exists():
        raise OutputError(f"{path}: folder {parent} does not exist")
    if not parent.is_dir():
        raise OutputError(f"{path}: cannot write: {parent} is not a directory")
    if path.is_dir():
        raise OutputError(f"{path}: cannot write: it is a folder")
    return path


def _umask_mode(mode: int) -> int:
    """``mode`` as the process umask leaves it (what open() would give a new file or folder)."""
    umask = os.umask(0)
    os.umask(umask)
    return mode & ~umask


def atomic_write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder, then rename."""
    path = check_writable(path)
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, _umask_mode(0o666))  # mkstemp makes it private; the output is the user's as any file
        os.replace(tmp, path)
    except OSError as exc:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)
        raise OutputError(f"{path}: cannot write: {exc.strerror or exc}") from None


def atomic_write_text(path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` through a temporary file in the same folder, then rename."""
    atomic_write_bytes(path, text.encode("utf-8"))


@contextmanager
def atomic_dir(path, force: bool = False):
    """Yield a temporary folder beside ``path``; move it into place only if the block succeeds.

    An existing ``path`` is refused unless ``force``, in which case it is replaced at the end.
    """
    path = Path(path)
    if path.exists() and not force:
        raise OutputError(f"{path}: output folder exists; choose another --out or pass --force")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.exists():
        raise OutputError(f"{path}: parent folder {parent} does not exist")
    try:
        tmp = Path(tempfile.mkdtemp(dir=parent, prefix=f".{path.name}.", suffix=".tmp"))
        tmp.chmod(_umask_mode(0o777))  # mkdtemp makes it private; the folder is the user's as any folder
    except OSError as exc:
        raise OutputError(f"{path}: cannot write in {parent}: {exc.strerror or exc}") from None
    try:
        yield tmp
        if path.exists():
            old = parent / f".{path.name}.old"
            shutil.rmtree(old, ignore_errors=True)
            os.replace(path, old)
            os.replace(tmp, path)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, path)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
