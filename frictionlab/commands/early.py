"""Answers a command gives before it imports the numerics: an unknown law or dataset name and an output folder
that exists, refused with the same one-line errors the full checks give later, in a fraction of a second.

Law names are read from the installed packages' entry-point metadata (``frictionlab.laws``) without importing any
law; where a law could come from elsewhere (a --load file, a third-party plugin, whose law's name may differ from
its entry point's), nothing is refused here and the registry decides as before. Only the standard library and
frictionlab's own light modules are imported."""
from __future__ import annotations

from importlib.metadata import entry_points
from pathlib import Path

GROUP = "frictionlab.laws"  # physics.registry.GROUP


def check_laws(names, loads=()) -> None:
    """RegistryError for a name among ``names`` that no built-in law has, where only built-in laws are installed
    and no --load file is given ("all" names every law)."""
    if loads or not names:
        return
    points = entry_points(group=GROUP)
    if any(not ep.value.startswith("frictionlab.") for ep in points):
        return  # a third-party plugin: its law's name is known once it is imported
    known = {ep.name for ep in points}
    for name in names:
        if name != "all" and name not in known:
            from ..core.errors import RegistryError

            raise RegistryError(f"unknown law '{name}'; registered laws: {', '.join(sorted(known))}")


def check_datasets(names) -> None:
    """DatasetError for a name among ``names`` that is neither a built-in dataset, a measured record's name, nor
    a .toml or .csv path (as ``io.dataset.resolve`` says it)."""
    from importlib import resources

    from ..io.external import RECORDS

    folder = Path(str(resources.files("frictionlab.data")))
    for name in names:
        if Path(name).suffix in (".toml", ".csv") or name in RECORDS or (folder / f"{name}.toml").exists():
            continue
        from ..core.errors import DatasetError

        builtin = ", ".join(sorted(p.stem for p in folder.glob("*.toml")))
        raise DatasetError(f"unknown dataset '{name}'; built-in: {builtin} (or give a .toml path)")


def check_out(path, force: bool, data=()) -> None:
    """OutputError for an output that is, holds or lies inside a dataset file named in ``data`` (and its CSV), or
    a folder that exists, unless --force (``core.inputs.check_apart``, ``core.outfolder.check_target``)."""
    import os

    from ..core.inputs import check_apart
    from ..core.outfolder import check_target

    files = [p for d in data if str(d).endswith(".toml") for p in (str(d), str(d)[:-5] + ".csv") if os.path.lexists(p)]
    check_apart(path, files)
    check_target(path, force)
