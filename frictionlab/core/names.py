"""Names: one grammar for every name a user or a plugin gives (dataset, template, law, group).

A name

* is a string of 1 to ``MAX_NAME`` (100) characters,
* starts with an ASCII letter or digit and holds only ASCII letters, digits and ``. _ + -``,
* is not a reserved word: ``ALL`` (the group of every dataset in a ranking), in any case, nor a
  device name that cannot be a file name on some systems (``CON``, ``PRN``, ``AUX``, ``NUL``,
  ``COM1``-``COM9``, ``LPT1``-``LPT9``).

So a name never holds a path separator (``/``, ``\\``), a list separator (``,``, space), a control
character, a quote or a ``$`` (matplotlib mathtext), and it never starts with ``.`` (a hidden file,
``..``). It becomes part of file names, list options and table cells as it is.

``check_name`` is the one place the grammar is checked; every way a name enters (a dataset's TOML,
``--name``, ``--laws``/``--data`` lists, a plugin's ``name``, the Python API) calls it.
"""
from __future__ import annotations

import re

MAX_NAME = 100
GRAMMAR = ("a name starts with a letter or digit and holds only letters, digits and . _ + - "
           f"(at most {MAX_NAME} characters; it becomes part of file names and lists)")
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._+-]*")
RESERVED = frozenset({"all", "con", "prn", "aux", "nul"} | {f"{d}{i}" for d in ("com", "lpt") for i in range(1, 10)})


def shown(name: str, width: int = 40) -> str:
    """``name`` quoted for a message: control characters escaped (repr), long names shortened."""
    text = name if len(name) <= width else name[:width - 3] + "..."
    return repr(text)


def name_problem(name) -> str | None:
    """Why ``name`` is not a name (a phrase), or None if it is one."""
    if not isinstance(name, str):
        return f"is {type(name).__name__}, not a string"
    if len(name) > MAX_NAME:
        return f"is {len(name)} characters long; at most {MAX_NAME}"
    if not _NAME.fullmatch(name):
        return "must start with a letter or digit and hold only letters, digits and . _ + - " \
               "(it becomes part of file names and lists)"
    if name.lower() in RESERVED:
        return f"is a reserved word ({'the group of every dataset' if name.lower() == 'all' else 'a device name'})"
    return None


def check_name(name, where: str, error: type[Exception] = ValueError) -> str:
    """``name`` if it follows the grammar, else ``error`` (for the default ValueError: TypeError if not a
    string) with a one-line
    message ``where: 'name' ...``; ``where`` names the field or parameter the name came from."""
    problem = name_problem(name)
    if problem is None:
        return name
    if not isinstance(name, str) and error is ValueError:  # the Python API: a wrong type
        raise TypeError(f"{where}: {problem}")
    raise error(f"{where}: {shown(name)} {problem}")


def is_name(name) -> bool:
    """True if ``name`` follows the grammar."""
    return name_problem(name) is None
