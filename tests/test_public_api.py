"""Every public function and class of the API is annotated and documented: the names of
``frictionlab.__all__`` and the public names of the modules the API reference documents (docs/api/*.md).
A public callable has a docstring, every parameter an annotation (``*args``/``**kwargs`` included) and a
return annotation; a public class has a docstring, and so has each public method it defines."""
from __future__ import annotations

import importlib
import inspect
import re
from pathlib import Path

import pytest

import frictionlab

ROOT = Path(__file__).resolve().parents[1]


def documented_objects() -> dict[str, object]:
    """Qualified name -> object, for frictionlab.__all__ and every '::: module.name' of the API reference."""
    out = {f"frictionlab.{n}": getattr(frictionlab, n) for n in frictionlab.__all__}
    for page in sorted((ROOT / "docs" / "api").glob("*.md")):
        for path in re.findall(r"^::: ([\w.]+)$", page.read_text(encoding="utf-8"), re.M):
            module, _, name = path.rpartition(".")
            out[path] = getattr(importlib.import_module(module), name)
    return out


def problems(qualname: str, obj) -> list[str]:
    out = []
    if inspect.isclass(obj):
        if not (obj.__doc__ or "").strip():
            out.append(f"{qualname}: no docstring")
        for name, member in vars(obj).items():
            if name.startswith("_") or not (inspect.isfunction(member) or isinstance(member, (property, classmethod,
                                                                                                 staticmethod))):
                continue
            fn = member.fget if isinstance(member, property) else getattr(member, "__func__", member)
            out += problems(f"{qualname}.{name}", fn)
        return out
    if not callable(obj):
        return out
    if not (inspect.getdoc(obj) or "").strip():
        out.append(f"{qualname}: no docstring")
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return out
    for p in sig.parameters.values():
        if p.name in ("self", "cls"):
            continue
        if p.annotation is inspect.Parameter.empty:
            out.append(f"{qualname}: parameter {p.name} has no annotation")
    if sig.return_annotation is inspect.Signature.empty:
        out.append(f"{qualname}: no return annotation")
    return out


def test_the_public_api_is_found():
    objects = documented_objects()
    assert {"frictionlab.fit", "frictionlab.compare", "frictionlab.simulate"} <= set(objects)
    assert len(objects) > 40


@pytest.mark.parametrize("qualname", sorted(documented_objects()))
def test_public_callable_is_annotated_and_documented(qualname):
    assert problems(qualname, documented_objects()[qualname]) == []


def test_the_check_finds_what_is_missing():
    def f(a, b: int):
        return a

    class C:
        """A class."""

        def m(self) -> None:
            pass

    assert problems("f", f) == ["f: no docstring", "f: parameter a has no annotation", "f: no return annotation"]
    assert problems("C", C) == ["C.m: no docstring"]
