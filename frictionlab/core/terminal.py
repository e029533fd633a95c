"""What reaches a terminal: inert text in any encoding, on streams that may be closed or full.

``inert(text)`` drops what a terminal would act on rather than show: escape sequences (CSI, and OSC
such as OSC 52, which writes the clipboard), every other C0/C1 control character but the line
break and the tab, and the bidirectional overrides that reorder what is seen.
``ascii_fallback(text)`` spells symbols a legacy encoding lacks (``±`` -> ``+/-``, ``σ`` -> ``sigma``).

``guarded_streams()`` (the command line wraps every run in it) puts both at the one place all
output passes: sys.stdout and sys.stderr are replaced by ``TerminalStream`` objects that clean and
encode each write. A stream that fails (stdout on a full disk, EIO) is remembered, not raised, so
the run still finishes and writes its files; the command line then names the stream and exits 2.
A broken pipe is raised at once (the reader went away: stop as ``cat`` does). A closed standard
stream (``2>&-``) is reopened on /dev/null first, so no file the run opens can take its number.
"""
from __future__ import annotations

import errno
import os
import re
import sys
import unicodedata
from contextlib import contextmanager

_SEQUENCES = re.compile(
    r"\x1b\][^\x07\x1b\x9c]*(?:\x07|\x1b\\|\x9c)?"  # OSC ... BEL/ST (title, clipboard, hyperlink)
    r"|\x9d[^\x07\x1b\x9c]*(?:\x07|\x1b\\|\x9c)?"  # the same with the 8-bit introducer
    r"|\x1b\[[0-?]*[ -/]*[@-~]?|\x9b[0-?]*[ -/]*[@-~]?"  # CSI (colours, cursor moves, erase)
    r"|\x1b[PX^_][^\x1b\x9c]*(?:\x1b\\|\x9c)?"  # DCS, SOS, PM, APC strings
    r"|\x1b.?",  # any other escape
    re.S)
_CONTROLS = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u200e\u200f\u202a-\u202e\u2066-\u2069]")


def inert(text: str) -> str:
    """``text`` without escape sequences, control characters (but ``\\n`` and ``\\t``) and bidi overrides."""
    text = str(text)
    if text.isprintable():  # the common case: nothing to do
        return text
    return _CONTROLS.sub("", _SEQUENCES.sub("", text))


_SYMBOLS = {"±": "+/-", "−": "-", "–": "-", "—": "--", "≈": "~", "≥": ">=", "≤": "<=", "≡": "==",
            "…": "...", "✓": "ok", "⚠": "!", "√": "sqrt", "→": "->", "×": "x", "²": "^2", "³": "^3",
            "′": "'", "°": " deg", "µ": "u", "·": "*", "‘": "'", "’": "'", "“": '"', "”": '"'}


def ascii_fallback(text: str) -> str:
    """``text`` in ASCII: symbols spelled (``±`` -> ``+/-``), Greek letters named, anything else '?'."""
    out = []
    for ch in text:
        if ord(ch) < 128:
            out.append(ch)
        elif ch in _SYMBOLS:
            out.append(_SYMBOLS[ch])
        else:
            name = unicodedata.name(ch, "")
            if name.startswith("GREEK") and "LETTER" in name:
                word = name.rsplit(" ", 1)[-1].lower()
                out.append(word.capitalize() if "CAPITAL" in name else word)
            else:
                decomposed = unicodedata.normalize("NFKD", ch).encode("ascii", "ignore").decode()
                out.append(decomposed or "?")
    return "".join(out)


def encodable(text: str, encoding: str | None) -> str:
    """``text`` as it can be encoded in ``encoding``: unchanged if it can, else with ASCII fallbacks."""
    try:
        text.encode(encoding or "utf-8")
        return text
    except (UnicodeEncodeError, LookupError):
        return ascii_fallback(text)


class TerminalStream:
    """A text stream that writes ``inert``, encodable text to ``stream`` and remembers (rather than
    raises) a failure other than a broken pipe. ``unfiltered`` is the stream itself (a progress bar
    draws with carriage returns through it)."""

    def __init__(self, stream, name: str):
        self.unfiltered, self.name = stream, name
        self.failure: OSError | None = None

    @property
    def encoding(self):
        return getattr(self.unfiltered, "encoding", None) or "utf-8"

    def write(self, text: str) -> int:
        if self.failure is not None:
            return len(text)
        clean = encodable(inert(text), self.encoding)
        self._do(self.unfiltered.write, clean)
        if "\n" in clean:
            self._do(self.unfiltered.flush)
        return len(text)

    def flush(self) -> None:
        if self.failure is None:
            self._do(self.unfiltered.flush)

    def _do(self, call, *args):
        try:
            call(*args)
        except BrokenPipeError:
            raise
        except OSError as exc:
            if exc.errno == errno.EPIPE:
                raise BrokenPipeError(*exc.args) from None
            self._failed(exc)
        except ValueError:  # a stream closed under us: nothing more can be shown on it
            self._failed(OSError(errno.EBADF, "the stream is closed"))

    def _failed(self, exc: OSError) -> None:
        """Remember the failure; point the descriptor at /dev/null so that what is still buffered
        does not fail again when the interpreter exits."""
        self.failure = exc
        try:
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, self.unfiltered.fileno())
            os.close(null)
        except (OSError, ValueError, AttributeError):
            pass

    def isatty(self) -> bool:
        try:
            return self.unfiltered.isatty()
        except (OSError, ValueError, AttributeError):
            return False

    def fileno(self) -> int:
        return self.unfiltered.fileno()

    def __getattr__(self, attr):  # errors, buffer, mode ...: as the stream has them
        return getattr(self.unfiltered, attr)


def reopen_closed_standard_fds() -> set[int]:
    """Open /dev/null on any of the file descriptors 0, 1, 2 that is closed (``2>&-``), so that no
    file this run opens gets that number (and receives what is meant for the terminal); returns them."""
    closed = set()
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            closed.add(fd)
            new = os.open(os.devnull, os.O_RDWR)
            if new != fd:  # a lower one was closed too and took this open: the loop reaches it
                os.dup2(new, fd)
                os.close(new)
    return closed


class _Null:
    encoding = "utf-8"

    def write(self, text):
        return len(text)

    def flush(self):
        pass

    def isatty(self):
        return False


@contextmanager
def guarded_streams():
    """Replace sys.stdout and sys.stderr by TerminalStream objects for the block; yields them."""
    closed = reopen_closed_standard_fds()
    saved = sys.stdout, sys.stderr
    out = TerminalStream(sys.stdout if sys.stdout is not None else _Null(), "standard output")
    err = TerminalStream(sys.stderr if sys.stderr is not None else _Null(), "standard error")
    if 1 in closed:  # nothing shown can reach anyone: said once at the end (core of the command line)
        out.failure = OSError(errno.EBADF, "it is closed")
    sys.stdout, sys.stderr = out, err
    try:
        yield out, err
    finally:
        for s in (out, err):
            try:
                s.flush()
            except OSError:
                pass
        sys.stdout, sys.stderr = saved
