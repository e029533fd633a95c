"""Generated datasets are regenerated bit for bit by the project's own command."""
import filecmp
from pathlib import Path

from frictionlab.io.datagen import rebuild
from frictionlab.io.dataset import builtin_dir


def test_rebuild_equals_committed_files(tmp_path):
    written = rebuild(tmp_path)
    assert len(written) >= 10
    for p in written:
        committed = builtin_dir() / p.name
        assert committed.exists(), f"{p.name} is generated but not committed"
        assert filecmp.cmp(p, committed, shallow=False), f"{p.name} differs from the committed file"
    generated = {p.name for p in written}
    for p in Path(builtin_dir()).glob("*.toml"):
        assert p.name in generated, f"{p.name} is committed but no generator makes it"


def test_rebuild_check_command(run_cli):
    out = run_cli("datasets", "rebuild", "--check")
    assert out.returncode == 0, out.stdout + out.stderr
    assert "equal the committed ones" in out.stdout
