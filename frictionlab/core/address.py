"""Scheduler addresses: the HOST:PORT of ``compare --scheduler``, checked before any connection is tried.

A host is an IPv4 address (four numbers 0-255), an IPv6 address in brackets (``[::1]``, a zone ``%eth0``
allowed) or a DNS name (labels of 1 to 63 letters, digits, ``-`` or ``_``, not starting or ending with ``-``,
separated by single dots, at most 253 characters; a final dot allowed). A port is 1 to 65535 in ASCII digits.
"""
from __future__ import annotations

import ipaddress
import re

from .errors import ParameterError

MAX_PORT = 65535
_PORT = re.compile(r"[0-9]{1,5}")
_LABEL = re.compile(r"(?!-)[\w-]{1,63}(?<!-)")
_IPV4ISH = re.compile(r"[0-9.]+")
EXAMPLE = "e.g. tcp://10.0.0.5:8786, tcp://[::1]:8786 or tcp://scheduler.example.org:8786"


def check_host_port(loc: str, where: str) -> tuple[str, int]:
    """(host, port) of ``loc`` ('HOST:PORT'), or a one-line ParameterError naming ``where`` and what is wrong."""
    if loc.startswith("["):
        inside, closed, rest = loc[1:].partition("]")
        if not closed:
            raise ParameterError(f"{where}: the IPv6 address opened with '[' is not closed; write it as [ADDRESS]:PORT "
                                 f"({EXAMPLE})")
        try:
            ipaddress.IPv6Address(inside)
        except ValueError:
            raise ParameterError(f"{where}: [{inside}] is not an IPv6 address ({EXAMPLE})") from None
        host, colon, port = inside, rest[:1], rest[1:]
        if colon != ":":
            raise ParameterError(f"{where}: expected :PORT after [{inside}] ({EXAMPLE})")
    else:
        host, colon, port = loc.rpartition(":")
        if not colon:
            raise ParameterError(f"{where}: expected PROTOCOL://HOST:PORT, got no port ({EXAMPLE})")
        if ":" in host or "[" in host or "]" in host:
            raise ParameterError(f"{where}: more than one ':' before the port; an IPv6 address goes in brackets, like "
                                 "tcp://[::1]:8786")
        _check_host(host, where)
    if not _PORT.fullmatch(port) or not 1 <= int(port) <= MAX_PORT:
        raise ParameterError(f"{where}: port {port!r} is not a port number from 1 to {MAX_PORT}")
    return host, int(port)


def _check_host(host: str, where: str) -> None:
    if not host:
        raise ParameterError(f"{where}: no host; expected PROTOCOL://HOST:PORT ({EXAMPLE})")
    if _IPV4ISH.fullmatch(host) and not host.endswith("."):
        try:
            ipaddress.IPv4Address(host)
        except ValueError:
            raise ParameterError(f"{where}: {host} is not an IPv4 address (four numbers from 0 to 255)") from None
        return
    name = host[:-1] if host.endswith(".") else host
    if len(name) > 253:
        raise ParameterError(f"{where}: the host name is {len(name)} characters long; at most 253")
    for label in name.split("."):
        if not label:
            raise ParameterError(f"{where}: host {host!r} has an empty label (two dots in a row, or a leading dot)")
        if not _LABEL.fullmatch(label):
            raise ParameterError(f"{where}: host {host!r}: label {label!r} must be 1 to 63 letters, digits, '-' or "
                                 "'_', not starting or ending with '-'")
