"""Data flows one way: no module imports, even inside a function, a module that imports it back.
In particular dataset -> outcome (scene models), predict -> dataset and outcome, and solvers
never read datasets. Subpackages (solvers/, report/, commands/, ...) count as one module."""
import ast
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "frictionlab"


def graph() -> dict[str, set[str]]:
    """module -> the frictionlab modules it imports (relative imports, at any depth of the code)."""
    units = {p.stem for p in PKG.glob("*.py")} | {p.name for p in PKG.iterdir() if (p / "__init__.py").exists()}
    g: dict[str, set[str]] = {}
    for path in PKG.rglob("*.py"):
        parts = path.relative_to(PKG).parts
        me, depth = (parts[0] if len(parts) > 1 else path.stem), len(parts) - 1
        for node in ast.walk(ast.parse(path.read_text())):
            if not (isinstance(node, ast.ImportFrom) and node.level) or node.level - 1 < depth:
                continue  # absolute, or inside the same subpackage
            names = [node.module.split(".")[0]] if node.module else [a.name for a in node.names]
            g.setdefault(me, set()).update(n for n in names if n in units and n != me)
    return g


def cycles(g) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
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


#: Known cycles, each with the reason it is still there (remove an entry when it is untangled).
KNOWN = {("plan", "solvers"): "Plan.derivatives (laws with state) reads solvers.stick.branch_slip inside a function"}


def test_imports_flow_one_way():
    g = graph()
    assert "outcome" in g["dataset"] and {"dataset", "outcome"} <= g["predict"]
    assert "dataset" not in g["solvers"] and "dataset" not in g["outcome"] and "predict" not in g["outcome"]
    found = cycles({k: v - {"__init__"} for k, v in g.items() if k != "__init__"})
    assert [tuple(c) for c in found if tuple(c) not in KNOWN] == []


def test_the_cycle_finder_finds_a_cycle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
