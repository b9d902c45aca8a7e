"""What an FMU archive of ours holds where, and rewriting one (the standard library only,
and :mod:`~wire_fmu.export.replaced_whole`).

The builder finishes pythonfmu's archive with these; :mod:`wire_fmu.export.start_values`
configures a copy of a finished one.
"""

from __future__ import annotations

import zipfile
from collections.abc import Callable
from pathlib import Path

from wire_fmu.export.replaced_whole import replaced_whole

__all__ = ["FACADE_FILE", "MODEL_DESCRIPTION", "rewrite_zip"]

MODEL_DESCRIPTION = "modelDescription.xml"

FACADE_FILE = "resources/wire_fmu_facade.txt"
"""What the FMU binary instantiates: module, class and GUID, one per line."""


def rewrite_zip(
    archive: Path, add: dict[str, bytes], drop: Callable[[str], bool] = lambda name: False
) -> None:
    """Rewrite ``archive`` in place without the entries ``drop`` selects, with ``add`` added.

    Parameters
    ----------
    archive : Path
        The zip file.
    add : dict of str to bytes
        Entries to write, by name (replacing any of the same name).
    drop : callable
        Whether to leave out an existing entry, by name.
    """
    # a reader sees the archive before or after, never half of it
    with replaced_whole(archive) as rewritten:
        with zipfile.ZipFile(archive) as src, zipfile.ZipFile(rewritten, "w") as dst:
            for item in src.infolist():
                if not drop(item.filename) and item.filename not in add:
                    dst.writestr(item, src.read(item.filename), zipfile.ZIP_DEFLATED)
            for name, data in add.items():
                dst.writestr(name, data, zipfile.ZIP_DEFLATED)
