"""Hostile zip archives: SSP packages and FMUs that must be refused cleanly.

Every archive is made on the fly and kept small on disk: a zip bomb is
either a few megabytes of zeros checked against a lowered limit, or about
a megabyte of raw deflate blocks that expand to more than the default
1 GiB (each block is 1 MiB of zeros compressed with a full flush, so the
block repeats byte for byte and the archive is written without compressing
a gigabyte). Each test checks the error type, that the message names the
archive and the offending member, and that nothing is left behind.
"""

from __future__ import annotations

import os
import stat
import struct
import tempfile
import time
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path

import pytest
from fmpy import platform, sharedLibraryExtension

from wire_fmu.core.errors import WireFmuError
from wire_fmu.interop import read_ssp
from wire_fmu.interop.ssp import NS, SSD_NAME
from wire_fmu.interop.ssp_read import extract_ssp
from wire_fmu.master.archive import (
    COMPLETE_MARKER,
    DEFAULT_MAX_BYTES,
    ArchiveError,
    ArchiveLimits,
    extract_archive,
    extract_cached,
    extract_temporary,
    remove_extracted,
)
from wire_fmu.master.scene import SceneError
from wire_fmu.master.slave import Slave

MIB = 1 << 20
SSD = f"""<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="{NS["ssd"]}" version="1.0" name="x">
  <ssd:System name="x"/>
</ssd:SystemStructureDescription>"""
MODEL_DESCRIPTION = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="hostile"
    guid="{00000000-0000-0000-0000-000000000000}" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="hostile"/>
  <ModelVariables>
    <ScalarVariable name="x" valueReference="0" causality="output" variability="continuous">
      <Real/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="1"/></Outputs></ModelStructure>
