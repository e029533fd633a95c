"""Output folders (a report, a bench report, a sweep): built in a temporary folder beside the target and moved
into place whole at the end, under the target's lock (``files.output_lock``), or not at all.

``force`` replaces only a folder that holds the marker file ``MARKER`` (every folder written here gets one) or an
empty one; anything else, a regular file included, is refused. The marker lists the files frictionlab wrote there
(its manifest). A rewrite with ``force`` replaces those and keeps every other file, folder and link of the old
folder (what the user added: notes, their own figures) at its place in the new one, as a hard link made before
the new folder is moved in (so that no exit between the two moves loses it; ``files.clear_dead`` puts an old
folder back if a run dies between them); a file the user added where the new output writes one is refused, naming
it, before anything moves. A folder marked by a frictionlab that wrote no manifest keeps every file the new output
does not write.
"""
from __future__ import annotations

import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

from .errors import OutputError
from .files import _leftovers, _oserror, _remove, _tag, _umask, output_lock
from .inputs import check_apart

#: File that marks a folder written by frictionlab (a report, a bench report, rebuilt datasets).
MARKER = ".frictionlab-output"
#: The line of MARKER after which the files frictionlab wrote follow, one a line.
MANIFEST_HEAD = ("# The files frictionlab wrote in this folder, one a line; a rewrite with --force replaces them "
                 "and keeps every other file.")


def _replaceable(path: Path) -> bool:
    """True if ``force`` may replace ``path``: a folder with frictionlab's marker, or an empty one."""
    return path.is_dir() and not path.is_symlink() and ((path / MARKER).is_file() or not any(path.iterdir()))


def check_target(path, force: bool = False) -> Path:
    """Raise OutputError unless an output folder may be created (or, with ``force``, replaced) at ``path``."""
    path = Path(path)
    check_apart(path)
    if os.path.lexists(path):
        if not force:
            raise OutputError(f"{path}: output folder exists; choose another --out or pass --force")
        if not _replaceable(path):
            what = "a folder frictionlab did not write" if path.is_dir() and not path.is_symlink() else \
                "not a folder" if not path.is_symlink() else "a symbolic link"
            raise OutputError(f"{path}: --force replaces only a folder written by frictionlab (it holds {MARKER}) "
                              f"or an empty one; this is {what}: remove it yourself or choose another --out")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.exists():
        raise OutputError(f"{path}: parent folder {parent} does not exist")
    if not parent.is_dir():
        raise OutputError(f"{path}: cannot write: {parent} is not a directory")
    return path


def entries(folder: Path) -> list[str]:
    """The relative paths ('a/b.png') of everything below ``folder`` that is not a folder (files, links, special
    files; links never followed), and of its empty folders, sorted."""
    out = []
    for root, dirs, files in os.walk(folder):
        rel = os.path.relpath(root, folder)
        names = files + [d for d in dirs if os.path.islink(os.path.join(root, d))]
        out += [n if rel == "." else f"{rel}/{n}".replace(os.sep, "/") for n in names]
        if rel != "." and not dirs and not files:
            out.append(rel.replace(os.sep, "/") + "/")
    return sorted(out)


def manifest(folder: Path) -> set[str] | None:
    """The files frictionlab wrote in ``folder`` by its marker, or None where the marker lists none (an empty
    folder, or a folder written by a frictionlab that kept no manifest)."""
    try:
        lines = (folder / MARKER).read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return None
    return set(lines[lines.index(MANIFEST_HEAD) + 1:]) if MANIFEST_HEAD in lines else None


def users_entries(old: Path, new: Path) -> list[str]:
    """What the old folder ``old`` holds that frictionlab did not write there: not in its manifest (without one:
    not written anew in ``new`` either), never the marker."""
    if not old.is_dir() or old.is_symlink():
        return []
    written = manifest(old)
    fresh = set(entries(new))
    return [e for e in entries(old) if e != MARKER and e not in (written if written is not None else fresh)]


def carry(old: Path, new: Path, kept: list[str], target: Path) -> None:
    """Give ``new`` each of the user's entries ``kept`` of ``old`` at the same place (a hard link, or a copy where
    the file system makes none; an empty folder made); refuse, naming them, entries where ``new`` has its own."""
    clash = [e for e in kept if os.path.lexists(new / e.rstrip("/")) and not e.endswith("/")]
    if clash:
        shown = ", ".join(clash[:5]) + (f" and {len(clash) - 5} more" if len(clash) > 5 else "")
        raise OutputError(f"{target}: --force would replace files frictionlab did not write there: {shown}; move them "
                          "out of the folder, or choose another --out")
    for e in kept:
        src, dst = old / e.rstrip("/"), new / e.rstrip("/")
        if e.endswith("/"):
            dst.mkdir(parents=True, exist_ok=True)
            continue
        dst.parent.mkdir(parents=True, exist_ok=True)
        try:
            os.link(src, dst, follow_symlinks=False)
        except OSError:  # a file system without hard links: a copy (a link as a link)
            if os.path.islink(src):
                os.symlink(os.readlink(src), dst)
            else:
                shutil.copy2(src, dst)


