"""core.terminal and core.names: the filters every string passes on its way to a terminal, and the name grammar."""
from __future__ import annotations

import errno
import io

import pytest

from frictionlab.core.names import check_name, is_name
from frictionlab.core.progress import Progress
from frictionlab.core.terminal import TerminalStream, ascii_fallback, inert


@pytest.mark.parametrize("text, shown", [
    ("a\x1b]52;c;ZWNobw==\x07b", "ab"),  # OSC 52: a clipboard write, payload and all
    ("a\x1b]0;title\x1b\\b", "ab"),  # OSC ended by ST
    ("\x1b[31mred\x1b[0m", "red"),  # CSI colours
    ("a\x9b2Jb", "ab"),  # 8-bit CSI
    ("x\u202eevil", "xevil"),  # a bidi override
    ("bell\x07 nul\x00 del\x7f", "bell nul del"),
    ("tab\tline\nkept", "tab\tline\nkept"),
    ("plain ± σ", "plain ± σ"),
])
def test_inert_drops_what_a_terminal_acts_on(text, shown):
    assert inert(text) == shown


def test_ascii_fallback_spells_symbols():
    assert ascii_fallback("h = 4.0 ± 0.1 µm, σ ≈ 2, Δχ² ≥ 1 → ok") == "h = 4.0 +/- 0.1 um, sigma ~ 2, Deltachi^2 >= 1 -> ok"


def test_a_failing_stream_is_remembered_not_raised():
    class Full(io.StringIO):
        def flush(self):
            raise OSError(errno.ENOSPC, "No space left on device")

    s = TerminalStream(Full(), "standard output")
    s.write("one line\n")
    s.write("and more\n")  # no second failure
    assert s.failure is not None and s.failure.errno == errno.ENOSPC


def test_a_broken_pipe_is_raised_at_once():
    class Gone(io.StringIO):
        def write(self, text):
            raise BrokenPipeError(errno.EPIPE, "Broken pipe")

    with pytest.raises(BrokenPipeError):
        TerminalStream(Gone(), "standard output").write("x\n")


def test_an_encoding_without_the_symbols_gets_ascii():
    raw = io.TextIOWrapper(io.BytesIO(), encoding="latin-1")
    s = TerminalStream(raw, "standard output")
    s.write("σ ± 1\n")
    raw.flush()
    assert raw.buffer.getvalue() == "sigma +/- 1\n".encode("latin-1")


def test_the_progress_bar_keeps_its_carriage_returns():
    raw = io.StringIO()
    with Progress("compare", stream=TerminalStream(raw, "standard error"), tty=True) as bar:
        bar(1, 2, "coulomb")
    assert "\r" in raw.getvalue()


@pytest.mark.parametrize("name", ["incline-oil-a100", "kt-twolam-v20", "rate-state.aging_2+x", "A1"])
def test_names(name):
    assert is_name(name) and check_name(name, "x") == name


@pytest.mark.parametrize("name, error, match", [
    ("a,b", ValueError, "x: 'a,b' must start"), ("ALL", ValueError, "reserved word"), ("nul", ValueError, "device name"),
    ("../x", ValueError, "must start"), ("", ValueError, "must start"), ("x" * 101, ValueError, "101 characters"),
    ("a\x1bb", ValueError, r"'a\\x1bb'"), (3, TypeError, "x: is int, not a string"),
])
def test_not_names(name, error, match):
    with pytest.raises(error, match=match):
        check_name(name, "x")
