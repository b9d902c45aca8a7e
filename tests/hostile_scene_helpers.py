"""Shared machinery of the hostile-scene tests: shipped scenes with something wrong in them.

:func:`variant` writes a copy of a shipped scene with text replaced, lines put
at the top of sections or text appended; :func:`problems_of` checks it and
returns the problems (each once, never a traceback); :func:`only` picks the
one problem that names given words. The constants are lines of the shipped
riser tensioner that the variants change.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from wire_fmu.master.run import SCENE_DIR, check_scene
from wire_fmu.master.scene import SceneError

__all__ = [
    "CYL",
    "DRAWWORKS",
    "LONG_BOND",
    "PORTS",
    "RISER",
    "RISER_ROD",
    "only",
    "problems_of",
    "variant",
]

RISER = SCENE_DIR / "riser_tensioner.toml"
DRAWWORKS = SCENE_DIR / "drawworks.toml"


def variant(
    folder: Path,
    base: Path = RISER,
    *,
    replace: dict[str, str] | None = None,
    sections: dict[str, str] | None = None,
    append: str = "",
    name: str = "hostile",
) -> Path:
    """A copy of ``base`` with text replaced, lines put at the top of sections, text appended."""
    text = base.read_text(encoding="utf-8")
    text = re.sub(r'^name = ".*"$', f'name = "{name}"', text, count=1, flags=re.M)
    for old, new in (replace or {}).items():
        assert old in text, old
        text = text.replace(old, new)
    for header, lines in (sections or {}).items():
        assert f"{header}\n" in text, header
        text = text.replace(f"{header}\n", f"{header}\n{lines}\n", 1)
    path = folder / f"{name}.toml"
    path.write_text(text + append, encoding="utf-8")
    return path


def problems_of(path: Path, fmu_dir: Path) -> list[str]:
    with pytest.raises(SceneError) as caught:
        check_scene(path, fmu_dir)
    problems = caught.value.problems
    assert len(problems) == len(set(problems)), "a problem said twice"
    assert not any("Traceback" in p or "Fatal py exception" in p for p in problems)
    return problems


def only(problems: list[str], *words: str) -> str:
    """The one problem that names every word."""
    found = [p for p in problems if all(w in p for w in words)]
    assert len(found) == 1, (words, problems)
    return found[0]


RISER_ROD = (
    '"rod.force" = -1.424e6        # N, 4 x 356 kN at the start: the rod begins in equilibrium'
)
CYL = "[units.cylinder.parameters]"
PORTS = 'ports = "cylinder.rod <-> rope.mover_a"'
LONG_BOND = (  # the riser's bond written out, with its effort going to an unknown unit
    'kind = "translational"\n'
    'effort = "rope.mover_a.force -> piston.rod.force"\n'
    'flow = "cylinder.rod.velocity -> rope.mover_a.velocity"\n'
    'position = "cylinder.rod.displacement -> rope.mover_a.position"'
)