def _written(folder: Path, marker: str) -> str:
    """The marker's text: ``marker``, then the manifest of every file in ``folder`` (the output just built)."""
    return marker.rstrip("\n") + "\n" + MANIFEST_HEAD + "\n" + "".join(f"{e}\n" for e in entries(folder) if e != MARKER)


@contextmanager
def atomic_dir(path, force: bool = False, marker: str = "frictionlab output\n"):
    """Yield a temporary folder beside ``path``; move it into place only if the block succeeds.

    An existing ``path`` is refused unless ``force`` and it is a frictionlab output folder (it holds
    MARKER) or empty; it is then replaced at the end, what the user added to it kept (the module). The folder gets
    a MARKER file holding ``marker`` and the manifest, and permissions from the umask. The target is locked
    throughout (output_lock).
    """
    path = Path(path)
    with output_lock(path):
        check_target(path, force)
        parent = path.parent if str(path.parent) else Path(".")
        try:
            tmp = Path(tempfile.mkdtemp(dir=parent, prefix=_tag(path), suffix=".tmp"))
        except OSError as exc:
            raise _oserror(path, exc) from None
        _leftovers.add(str(tmp))
        try:
            try:
                os.chmod(tmp, 0o777 & ~_umask())
                yield tmp
                (tmp / MARKER).write_text(_written(tmp, marker), encoding="utf-8")
                _fix_modes(tmp)  # before the user's files join: their modes stay theirs
            except OSError as exc:
                raise _oserror(path, exc) from None
            check_target(path, force)  # again: something may have appeared during the work
            try:
                kept = users_entries(path, tmp)
                carry(path, tmp, kept, path)
            except OSError as exc:
                raise _oserror(path, exc, "cannot keep the files added to it") from None
            _swap(path, tmp, parent, kept)
        finally:
            _remove(str(tmp))


def _swap(path: Path, tmp: Path, parent: Path, kept: list[str]) -> None:
    """Move ``tmp`` into place at ``path``, the old folder aside and then removed; what the user put in the old
    folder meanwhile (not in ``kept``, not frictionlab's) is moved over, or the old folder kept beside if it cannot."""
    old = None
    try:
        if os.path.lexists(path):
            old = Path(tempfile.mkdtemp(dir=parent, prefix=_tag(path), suffix=".old"))
            _leftovers.add(str(old))
            os.replace(path, old / "x")
        os.replace(tmp, path)
    except OSError as exc:
        if old is not None and (old / "x").exists() and not os.path.lexists(path):
            os.replace(old / "x", path)  # put the old one back
        raise _oserror(path, exc) from None
    finally:
        if old is not None and not os.path.lexists(path) and (old / "x").exists():
            os.replace(old / "x", path)  # an exit between the two moves: the old folder back
    if old is None:
        return
    late = [e for e in users_entries(old / "x", path) if e not in kept and not e.endswith("/")]
    try:
        for e in late:  # added while the new folder was being moved in
            (path / e).parent.mkdir(parents=True, exist_ok=True)
            if not os.path.lexists(path / e):
                os.replace(old / "x" / e, path / e)
    except OSError:
        pass
    stuck = [e for e in late if os.path.lexists(old / "x" / e)]
    if stuck:  # kept beside, in sight, rather than lost
        import warnings

        beside = parent / f"{path.name}.kept-{os.getpid()}"
        os.replace(old / "x", beside)
        warnings.warn(f"{path}: files added to it while it was rewritten ({', '.join(stuck[:3])}) are kept in {beside}")
    _remove(str(old))


def _fix_modes(folder: Path) -> None:
    """Give files and folders below ``folder`` the permissions the umask allows (0666 / 0777 & ~umask),
    whatever created them (tempfile makes them private)."""
    mask = _umask()
    for root, dirs, files in os.walk(folder):
        for d in dirs:
            os.chmod(os.path.join(root, d), 0o777 & ~mask)
        for f in files:
            p = os.path.join(root, f)
            if not os.path.islink(p):
                os.chmod(p, (0o777 if os.stat(p).st_mode & 0o111 else 0o666) & ~mask)
