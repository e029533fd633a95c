"""Files in and out: inputs read only from regular files of bounded size, outputs written whole or
not at all, under a lock, with the permissions the umask gives.

Rules (stated once):

* An input file is read only if it is a regular file (a FIFO, device or socket is refused before
  it is opened, so nothing blocks) no larger than its limit (``MAX_TOML_BYTES``,
  ``MAX_CSV_BYTES``). A file found beside another (a dataset's CSV beside its TOML) must lie,
  once symbolic links are resolved, inside the folder of the file that names it: a link within
  that folder is followed, a link out of it is refused.
* TOML may start with a UTF-8 byte-order mark (it is dropped); brackets, braces and dotted keys
  nest at most ``MAX_TOML_DEPTH`` deep.
* Every output is written under a lock (``.NAME.lock`` beside the target, removed afterwards) that keeps a
  second frictionlab run away from the same target: that run fails at once, naming the target. An output
  folder is built beside its target and moved into place whole (``outfolder.atomic_dir``).
* Several files written by one command (a dataset's TOML and CSV, a simulation and its plot) are a set
  (``atomic_files``, ``write_files``): written into a temporary folder beside their targets and moved into place
  together at the end, or, on any failure, none of them (a target replaced with ``force`` is put back).
* Every temporary file and folder, and every lock, carries its owner: the name of a temporary holds the
  owner's process id and start time (``.NAME.PID-START.XXXX.tmp``), a lock file holds them as text. A run that
  takes a lock removes what dead owners left beside that target (a run killed with SIGKILL), except an old
  output folder moved aside while its target is missing (a run killed between moving the old folder out and the
  new one in), which is put back; a lock whose owner is dead is taken over even when a process the owner forked
  still holds its flock.
* Every error names the path it concerns, "No space left on device" included.
"""
from __future__ import annotations

import errno
import os
import re
import shutil
import stat
import tempfile
import threading
from contextlib import ExitStack, contextmanager
from pathlib import Path

from .errors import DatasetError, OutputError
from .inputs import check_apart, note_input

MAX_TOML_BYTES = 1 << 20  # 1 MiB: a dataset's sidecar is a few kB
MAX_CSV_BYTES = 256 << 20  # 256 MiB
MAX_TOML_DEPTH = 16


# --- reading --------------------------------------------------------------------------------
def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"), (stat.S_ISDIR, "a folder")):
        if test(mode):
            return name
    return "not a regular file"


def read_bytes(path, limit: int, within=None, error=DatasetError) -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them; ``within``: a folder the
    file's real path must lie in. Raises ``error`` with a one-line message naming the path."""
    path = Path(path)
    note_input(path)
    if within is not None:
        real, base = os.path.realpath(path), os.path.realpath(within)
        if os.path.commonpath([real, base]) != base:
            raise error(f"{path}: is a symbolic link to {real}, outside the dataset's folder {base}; "
                        "links are followed only within that folder (copy the file there)")
    try:
        st = os.stat(path)
        if not stat.S_ISREG(st.st_mode):  # refused before opening: opening a FIFO could block
            raise error(f"{path}: is {_kind(st.st_mode)}, not a regular file")
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise error(f"{path}: no such file") from None
    except OSError as exc:
        raise error(f"{path}: cannot read: {exc.strerror or exc}") from None
    try:
        st = os.fstat(fd)  # the file opened may not be the one checked (a swap in between)
        if not stat.S_ISREG(st.st_mode):
            raise error(f"{path}: is {_kind(st.st_mode)}, not a regular file")
        if st.st_size > limit:
            raise error(f"{path}: is {st.st_size} bytes, more than the limit of {limit} bytes")
        chunks, size = [], 0
        while True:
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                break
            size += len(chunk)
            if size > limit:
                raise error(f"{path}: is more than the limit of {limit} bytes")
            chunks.append(chunk)
        return b"".join(chunks)
    except OSError as exc:
        raise error(f"{path}: cannot read: {exc.strerror or exc}") from None
    finally:
        os.close(fd)


def read_text(path, limit: int, within=None, error=DatasetError) -> str:
    """A UTF-8 text file (a leading byte-order mark is dropped), read as ``read_bytes`` does."""
    data = read_bytes(path, limit, within, error)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise error(f"{path}: cannot read: not UTF-8 text (byte {exc.start + 1})") from None


