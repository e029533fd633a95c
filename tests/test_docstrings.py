"""The public API's docstrings: numpydoc sections on at least 90 % of the public callables (everything
``frictionlab`` exports and the public methods of its result objects), and their Examples run as doctests."""
from __future__ import annotations

import doctest
import importlib
import inspect
import re

import pytest

import frictionlab as fl

#: The result objects whose public methods count as public API.
RESULTS = ("Comparison", "Dataset", "EquivalenceResult", "FitResult", "ParamResult", "RankRow", "Target",
           "Trajectory")
SECTION = re.compile(r"^(Parameters|Returns|Yields|Raises|Attributes|Examples)\n-{3,}$", re.M)
MINIMUM = 0.90


def public_callables() -> list[tuple[str, object]]:
    out = []
    for name in fl.__all__:
        obj = getattr(fl, name)
        if not callable(obj):
            continue
        out.append((name, obj))
        if name in RESULTS:
            out += [(f"{name}.{m}", v) for m, v in vars(obj).items()
                    if not m.startswith("_") and inspect.isfunction(v)]
    return out


def missing_sections(obj) -> set[str]:
    """The numpydoc sections ``obj``'s docstring lacks: Parameters when it takes arguments, Returns when it
    is a function that returns something, Parameters or Attributes for a class."""
    found = set(SECTION.findall(inspect.getdoc(obj) or ""))
    if inspect.isclass(obj):
        return set() if found & {"Parameters", "Attributes"} else {"Parameters or Attributes"}
    signature = inspect.signature(obj)
    need = set()
    if [p for p in signature.parameters if p not in ("self", "cls")]:
        need.add("Parameters")
    if signature.return_annotation not in (None, "None"):
        need.add("Returns")
    return need - found


def test_numpydoc_sections_on_the_public_api():
    items = public_callables()
    assert len(items) >= 50  # the exports and the result objects' methods were found
    lacking = {name: sorted(missing_sections(obj)) for name, obj in items if missing_sections(obj)}
    share = 1 - len(lacking) / len(items)
    assert share >= MINIMUM, f"{share:.0%} of {len(items)} public callables have numpydoc sections; lacking: {lacking}"


def test_the_measure_tells_a_bare_docstring_from_a_numpydoc_one():
    def bare(x: float) -> float:
        """Twice x."""
        return 2 * x

    def documented(x: float) -> float:
        """Twice x.

        Parameters
        ----------
        x : float
            A number [m].

        Returns
        -------
        float
            Twice it [m].
        """
        return 2 * x

    assert missing_sections(bare) == {"Parameters", "Returns"}
    assert missing_sections(documented) == set()


def modules_with_examples() -> list[str]:
    names = sorted({inspect.getmodule(obj).__name__ for _, obj in public_callables()})
    return [n for n in names if ">>>" in inspect.getsource(importlib.import_module(n))]


@pytest.mark.parametrize("module", modules_with_examples())
def test_docstring_examples_run(module):
    result = doctest.testmod(importlib.import_module(module), optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0, f"{result.failed} of {result.attempted} doctest examples failed in {module}"


def test_there_are_examples_to_run():
    assert len(modules_with_examples()) >= 5
