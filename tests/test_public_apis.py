"""frictionlab and laws use their dependencies through public APIs only: no private module (``scipy.integrate._ivp``),
no private name imported from one (``from matplotlib import _api``), no private attribute read or set on what a
dependency hands back (``font._layout``, ``axis._update_ticks = ...``, ``getattr(pool, "_processes")``), no method
patched in (``types.MethodType``).

The source is walked as syntax (``ast``): a private name (one leading underscore, not a dunder) read as an attribute
counts as the project's own only where the project defines it (a function, method, class, class attribute, slot,
or an attribute set on ``self`` or ``cls``); anything else is a dependency's. The check is run on planted lines
first, so that it is known to find what it is there to find."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("frictionlab", "laws")
#: private-looking names that are documented public API: os._exit (the os module), a namedtuple's methods
PUBLIC = {"_exit", "_replace", "_asdict", "_fields", "_make", "_field_defaults"}


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _own_names(trees) -> set[str]:
    """Private names the project defines: functions, classes, class-level names, slots, self./cls. attributes."""
    own = set()
    for tree in trees:
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                own.add(node.name)
            if isinstance(node, ast.ImportFrom) and _local(node.module, node.level):
                own.update(a.asname or a.name for a in node.names)
            if isinstance(node, ast.ClassDef):
                for stmt in node.body:
                    for t in (stmt.targets if isinstance(stmt, ast.Assign) else
                              [stmt.target] if isinstance(stmt, ast.AnnAssign) else []):
                        if isinstance(t, ast.Name):
                            own.add(t.id)
                        if isinstance(t, ast.Name) and t.id == "__slots__" and isinstance(stmt.value, ast.Tuple):
                            own.update(e.value for e in stmt.value.elts if isinstance(e, ast.Constant))
            if isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
                for t in (node.targets if isinstance(node, ast.Assign) else [node.target]):
                    for e in ast.walk(t):
                        if isinstance(e, ast.Attribute) and isinstance(e.value, ast.Name) and e.value.id in ("self",
                                                                                                             "cls"):
                            own.add(e.attr)
                        if isinstance(e, ast.Name):
                            own.add(e.id)
    return {n for n in own if _private(n)}


def _local(module: str | None, level: int) -> bool:
    return level > 0 or (module or "").split(".")[0] in PACKAGES


def violations(source: str, own: set[str] | None = None, where: str = "<text>") -> list[str]:
    """What ``source`` uses of its dependencies' private parts, one line each ('file:line: what')."""
    tree = ast.parse(source)
    own = _own_names([tree]) if own is None else own
    out = []
    for node in ast.walk(tree):
        line = f"{where}:{getattr(node, 'lineno', 0)}"
        if isinstance(node, ast.Import):
            out += [f"{line}: import {a.name}" for a in node.names
                    if not _local(a.name, 0) and any(_private(p) for p in a.name.split("."))]
        elif isinstance(node, ast.ImportFrom) and not _local(node.module, node.level):
            if any(_private(p) for p in (node.module or "").split(".")):
                out.append(f"{line}: from {node.module} import ...")
            out += [f"{line}: from {node.module} import {a.name}" for a in node.names if _private(a.name)]
        elif isinstance(node, ast.Attribute) and _private(node.attr) and node.attr not in own | PUBLIC:
            out.append(f"{line}: .{node.attr}")
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "MethodType"
              and isinstance(node.func.value, ast.Name) and node.func.value.id == "types"):
            out.append(f"{line}: types.MethodType (a method patched in)")
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
              and node.func.id in ("getattr", "setattr", "hasattr", "delattr") and len(node.args) >= 2
              and isinstance(node.args[1], ast.Constant) and isinstance(node.args[1].value, str)
              and _private(node.args[1].value) and node.args[1].value not in own | PUBLIC):
            out.append(f"{line}: {node.func.id}(..., {node.args[1].value!r}) (a private attribute by name)")
    return out


def _sources():
    files = sorted(p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py"))
    assert len(files) > 100
    return [(p, p.read_text(encoding="utf-8")) for p in files]


PLANTED = [
    "from scipy.integrate._ivp import dop853_coefficients as dc\n",
    "import matplotlib._api\n",
    "from matplotlib import _api\n",
    "from matplotlib.ft2font import FT2Font\nFT2Font('x')._layout('text')\n",
    "def f(ax):\n    ax._request_autoscale_view()\n",
    "import types\ndef f(axis, g):\n    axis._update_ticks = types.MethodType(g, axis)\n",
    "def f(lines, kw):\n    lines._internal_update(kw)\n",
    "def f(pool):\n    return getattr(pool, '_processes', None)\n",
]


@pytest.mark.parametrize("text", PLANTED)
def test_the_check_finds_a_planted_private_use(text):
    assert violations(text), text


def test_the_check_leaves_the_projects_own_private_names_alone():
    text = ("from ._helpers import _kept\nfrom . import base\nimport os\n"
            "class A:\n    __slots__ = ('_b',)\n    def _c(self):\n        self._d = 1\n        return self._b\n"
            "def f(a):\n    a._c(); base._kept(); os._exit(0)\n    return a._d\n")
    assert violations(text) == []


def test_no_private_use_of_a_dependency_in_the_package():
    sources = _sources()
    own = _own_names(ast.parse(text) for _, text in sources)
    found = [v for path, text in sources for v in violations(text, own, str(path.relative_to(ROOT)))]
    assert found == []
