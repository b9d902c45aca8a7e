"""What the compiled-code cache holds, and pruning other versions' code (``wire-fmu cache``).

Every version of a kernel module's sources has its own folder in the cache, never
overwritten by another, so upgrades and edits leave folders behind; ``--prune`` removes
those of other versions than this copy's sources, and nothing else in the cache.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from wire_fmu.cli import main
from wire_fmu.core.framework import compiled
from wire_fmu.core.framework.compiled_cache import (
    cache_folders,
    current_folder_names,
    kernel_modules,
    prune,
)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """An empty cache folder, the one ``WIRE_FMU_CACHE_DIR`` names."""
    folder = tmp_path / "cache"
    folder.mkdir()
    monkeypatch.setenv(compiled.CACHE_ENV, str(folder))
    return folder


def filled(cache) -> tuple[list[str], list[str]]:
    """The cache with a folder of 1000 bytes for each kernel module of these sources, one of
    an older version of each, and things that are not a kernel module's folder."""
    current = sorted(current_folder_names())
    older = [re.sub(r"-[0-9a-f]{16}$", "-0123456789abcdef", name) for name in current]
    for name in current + older:
        (cache / name).mkdir()
        (cache / name / "kernel.rhs-10.py311.nbi").write_bytes(b"x" * 1000)
    (cache / "notes").mkdir()  # not a kernel module's folder: left alone
    (cache / "wire_fmu_readme.txt").write_text("a file, not a folder")
    return current, older


def test_the_kernel_modules_are_those_that_take_their_decorators():
    root = Path(compiled.__file__).resolve().parents[3]  # the folder holding wire_fmu
    names = {p.relative_to(root).as_posix() for p in kernel_modules()}
    assert {
        "wire_fmu/core/units/winch/kernel.py",
        "wire_fmu/core/units/block_train/kernel_outputs.py",
        "wire_fmu/core/units/hydraulics/kernel_quiet_step.py",
        "wire_fmu/core/framework/compiled_step.py",
    } <= names
    assert not any(name.endswith(("compiled.py", "compiled_cache.py")) for name in names)
    # each module's folder is the one its functions' locator gives
    winch = next(p for p in kernel_modules() if p.parent.name == "winch")
    expected = compiled.cache_folder_name(str(winch), compiled.source_digest(str(winch)))
    assert expected in current_folder_names()
    assert re.fullmatch(r"wire_fmu_core_units_winch_kernel-[0-9a-f]{16}", expected)


def test_the_folders_of_these_sources_and_of_other_versions_are_told_apart(cache):
    current, older = filled(cache)
    folders = cache_folders()
    assert sorted(f.path.name for f in folders if f.current) == current
    assert sorted(f.path.name for f in folders if not f.current) == sorted(older)
    assert all(f.size == 1000 for f in folders)


def test_pruning_removes_other_versions_and_nothing_else(cache):
    current, older = filled(cache)
    removed = prune()
    assert sorted(f.path.name for f in removed) == sorted(older)
    left = sorted(p.name for p in cache.iterdir())
    assert left == sorted([*current, "notes", "wire_fmu_readme.txt"])
    assert prune() == []


def test_the_cache_command_says_what_it_holds_and_prunes(cache, capsys):
    current, older = filled(cache)
    assert main(["cache"]) == 0
    text = capsys.readouterr().out
    assert str(cache) in text
    assert f"these sources: {len(current)} folders, {len(current) * 1000 / 1e6:.1f} MB" in text
    assert f"other versions: {len(older)} folders" in text and "--prune" in text
    assert main(["cache", "--prune"]) == 0
    assert f"removed, of other versions: {len(older)} folders" in capsys.readouterr().out
    assert sorted(p.name for p in cache.iterdir() if p.name in current) == current


def test_a_cache_that_does_not_exist_holds_nothing(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path / "none"))
    assert cache_folders() == [] and prune() == []
    assert main(["cache"]) == 0
    assert "these sources: 0 folders, 0.0 MB" in capsys.readouterr().out


def test_a_folder_that_cannot_be_removed_is_named(cache, monkeypatch, capsys):
    filled(cache)

    def refuse(path, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr("wire_fmu.core.framework.compiled_cache.shutil.rmtree", refuse)
    assert main(["cache", "--prune"]) == 1
    out = capsys.readouterr().out
    assert "error: cannot remove" in out and "0123456789abcdef" in out
    assert "Permission denied" in out and "Traceback" not in out


def test_a_cache_that_cannot_be_read_is_named(cache, monkeypatch, capsys):
    def refuse(self):
        raise PermissionError(13, "Permission denied", str(self))

    monkeypatch.setattr("pathlib.Path.iterdir", refuse)
    assert main(["cache"]) == 1
    out = capsys.readouterr().out
    assert f"error: cannot read the cache {cache}: Permission denied" in out
