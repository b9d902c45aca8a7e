"""The layers import only what they may (README, docs/architecture.md)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "wire_fmu"


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
    return names


def _files(folder: str) -> list[Path]:
    return sorted((PACKAGE / folder).rglob("*.py"))


@pytest.mark.parametrize("path", _files("core"), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_the_core_imports_no_fmi_layer(path):
    forbidden = (
        "fmpy",
        "pythonfmu",
        "wire_fmu.master",
        "wire_fmu.export",
        "wire_fmu.study",
        "wire_fmu.tools",
        "wire_fmu.interop",
        "wire_fmu.sweep",
        "wire_fmu.bench",
    )
    bad = [n for n in _imports(path) if n.split(".")[0] in forbidden or n.startswith(forbidden)]
    assert not bad, f"{path.name} imports {bad}"


@pytest.mark.parametrize("path", _files("master"), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_the_master_reaches_units_only_through_fmi(path):
    """Only the exceptions every layer shares may come from the core."""
    bad = [
        n for n in _imports(path) if n.startswith("wire_fmu.core") and n != "wire_fmu.core.errors"
    ]
    bad += [
        n for n in _imports(path) if n.startswith(("pythonfmu", "wire_fmu.tools", "wire_fmu.study"))
    ]
    assert not bad, f"{path.name} imports {bad}"