def toml_depth(text: str) -> int:
    """Deepest nesting of a TOML text: brackets and braces, and dots in a key, outside strings and
    comments (a cheap scan, so that a pathological file is refused before it is parsed)."""
    depth = deepest = dots = 0
    i, n = 0, len(text)
    while i < n:
        ch = text[i]
        if ch in "\"'":
            quote = text[i:i + 3] if text[i:i + 3] in ('"""', "'''") else ch
            i += len(quote)
            while i < n and not text.startswith(quote, i):
                i += 2 if (quote[0] == '"' and text[i] == "\\") else 1
            i += len(quote)
            continue
        if ch == "#":
            while i < n and text[i] != "\n":
                i += 1
            continue
        if ch in "[{":
            depth += 1
            dots = 0
        elif ch in "]}":
            depth -= 1
        elif ch in "=,\n":
            dots = 0
        elif ch == ".":
            dots += 1
        deepest = max(deepest, depth + dots)
        i += 1
    return deepest


def read_toml(path, error=DatasetError) -> dict:
    """A TOML file as a dict, read as ``read_text`` does, with one-line errors naming the path."""
    import tomllib

    text = read_text(path, MAX_TOML_BYTES, error=error)
    if toml_depth(text) > MAX_TOML_DEPTH:
        raise error(f"{path}: TOML nests deeper than {MAX_TOML_DEPTH} levels (tables, arrays or dotted keys)")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path}: TOML does not parse: {exc}") from None
    except RecursionError:
        raise error(f"{path}: TOML nests too deeply to parse") from None


# --- writing --------------------------------------------------------------------------------
def _umask() -> int:
    with _umask_lock:
        mask = os.umask(0o022)
        os.umask(mask)
    return mask


_umask_lock = threading.Lock()


def _oserror(path, exc: OSError, doing: str = "cannot write") -> OutputError:
    """An OutputError naming ``path`` (and the file concerned, if another) for an OSError."""
    other = f" ({exc.filename})" if getattr(exc, "filename", None) and str(exc.filename) != str(path) else ""
    return OutputError(f"{path}: {doing}{other}: {exc.strerror or exc}")


def check_writable(path) -> Path:
    """Raise OutputError unless a file can be written at ``path`` (its folder exists and is a folder)."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    check_apart(path)
    if not parent.exists():
        raise OutputError(f"{path}: folder {parent} does not exist")
    if not parent.is_dir():
        raise OutputError(f"{path}: cannot write: {parent} is not a directory")
    if path.is_dir():
        raise OutputError(f"{path}: cannot write: it is a folder")
    if path.exists() and not path.is_file():
        raise OutputError(f"{path}: cannot write: it is {_kind(os.stat(path).st_mode)}")
    return path


# --- owners --------------------------------------------------------------------------------
def _start_time(pid: int) -> int:
    """When process ``pid`` started, in clock ticks since boot (Linux /proc), or 0 where it cannot be read."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            return int(f.read().rsplit(b")", 1)[1].split()[19])  # field 22: after the name, which may hold ')'
    except (OSError, ValueError, IndexError):
        return 0


def owner() -> str:
    """'PID-START' of this process: what it writes into its lock files and the names of its temporaries."""
    pid = os.getpid()
    return f"{pid}-{_start_time(pid)}"


def _alive(pid: int, start: int) -> bool:
    """True if process ``pid`` exists and, where start times can be read, is the one that started at ``start``
    (not another process given the same id since)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    now = _start_time(pid)
    return not (start and now and now != start)


def _tag(path: Path) -> str:
    """The prefix of a temporary of this process beside ``path``: '.NAME.PID-START.'"""
    return f".{path.name}.{owner()}."


def clear_dead(path) -> None:
    """Remove what runs that died (pid gone, or reused by another process) left beside the target ``path``:
    their temporary files and folders ``.NAME.PID-START.XXXX.tmp`` and ``.old``. Links are removed, never followed."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    pattern = re.compile(rf"\.{re.escape(path.name)}\.(\d+)-(\d+)\.[^.]+\.(tmp|old)")
    try:
        names = os.listdir(parent)
    except OSError:
        return
    for name in names:
        m = pattern.fullmatch(name)
        if m and not _alive(int(m[1]), int(m[2])):
            _put_back(os.path.join(parent, name), path)
            _remove(os.path.join(parent, name))


