"""The layers, as folders: imports point only downward, and nothing imports, even inside a function,
a module that imports it back.

core < physics < solve < io < inference < pipeline < report < the command line (cli, commands/) and
the public API (``frictionlab/__init__.py``, the ``frictionlab.law`` re-export). A module may import
from its own layer or any layer below it."""
import ast
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "frictionlab"
LAYERS = ["core", "physics", "solve", "io", "inference", "pipeline", "report", "top"]


def layer_of(module: str) -> str:
    head = module.split(".")[0]
    return head if head in LAYERS else "top"


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PKG).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports() -> dict[str, set[str]]:
    """module (dotted, below frictionlab) -> the frictionlab modules it imports, at any depth of its code."""
    g: dict[str, set[str]] = {}
    for path in PKG.rglob("*.py"):
        me = module_name(path)
        package = me.split(".") if path.name == "__init__.py" else me.split(".")[:-1]
        out = g.setdefault(me, set())
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level:
                base = package[: len(package) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
                out.update(f"{target}.{a.name}".strip(".") if not node.module else target for a in node.names)
            elif isinstance(node, (ast.Import, ast.ImportFrom)):
                names = [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module or ""]
                out.update(n.removeprefix("frictionlab.") for n in names if n.startswith("frictionlab."))
    return g


def climbs(g) -> list[str]:
    return sorted(f"{m} -> {t}" for m, ts in g.items() for t in ts
                  if LAYERS.index(layer_of(t)) > LAYERS.index(layer_of(m)))


def test_imports_point_only_downward():
    g = imports()
    assert "inference.fitting.fit" in g["pipeline.comparison"]  # the reader sees the code's real imports
    assert climbs(g) == []


def test_the_layer_check_finds_a_climb():
    assert climbs({"physics.scene": {"core.units", "solve.plan"}, "report.fits": {"inference.fitting.fit"}}) == [
        "physics.scene -> solve.plan"]


def test_every_layer_is_a_folder_and_nothing_else_is_loose():
    loose = sorted(p.name for p in PKG.glob("*.py"))
    assert loose == ["__init__.py", "__main__.py", "cli.py", "law.py"]
    assert all((PKG / layer / "__init__.py").exists() for layer in LAYERS[:-1])


def cycles(g) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan), modules grouped by their file's
    top-level unit (a subpackage such as solve.solvers counts as one)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in g.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in list(g):
        if v not in index:
            visit(v)
    return out


def unit(module: str) -> str:
    """'solve.solvers.stick' -> 'solve.solvers'; a module of inference's subpackages is a unit of its own
    ('inference.fitting.fit'); a layer package -> itself."""
    parts = module.split(".")
    return ".".join(parts[:3] if parts[0] == "inference" else parts[:2]) if len(parts) >= 2 else module


#: Known cycles, each with the reason it is still there (remove an entry when it is untangled).
KNOWN = {("solve.plan", "solve.solvers"): "Plan.derivatives (laws with state) reads solvers.stick.branch_slip inside a function"}


def test_imports_flow_one_way():
    g: dict[str, set[str]] = {}
    for m, ts in imports().items():
        if unit(m) in LAYERS or m in ("", "__main__"):
            continue  # a layer's own __init__ and the public API re-export
        g.setdefault(unit(m), set()).update(unit(t) for t in ts if unit(t) != unit(m) and unit(t) not in LAYERS)
    assert {"io.dataset", "solve.outcome"} <= g["inference.fitting.predict"] and "solve.outcome" in g["io.dataset"]
    assert "io.dataset" not in g["solve.solvers"] and "io.dataset" not in g["solve.outcome"]
    found = cycles(g)
    assert [tuple(c) for c in found if tuple(c) not in KNOWN] == []


def test_the_cycle_finder_finds_a_cycle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
