"""Measured records that the repository may not hold, used as built-in datasets when someone placed them.

Raw laboratory records under a third party's license are not committed. RECORDS names each one (its
file, SHA-256, source, license, citation and import options); when the file is present in a raw-data
folder with that checksum, the dataset is imported once into a cache folder and is then listed and
loaded like any built-in dataset. Raw-data folders: the ``FRICTIONLAB_RAW_DATA`` environment variable
(folders separated by ':'), else ``shared/data`` in the folder that holds the repository's folder. Cache: ``$XDG_CACHE_HOME/frictionlab/external`` (default ``~/.cache``).
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

from ..core.errors import DatasetError

_STEADYSTATE = dict(
    format="velstep", license="MIT",
    citation="Giacomel, Faulkner, Lambert and Allen, steadystate: A MATLAB-based routine for determining steady-state "
             "friction conditions in the framework of rate-and-state friction analysis, Geosphere 20(3) 965-980 "
             "(2024), doi:10.1130/GES02739.1",
)


def _steadystate(n: int, sha256: str) -> dict:
    raw = f"velstep{n}_TR2_exp013_sepiolite.txt"
    return dict(_STEADYSTATE, file=f"steadystate/{raw}", sha256=sha256,
                source=f"pgiacomel/steadystate (GitHub) commit 0225b97, file {raw}: sepiolite gouge, experiment "
                       "TR2 exp013, effective normal stress 30 MPa (sn 50 MPa, Pf 20 MPa)")


#: dataset name -> where its raw record comes from and how it is imported (``stiffness``: a start for the
#: machine stiffness [1/m] where the record's loading after the step does not give one; fitted with --free).
RECORDS = {
    "sepiolite-velstep1": _steadystate(1, "7c1037b7356a1916e5d3ecd22ed45acc0ffb70f812a6fb908d21648464a8ec29"),
    "sepiolite-velstep2": _steadystate(2, "7702fa500fe97c8ef345866f376222e600682f5da70ed6e4d4f0d9f8fbb72f40"),
    "sepiolite-velstep3": _steadystate(3, "e0d598a177dcb7f3dff040241f490541bec42940e016df541a19559a7b083dc5"),
    "basalt-velstep4": dict(
        _STEADYSTATE, file="steadystate/velstep4_BRAVA_expb819_basalt.txt",
        sha256="0ed7d29f21a37335d8191dcb365320d449bf7e52b6557690de34165fb889c959", stiffness=2e3,
        source="pgiacomel/steadystate (GitHub) branch Demo-velocity-stepping-tests, commit bfb4c1d, file "
               "velstep4_BRAVA_expb819_basalt.txt (the same bytes as velstep4_BRAVA_expb819_basalt_Giacomel_et_al_2021.txt "
               "at commit 0225b97): basalt gouge, BRAVA apparatus experiment b819, normal stress 20 MPa as recorded "
               "(the column is headed Normal_stress; the source states no pore pressure for it)"),
}


def raw_dirs() -> list[Path]:
    """Folders searched for raw records, in order."""
    env = os.environ.get("FRICTIONLAB_RAW_DATA")
    if env is not None:
        return [Path(p) for p in env.split(os.pathsep) if p]
    from importlib import resources

    builtin = Path(str(resources.files("frictionlab.data")))  # the repository's datasets/ folder
    return [builtin.resolve().parent.parent / "shared" / "data"]


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def locate(name: str) -> Path | None:
    """The raw record of ``name`` in a raw-data folder, if present with the expected checksum."""
    spec = RECORDS[name]
    for folder in raw_dirs():
        path = folder / spec["file"]
        if path.is_file() and _sha256(path) == spec["sha256"]:
            return path
    return None


def present() -> list[str]:
    """Names of the external datasets whose raw record is present."""
    return [name for name in RECORDS if locate(name) is not None]


def _cache() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "frictionlab" / "external"


def dataset_toml(name: str) -> Path:
    """The TOML of external dataset ``name``, imported into the cache on first use; a one-line error
    saying where to place the record when it is absent."""
    spec = RECORDS[name]
    raw = locate(name)
    if raw is None:
        where = " or ".join(str(d / spec["file"]) for d in raw_dirs())
        raise DatasetError(f"dataset '{name}' is a measured record not held in the repository ({spec['license']} "
                           f"license, {spec['source'].split(',')[0]}): place the file at {where} "
                           f"(SHA-256 {spec['sha256'][:12]}...), or set FRICTIONLAB_RAW_DATA")
    folder = _cache() / spec["sha256"][:16]
    toml = folder / f"{name}.toml"
    if toml.is_file() and (folder / f"{name}.csv").is_file():
        return toml
    from ..core.files import atomic_write_text
    from .velstep import velstep_dataset

    k = spec.get("stiffness")
    command = (f"frictionlab datasets import velstep {Path(spec['file']).name} --name {name} --points 600 --steps 1"
               + (f" --stiffness '{k * 1e-6:g} 1/um'" if k else ""))
    text, csv, _ = velstep_dataset(raw, name, source=spec["source"], license=spec["license"],
                                   citation=spec["citation"], command=command, stiffness=k)
    folder.mkdir(parents=True, exist_ok=True)
    atomic_write_text(folder / f"{name}.csv", csv)
    atomic_write_text(toml, text)
    return toml