def _put_back(aside: str, target) -> None:
    """An old output folder moved aside (``ASIDE/x``) put back at ``target`` if nothing is there."""
    if aside.endswith(".old") and os.path.isdir(os.path.join(aside, "x")) and not os.path.lexists(target):
        try:
            os.replace(os.path.join(aside, "x"), target)
        except OSError:
            pass


_leftovers: set[str] = set()  # temporary files and folders, and locks, of this process not yet removed


def _remove(path: str) -> None:
    if os.path.isdir(path) and not os.path.islink(path):
        shutil.rmtree(path, ignore_errors=True)
    else:
        try:
            os.unlink(path)
        except OSError:
            pass
    _leftovers.discard(path)


def remove_leftovers() -> None:
    """Remove every temporary file, folder and lock this process made and has not removed yet (for an
    exit that cannot run the normal clean-up: a plugin that swallowed SIGTERM)."""
    for path in list(_leftovers):
        if path.endswith(".old"):  # '.NAME.PID-START.XXXX.old' beside the target NAME
            _put_back(path, os.path.join(os.path.dirname(path), os.path.basename(path)[1:].split(f".{owner()}.")[0]))
        _remove(path)


def atomic_write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder, then rename."""
    path = check_writable(path)
    clear_dead(path)
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=_tag(path), suffix=".tmp")
        _leftovers.add(tmp)
        os.fchmod(fd, 0o666 & ~_umask())
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
        _leftovers.discard(tmp)
    except OSError as exc:
        raise _oserror(path, exc) from None
    finally:  # on any exit, ^C and SIGTERM included
        if tmp is not None and tmp in _leftovers:
            _remove(tmp)


def atomic_write_text(path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` through a temporary file in the same folder, then rename."""
    atomic_write_bytes(path, text.encode("utf-8"))


_held: dict[str, int] = {}  # lock file -> times held by this process


