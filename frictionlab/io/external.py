"""Measured records that the repository may not hold, used as built-in datasets when someone placed them.

Raw laboratory records under a third party's license are not committed. RECORDS names each one (its
file, size, SHA-256, source, license and citation); when the file is present in a raw-data folder with
that checksum, it is imported (``velstep``) into a cache folder once and then listed and loaded like any
built-in dataset. Raw-data folders: the ``FRICTIONLAB_RAW_DATA`` environment variable (folders separated
by ':'), else ``shared/data`` in the folder that holds the repository's folder.

The cache is ``platformdirs.user_cache_dir("frictionlab")/external`` (``~/.cache/frictionlab/external`` on
Linux, or under an absolute ``XDG_CACHE_HOME``; a relative one is ignored with a note). Each cached import
is a CSV, a TOML and a manifest with the SHA-256 of all three files' sources: the record, the CSV and the
TOML, and the importer's version. All are checked at each load; a cached import that differs is imported
again from the record, with a one-line note. Cache files are written atomically (a temporary file renamed
into place), no link in the cache is followed, and a cache that cannot be used (no home folder, no space,
no permission, a planted link) leaves the import in memory, with a note: never an error of its own.
"""
from __future__ import annotations

import errno
import hashlib
import json
import os
import stat
import tempfile
import warnings
from pathlib import Path

from ..core.errors import DatasetError
from ..core.files import MAX_CSV_BYTES, MAX_TOML_BYTES, read_bytes

#: Bump when the importer's output changes: cached imports of an older importer are imported again.
IMPORTER = "velstep-6"

_STEADYSTATE = dict(
    format="velstep", license="MIT",
    citation="Giacomel, Faulkner, Lambert and Allen, steadystate: A MATLAB-based routine for determining steady-state "
             "friction conditions in the framework of rate-and-state friction analysis, Geosphere 20(3) 965-980 "
             "(2024), doi:10.1130/GES02739.1",
)


def _steadystate(n: int, size: int, sha256: str) -> dict:
    raw = f"velstep{n}_TR2_exp013_sepiolite.txt"
    return dict(_STEADYSTATE, file=f"steadystate/{raw}", size=size, sha256=sha256,
                source=f"pgiacomel/steadystate (GitHub) commit 0225b97, file {raw}: sepiolite gouge, experiment "
                       "TR2 exp013, effective normal stress 30 MPa (sn 50 MPa, Pf 20 MPa)")