</fmiModelDescription>"""


# ------------------------------------------------------------------ making archives


@dataclass
class Raw:
    """One member of a hand-made zip: its stored bytes and what the headers declare."""

    name: str
    data: bytes  # as stored (deflated if method is 8)
    declared: int  # uncompressed size written in both headers
    crc: int
    method: int = 0  # 0 stored, 8 deflated
    mode: int = stat.S_IFREG | 0o644


def stored(name: str, data: bytes) -> Raw:
    """A stored member that tells the truth."""
    return Raw(name, data, len(data), zlib.crc32(data))


def raw_zip(path: Path, members: list[Raw]) -> Path:
    """Write a zip by hand, so the headers can say what we like."""
    body, central = bytearray(), bytearray()
    for m in members:
        name = m.name.encode()
        offset = len(body)
        body += struct.pack(
            "<4s5H3L2H",
            b"PK\x03\x04",
            20,
            0,
            m.method,
            0,
            0x21,
            m.crc,
            len(m.data),
            m.declared,
            len(name),
            0,
        )
        body += name + m.data
        central += struct.pack(
            "<4s6H3L5H2L",
            b"PK\x01\x02",
            (3 << 8) | 20,
            20,
            0,
            m.method,
            0,
            0x21,
            m.crc,
            len(m.data),
            m.declared,
            len(name),
            0,
            0,
            0,
            0,
            m.mode << 16,
            offset,
        )
        central += name
    end = struct.pack(
        "<4s4H2LH", b"PK\x05\x06", 0, 0, len(members), len(members), len(central), len(body), 0
    )
    path.write_bytes(bytes(body + central + end))
    return path


@pytest.fixture(scope="module")
def zeros_beyond_default() -> tuple[bytes, int, int]:
    """Raw deflate of (default limit + 76 MiB) of zeros: (data, size, crc), about 1.1 MB."""
    size_mib = (DEFAULT_MAX_BYTES >> 20) + 76
    compressor = zlib.compressobj(9, zlib.DEFLATED, -15)
    block = compressor.compress(bytes(MIB)) + compressor.flush(zlib.Z_FULL_FLUSH)
    data = block * size_mib + compressor.flush()
    crc, zeros = 0, bytes(MIB)
    for _ in range(size_mib):
        crc = zlib.crc32(zeros, crc)
    return data, size_mib * MIB, crc


def zip_with(path: Path, members: dict[str, bytes | str], *, deflate: bool = False) -> Path:
    method = zipfile.ZIP_DEFLATED if deflate else zipfile.ZIP_STORED
    with zipfile.ZipFile(path, "w", method) as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return path


def package(path: Path, **extra: bytes | str) -> Path:
    """A small SSP package: the SSD and ``extra`` members."""
    return zip_with(path, {SSD_NAME: SSD, **extra}, deflate=True)


def fmu(path: Path, **extra: bytes | str) -> Path:
    """An FMU that fmpy can describe (no binary unless given in ``extra``)."""
    return zip_with(path, {"modelDescription.xml": MODEL_DESCRIPTION, **extra}, deflate=True)


@pytest.fixture
def private_tmp(tmp_path, monkeypatch) -> Path:
    """The system temporary directory, for this test only (tempfile.gettempdir())."""
    folder = tmp_path / "systmp"
    folder.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(folder))
    return folder


def everything(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


# ------------------------------------------------------------------ extraction


def test_a_good_archive_extracts_once_with_a_marker_and_is_reused(tmp_path):
    path = package(tmp_path / "good.ssp", **{"resources/a.txt": "a", "resources/b/c.txt": "c"})
    into = extract_archive(path, tmp_path / "x", what="package")
    assert everything(into) == sorted(
        [
            COMPLETE_MARKER,
            SSD_NAME,
            "resources",
            "resources/a.txt",
            "resources/b",
            "resources/b/c.txt",
        ]
    )
    (into / "resources" / "a.txt").write_text("changed")  # a reuse must not rewrite it
    assert extract_archive(path, tmp_path / "x", what="package") == into
    assert (into / "resources" / "a.txt").read_text() == "changed"
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_a_bomb_over_a_lowered_limit_is_refused_before_writing(tmp_path):
    path = zip_with(tmp_path / "bomb.ssp", {SSD_NAME: SSD, "zeros": bytes(4 * MIB)}, deflate=True)
    assert path.stat().st_size < 20_000
    with pytest.raises(ArchiveError) as err:
        extract_archive(path, tmp_path / "x", what="package", limits=ArchiveLimits(max_bytes=MIB))
    text = str(err.value)
    assert f"package {path}" in text and "expands to more than 1 MiB" in text and "4 MiB" in text
    assert everything(tmp_path) == ["bomb.ssp"]


def test_a_bomb_over_the_default_limit_is_refused_at_once(tmp_path, zeros_beyond_default):
    data, size, crc = zeros_beyond_default
    path = raw_zip(
        tmp_path / "bomb.ssp",
        [stored(SSD_NAME, SSD.encode()), Raw("zeros", data, size, crc, method=8)],
    )
    assert path.stat().st_size < 2 * MIB
    start = time.perf_counter()
    with pytest.raises(ArchiveError) as err:
        extract_archive(path, tmp_path / "x", what="package")
    assert time.perf_counter() - start < 5.0
    assert f"package {path}" in str(err.value) and "expands to more than 1 GiB" in str(err.value)
    assert everything(tmp_path) == ["bomb.ssp"]


def test_a_member_that_lies_about_its_size_is_cut_at_the_declared_size(
    tmp_path, zeros_beyond_default
):
    """Declared 1 MiB, holds more than 1 GiB: never more than 1 MiB is written."""
    data, _, crc = zeros_beyond_default
    path = raw_zip(
        tmp_path / "liar.ssp",
        [stored(SSD_NAME, SSD.encode()), Raw("zeros", data, MIB, crc, method=8)],
    )
    start = time.perf_counter()
    with pytest.raises(ArchiveError) as err:
        extract_archive(path, tmp_path / "x", what="package")
    assert time.perf_counter() - start < 5.0
    assert "member 'zeros'" in str(err.value) and str(path) in str(err.value)
    assert everything(tmp_path) == ["liar.ssp"]


def test_too_many_members_are_refused(tmp_path):
    path = zip_with(tmp_path / "many.zip", {f"f{i}": "" for i in range(12)})
    with pytest.raises(ArchiveError, match="holds 12 members, more than the limit of 10"):
        extract_archive(path, tmp_path / "x", limits=ArchiveLimits(max_files=10))
    assert everything(tmp_path) == ["many.zip"]


@pytest.mark.parametrize(
    "name", ["../evil", "a/../../evil", "/tmp/evil", "C:/evil", "a\\..\\..\\evil", "./../evil"]
)
def test_a_member_outside_the_folder_is_refused(tmp_path, name):
    path = raw_zip(tmp_path / "up.ssp", [stored(SSD_NAME, SSD.encode()), stored(name, b"x")])
    with pytest.raises(ArchiveError) as err:
        extract_archive(path, tmp_path / "deep" / "x", what="package")
    assert f"package {path}" in str(err.value) and repr(name) in str(err.value)
    assert not (tmp_path / "evil").exists() and not (tmp_path / "deep" / "x").exists()


def test_symbolic_links_and_colliding_names_are_refused(tmp_path):
    path = raw_zip(
        tmp_path / "odd.zip",
        [
            Raw("link", b"/etc/passwd", 11, zlib.crc32(b"/etc/passwd"), mode=stat.S_IFLNK | 0o777),
            stored("a", b"file"),
            stored("a/b", b"under a file"),
            stored("c", b"1"),
            stored("c", b"2"),
        ],
    )
    with pytest.raises(ArchiveError) as err:
        extract_archive(path, tmp_path / "x")
    text = str(err.value)
    assert "'link' is a symbolic link" in text and "'a' is both a file and a folder" in text
    assert "'c' appears twice" in text and "3 problems" in text
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("kind", ["text", "folder", "device", "missing"])
def test_what_is_not_a_zip_file_is_named(tmp_path, kind):
    path = {
        "text": tmp_path / "a.ssp",
        "folder": tmp_path,
        "device": Path("/dev/zero"),
        "missing": tmp_path / "missing.ssp",
    }[kind]
    if kind == "text":
        path.write_text("SECRET=hunter2\n")
    if kind == "device" and not path.exists():
        pytest.skip("no /dev/zero here")
    with pytest.raises(ArchiveError) as err:
        extract_archive(path, tmp_path / "x", what="package")
    text = str(err.value)
    assert f"package {path}" in text and "hunter2" not in text
    expected = {
        "text": "not a valid zip archive",
        "folder": "not a regular file",
        "device": "not a regular file",
        "missing": "cannot read the file",
    }[kind]
    assert expected in text


def test_a_folder_holding_other_files_is_not_overwritten(tmp_path):
    path = package(tmp_path / "p.ssp")
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")
    with pytest.raises(ArchiveError, match="holds other files"):
        extract_archive(path, tmp_path / "mine", what="package")
    assert everything(tmp_path / "mine") == ["notes.txt"]


def test_our_extraction_of_other_content_is_replaced(tmp_path):
    first = package(tmp_path / "one.ssp", **{"resources/one.txt": "1"})
    second = package(tmp_path / "two.ssp", **{"resources/two.txt": "2"})
    extract_archive(first, tmp_path / "x")
    extract_archive(second, tmp_path / "x")
    assert (tmp_path / "x" / "resources" / "two.txt").exists()
    assert not (tmp_path / "x" / "resources" / "one.txt").exists()


# ------------------------------------------------------------------ the package cache


def test_a_half_extracted_cache_folder_is_not_reused(tmp_path, private_tmp):
    path = package(tmp_path / "p.ssp", **{"resources/u.ssv": "<x/>"})
    folder = extract_ssp(path)
    assert folder.parent == private_tmp / "wire_fmu_ssp"
    # a process killed half-way (or the reader before the marker): SSD there, the rest not
    (folder / COMPLETE_MARKER).unlink()
    (folder / "resources" / "u.ssv").unlink()
    again = extract_ssp(path)
    assert again == folder and (again / "resources" / "u.ssv").read_text() == "<x/>"
    assert (again / COMPLETE_MARKER).exists()


def test_a_partial_folder_of_a_killed_process_is_never_used_and_swept_when_old(tmp_path):
    path = package(tmp_path / "p.ssp")
    old = tmp_path / ".x.partial-dead"
    fresh = tmp_path / ".x.partial-running"
    for leftover in (old, fresh):
        leftover.mkdir()
        (leftover / SSD_NAME).write_text("half")
    os.utime(old, (time.time() - 3 * 86400,) * 2)
    into = extract_archive(path, tmp_path / "x")
    assert (into / SSD_NAME).read_text() == SSD
    assert not old.exists() and fresh.exists()  # one may still be at work


def test_the_cache_is_private_to_this_user(tmp_path, private_tmp):
    path = package(tmp_path / "p.ssp")
    extract_ssp(path)
    mode = (private_tmp / "wire_fmu_ssp").stat().st_mode
    assert not mode & (stat.S_IWGRP | stat.S_IWOTH)
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)  # anyone could have planted a "complete" folder here
    folder = extract_cached(path, shared, what="package")
    assert shared not in folder.parents and (folder / SSD_NAME).exists()


# ------------------------------------------------------------------ through the readers


def test_read_ssp_refuses_a_bomb_naming_the_package(tmp_path, private_tmp, zeros_beyond_default):
    data, size, crc = zeros_beyond_default
    path = raw_zip(
        tmp_path / "bomb.ssp",
        [stored(SSD_NAME, SSD.encode()), Raw("resources/zeros", data, size, crc, method=8)],
    )
    with pytest.raises(SceneError) as err:
        read_ssp(path)
    assert f"package {path}" in str(err.value) and "1 GiB" in str(err.value)
    assert everything(private_tmp) == ["wire_fmu_ssp"]


def test_read_ssp_refuses_a_member_outside_the_package(tmp_path, private_tmp):
    path = raw_zip(
        tmp_path / "up.ssp", [stored(SSD_NAME, SSD.encode()), stored("../../evil.fmu", b"x")]
    )
    with pytest.raises(SceneError) as err:
        read_ssp(path, extract_to=tmp_path / "x")
    assert "member '../../evil.fmu' would be written outside the folder" in str(err.value)
    assert str(path) in str(err.value) and not (tmp_path / "x").exists()


def test_an_fmu_bomb_is_refused_at_instantiation_and_leaves_nothing(tmp_path, private_tmp):
    path = fmu(tmp_path / "bomb.fmu", **{"resources/zeros": bytes(4 * MIB)})
    slave = Slave("u", path)
    with pytest.raises(ArchiveError) as err:
        slave.instantiate(limits=ArchiveLimits(max_bytes=MIB))
    assert isinstance(err.value, WireFmuError)
    assert f"FMU {path}" in str(err.value) and "expands to more than 1 MiB" in str(err.value)
    assert everything(private_tmp) == []
    slave.terminate()


def test_an_fmu_member_outside_the_folder_is_refused(tmp_path, private_tmp):
    path = raw_zip(
        tmp_path / "up.fmu",
        [
            stored("modelDescription.xml", MODEL_DESCRIPTION.encode()),
            stored("binaries/../../../evil", b"x"),
        ],
    )
    slave = Slave("u", path)
    with pytest.raises(ArchiveError) as err:
        slave.instantiate()
    assert "'binaries/../../../evil' would be written outside" in str(err.value)
    assert str(path) in str(err.value) and everything(private_tmp) == []


@pytest.mark.parametrize("binary", [None, b"not a shared library"])
def test_a_failed_instantiation_removes_its_folder_and_keeps_the_working_directory(
    tmp_path, private_tmp, binary
):
    extra = (
        {} if binary is None else {f"binaries/{platform}/hostile{sharedLibraryExtension}": binary}
    )
    slave = Slave("u", fmu(tmp_path / "u.fmu", **extra))
    cwd = os.getcwd()
    with pytest.raises(Exception, match="shared library"):
        slave.instantiate()
    assert os.getcwd() == cwd  # fmpy changes into the binary's folder and not back on failure
    assert everything(private_tmp) == []
    slave.terminate()


def test_a_temporary_extraction_is_private_and_removed_on_failure(tmp_path, private_tmp):
    good = extract_temporary(fmu(tmp_path / "u.fmu"), what="FMU", prefix="wire_fmu_fmu_")
    assert good.parent == private_tmp and (good / "modelDescription.xml").exists()
    assert stat.S_IMODE(good.stat().st_mode) == 0o700
    remove_extracted(good)
    bomb = fmu(tmp_path / "bomb.fmu", **{"zeros": bytes(2 * MIB)})
    with pytest.raises(ArchiveError, match=f"FMU {bomb}: 1 problem"):
        extract_temporary(bomb, what="FMU", limits=ArchiveLimits(max_bytes=MIB))
    assert everything(private_tmp) == []