@contextmanager
def output_lock(path):
    """Hold an exclusive lock on the output ``path`` (a file ``.NAME.lock`` beside it, removed on
    release). A second holder, in this process or another, fails at once with an OutputError."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    lock = parent / f".{path.name}.lock"
    key = os.path.abspath(lock)
    if key in _held:  # already ours (compare holds it, then write_report asks again)
        _held[key] += 1
        try:
            yield
        finally:
            _held[key] -= 1
        return
    busy = OutputError(f"{path}: another frictionlab run is writing this output (lock {lock}); "
                       "wait for it to finish or choose another --out")
    fd = _take_lock(lock, path, parent, busy)
    _held[key] = 1
    _leftovers.add(str(lock))
    try:
        yield
    finally:
        del _held[key]
        _remove(str(lock))
        os.close(fd)


_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)


def _take_lock(lock: Path, path: Path, parent: Path, busy: OutputError) -> int:
    """A descriptor of the lock file ``lock``, created with O_EXCL|O_NOFOLLOW (a planted link is never
    followed) and flock-ed. A lock file left by a run that died is taken over (nobody holds its flock);
    one held is ``busy``; a symbolic link or anything but a regular file there is refused."""
    import fcntl

    planted = OutputError(f"{path}: the lock file {lock} is a symbolic link or not a regular file (not made by "
                          "frictionlab); remove it and run again")
    for _ in range(100):
        try:
            try:
                fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_EXCL | _NOFOLLOW, 0o666 & ~_umask())
            except FileExistsError:  # another run's, or one left behind: held if its flock is
                fd = os.open(lock, os.O_RDWR | _NOFOLLOW | getattr(os, "O_NONBLOCK", 0))
        except FileNotFoundError:
            if not parent.is_dir():
                raise OutputError(f"{path}: parent folder {parent} does not exist") from None
            continue  # released between the two opens: create it again
        except OSError as exc:
            if exc.errno == errno.ELOOP or os.path.islink(lock):
                raise planted from None
            raise _oserror(path, exc, "cannot lock") from None
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            os.close(fd)
            raise planted
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                stale = _dead_owner(fd) and _same_file(fd, lock)
                os.close(fd)
                if stale:  # its owner died; a child it forked holds the flock: this file is free to replace
                    _remove(str(lock))
                    continue
                raise busy from None
            os.close(fd)
            raise _oserror(path, exc, "cannot lock") from None
        try:  # the holder before us may have removed the file after we opened it: lock the new one
            if os.fstat(fd).st_ino == os.lstat(lock).st_ino:
                _claim(fd, path)
                return fd
        except FileNotFoundError:
            pass
        os.close(fd)
    raise busy


def _claim(fd: int, path: Path) -> None:
    """A lock just taken: what dead runs left beside the target removed, and this process written in as owner."""
    clear_dead(path)
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{owner()}\n".encode(), 0)
    except OSError:  # a full disk: the flock still guards; only a stale lock cannot be told by its owner then
        pass


def _dead_owner(fd: int) -> bool:
    """True if the lock file open at ``fd`` names an owner 'PID-START' that is no longer running (its flock then
    held only by a process the owner forked, e.g. a plugin's helper)."""
    try:
        text = os.pread(fd, 64, 0).decode("ascii", "replace").strip()
        pid, start = (int(x) for x in text.split("-"))
    except (OSError, ValueError):
        return False
    return pid != os.getpid() and not _alive(pid, start)


def _same_file(fd: int, path: Path) -> bool:
    try:
        return os.fstat(fd).st_ino == os.lstat(path).st_ino
    except OSError:
        return False


@contextmanager
def atomic_files(paths, force: bool = False):
    """Yield one temporary path per target in ``paths`` (in their order) to write; when the block ends normally
    every target is moved into place, else none is and what the block wrote is removed (see the module: a set).

    Each target is locked (``output_lock``) throughout and must be writable (``check_writable``); an existing
    one is refused unless ``force``, and then replaced (put back if a later move fails). The temporaries lie in
    one temporary folder per target folder (``.NAME.PID-START.XXXX.tmp``, NAME the first target there), so each
    move is a rename within one file system."""
    targets = [Path(p) for p in paths]
    if len({os.path.realpath(p) for p in targets}) != len(targets):
        raise OutputError(f"{targets[0]}: the same file is named twice among the outputs {', '.join(map(str, targets))}")
    with ExitStack() as stack:
        for t in targets:
            stack.enter_context(output_lock(t))
        for t in targets:
            check_writable(t)
            if os.path.lexists(t) and not force:
                raise OutputError(f"{t}: exists; choose another name or folder, or pass --force")
        stages: dict[str, Path] = {}
        staged = []
        try:
            for t in targets:
                parent = t.parent if str(t.parent) else Path(".")
                key = os.path.realpath(parent)
                if key not in stages:
                    try:
                        stages[key] = Path(tempfile.mkdtemp(dir=parent, prefix=_tag(t), suffix=".tmp"))
                    except OSError as exc:
                        raise _oserror(t, exc) from None
                    _leftovers.add(str(stages[key]))
                staged.append(stages[key] / t.name)
            try:
                yield list(staged)
            except OSError as exc:  # named by its target, never by the temporary written
                which = [t for t, tmp in zip(targets, staged) if str(tmp) == str(getattr(exc, "filename", ""))]
                raise OutputError(f"{(which or targets)[0]}: cannot write: {exc.strerror or exc}") from None
            for t, tmp in zip(targets, staged):
                if not tmp.is_file():
                    raise OutputError(f"{t}: nothing was written for it")
                os.chmod(tmp, 0o666 & ~_umask())
            _move_all(targets, staged)
        finally:
            for folder in stages.values():
                _remove(str(folder))


def _move_all(targets: list[Path], staged: list[Path]) -> None:
    """Move each staged file onto its target; on a failure, undo the moves made (old targets put back)."""
    done = []  # (target, its old version moved aside, or None)
    try:
        for t, tmp in zip(targets, staged):
            aside = None
            if os.path.lexists(t):
                aside = tmp.with_name(tmp.name + ".old")
                os.replace(t, aside)
            done.append((t, aside))
            os.replace(tmp, t)
    except OSError as exc:
        for t, aside in reversed(done):
            try:
                if aside is not None:
                    os.replace(aside, t)
                elif os.path.lexists(t):
                    os.unlink(t)
            except OSError:
                pass
        raise _oserror(t, exc) from None


def write_files(contents, force: bool = False) -> None:
    """Write ``contents`` (target path -> text or bytes) as one set (``atomic_files``): all or none."""
    paths = list(contents)
    with atomic_files(paths, force=force) as staged:
        for p, tmp in zip(paths, staged):
            data = contents[p]
            try:
                tmp.write_bytes(data.encode("utf-8") if isinstance(data, str) else bytes(data))
            except OSError as exc:
                raise OutputError(f"{p}: cannot write: {exc.strerror or exc}") from None