#: dataset name -> where its raw record comes from (file below a raw-data folder, its size in bytes and SHA-256).
RECORDS = {
    "sepiolite-velstep1": _steadystate(1, 1032840, "7c1037b7356a1916e5d3ecd22ed45acc0ffb70f812a6fb908d21648464a8ec29"),
    "sepiolite-velstep2": _steadystate(2, 3309739, "7702fa500fe97c8ef345866f376222e600682f5da70ed6e4d4f0d9f8fbb72f40"),
    "sepiolite-velstep3": _steadystate(3, 1384079, "e0d598a177dcb7f3dff040241f490541bec42940e016df541a19559a7b083dc5"),
    "basalt-velstep4": dict(
        _STEADYSTATE, file="steadystate/velstep4_BRAVA_expb819_basalt.txt", size=257407,
        sha256="0ed7d29f21a37335d8191dcb365320d449bf7e52b6557690de34165fb889c959",
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

    builtin = Path(str(resources.files("frictionlab.data")))  # the repository's frictionlab/data/ folder
    return [builtin.resolve().parents[2] / "shared" / "data"]


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _find(name: str) -> tuple[Path | None, bytes | None, str]:
    """(path, bytes) of the record of ``name`` with its checksum, else (None, None, why not)."""
    spec = RECORDS[name]
    why = []
    for folder in raw_dirs():
        path = folder / spec["file"]
        if not os.path.lexists(path):
            continue
        try:
            data = read_bytes(path, MAX_CSV_BYTES)
        except DatasetError as exc:
            why.append(str(exc))
            continue
        if _sha256(data) == spec["sha256"]:
            return path, data, ""
        size = spec.get("size")
        if size and len(data) < size:
            why.append(f"{path} is truncated ({len(data)} of {size} bytes)")
        else:
            why.append(f"{path} has another checksum (SHA-256 {_sha256(data)[:12]}..., not {spec['sha256'][:12]}...)")
    return None, None, "; ".join(why)


def locate(name: str) -> Path | None:
    """The raw record of ``name`` in a raw-data folder, if present with the expected checksum."""
    return _find(name)[0]


def present() -> list[str]:
    """Names of the external datasets whose raw record is present."""
    return [name for name in RECORDS if locate(name) is not None]


def _place_error(name: str, why: str) -> DatasetError:
    spec = RECORDS[name]
    where = " or ".join(str(d / spec["file"]) for d in raw_dirs())
    if why:
        return DatasetError(f"dataset '{name}': the measured record is there but is not the one named: {why}; place "
                            f"the original file ({spec['license']} license, {spec['source'].split(',')[0]}, SHA-256 "
                            f"{spec['sha256'][:12]}...) there")
    return DatasetError(f"dataset '{name}' is a measured record not held in the repository ({spec['license']} license, "
                        f"{spec['source'].split(',')[0]}): place the file at {where} (SHA-256 {spec['sha256'][:12]}...), "
                        "or set FRICTIONLAB_RAW_DATA")


# --- the cache ---------------------------------------------------------------------------------------
def _note(text: str) -> None:
    warnings.warn(text, stacklevel=3)


def cache_root() -> Path | None:
    """The cache folder (absolute): ``platformdirs.user_cache_dir("frictionlab")/external``; None with a note
    when there is none (a relative XDG_CACHE_HOME is ignored, with a note)."""
    xdg = os.environ.get("XDG_CACHE_HOME")
    if xdg and not os.path.isabs(xdg):
        _note(f"XDG_CACHE_HOME={xdg!r} is not an absolute path: ignored")
    try:
        import platformdirs

        base = platformdirs.user_cache_dir("frictionlab")
    except (RuntimeError, KeyError, OSError) as exc:
        _note(f"no cache folder for measured records ({exc}): imported in memory")
        return None
    if not os.path.isabs(base):
        _note(f"no cache folder for measured records ({base!r} is not an absolute path): imported in memory")
        return None
    return Path(base) / "external"


_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)


def _folder(root: Path, key: str) -> Path:
    """``root/key``, made if absent: the user's cache folder may be a link, but no folder of ours
    (frictionlab, external, key) may be one (OSError otherwise)."""
    os.makedirs(root.parent.parent, exist_ok=True)
    path = root.parent.parent
    for part in (root.parent.name, root.name, key):
        path = path / part
        try:
            os.mkdir(path, 0o700)
        except FileExistsError:
            pass
        st = os.lstat(path)
        if not stat.S_ISDIR(st.st_mode):
            raise OSError(errno.ENOTDIR, f"{path} is {'a symbolic link' if stat.S_ISLNK(st.st_mode) else 'not a folder'}")
    return path


def _read(path: Path, limit: int) -> bytes | None:
    """A cached file's bytes, None if absent, not a regular file, a link, or larger than ``limit``."""
    try:
        fd = os.open(path, os.O_RDONLY | _NOFOLLOW | getattr(os, "O_NONBLOCK", 0))
    except OSError:
        return None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or st.st_size > limit:
            return None
        with os.fdopen(os.dup(fd), "rb") as fh:
            return fh.read(limit + 1)
    except OSError:
        return None
    finally:
        os.close(fd)


def _write_all(folder: Path, files: dict[str, bytes]) -> None:
    """Write each file through a temporary file in ``folder`` renamed into place (a link there is replaced,
    never followed), in order, the manifest last; what this call made is removed if any write fails."""
    made = []
    try:
        for name, data in files.items():
            fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{name}.", suffix=".tmp")
            made.append(tmp)
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
            os.replace(tmp, folder / name)
            made[-1] = None
    finally:
        for tmp in made:
            if tmp:
                try:
                    os.unlink(tmp)
                except OSError:
                    pass


def load(name: str) -> tuple[dict, Path, dict]:
    """(TOML table, TOML path, CSV columns) of external record ``name``, what ``dataset.from_meta`` builds its
    Dataset from: from the cache when every checksum agrees, else imported from the record (and cached when
    the cache can be written; the path is then the record's when it is not); a one-line error saying where
    to place the record when it is absent, and how it differs when it is there but is not the one named."""
    from .csvread import read_csv

    spec = RECORDS[name]
    raw_path, data, why = _find(name)
    if raw_path is None:
        raise _place_error(name, why)
    root = cache_root()
    folder = None
    if root is not None:
        try:
            folder = _folder(root, spec["sha256"][:16])
        except OSError as exc:
            _note(f"cannot use the cache folder {root} ({exc.strerror or exc}): {name} imported in memory")
    if folder is not None:
        files = {ext: _read(folder / f"{name}.{ext}", MAX_TOML_BYTES if ext != "csv" else MAX_CSV_BYTES)
                 for ext in ("json", "toml", "csv")}
        stale = _stale(files, spec)
        if not stale:
            import tomllib

            path = folder / f"{name}.toml"
            meta = tomllib.loads(files["toml"].decode("utf-8"))
            return meta, path, read_csv(path.with_suffix(".csv"), text=files["csv"].decode("utf-8"))
        if stale != "absent":
            _note(f"the cached import of {name} in {folder} {stale}: imported again from {raw_path}")
    return _import(name, raw_path, data, folder)


def _stale(files: dict, spec: dict) -> str:
    """'' when the cached files agree with their manifest, the record and this importer; else what differs."""
    if files["json"] is None and files["toml"] is None and files["csv"] is None:
        return "absent"
    try:
        manifest = json.loads(files["json"] or b"")
    except ValueError:
        return "has no readable manifest"
    if not isinstance(manifest, dict):
        return "has no readable manifest"
    if manifest.get("importer") != IMPORTER:
        return "was made by another version of the importer"
    if manifest.get("record") != spec["sha256"]:
        return "was imported from another record"
    for ext in ("toml", "csv"):
        if files[ext] is None:
            return f"has lost its {ext.upper()}"
        if _sha256(files[ext]) != manifest.get(ext):
            return f"has a {ext.upper()} that differs from its checksum (edited?)"
    return ""


def _import(name: str, raw_path: Path, data: bytes, folder: Path | None):
    """Import the record; write the CSV, TOML and manifest into ``folder`` when given and writable."""
    import io

    from .velstep import analyse, dataset_toml, parts, read_raw, write_csv

    spec = RECORDS[name]
    imp = analyse(read_raw(raw_path, data=data), name, joint=None)
    w = imp.windows[0]
    command = f"frictionlab datasets import velstep {raw_path.name} --name {name}" + (" --joint" if len(w.steps) > 1 else "")
    toml = dataset_toml(imp, w, source=spec["source"], license=spec["license"], citation=spec["citation"],
                        command=command)
    meta, cols = parts(imp, w, toml)
    if folder is not None:
        buf = io.StringIO()
        write_csv(buf, imp, w)
        csv = buf.getvalue().encode("utf-8")
        text = toml.encode("utf-8")
        manifest = json.dumps({"importer": IMPORTER, "record": spec["sha256"], "toml": _sha256(text),
                               "csv": _sha256(csv), "file": raw_path.name}, indent=1).encode("utf-8")
        try:
            _write_all(folder, {f"{name}.csv": csv, f"{name}.toml": text, f"{name}.json": manifest})
            return meta, folder / f"{name}.toml", cols
        except OSError as exc:
            _note(f"cannot write the cache folder {folder} ({exc.strerror or exc}): {name} imported in memory")
    return meta, raw_path, cols
