"""Our scene annotation in an SSD: what SSP has no element for (run settings, drivers,
events, outputs, plots, effects), read back into scene data."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from lxml import etree

from .ssp import SCENE_ANNOTATION
from .ssp_read_files import _annotation, _inside, _shown

_INT64 = (-(2**63), 2**63 - 1)  # an integer in the scene annotation (as TOML allows)


def _json_int(text: str) -> int:
    """A JSON integer as TOML would hold it (64 bits), so later float() calls cannot overflow."""
    value = int(text)
    if not _INT64[0] <= value <= _INT64[1]:
        raise ValueError(f"integer {text[:20]}{'...' if len(text) > 20 else ''} out of range")
    return value


def _scene_metadata(system: etree._Element, problems: list[str]) -> dict[str, Any] | None:
    note = _annotation(system, SCENE_ANNOTATION)
    if note is None or not (note.text or "").strip():
        return None
    where = f"scene annotation ({SCENE_ANNOTATION})"
    try:
        meta = json.loads(note.text, parse_int=_json_int)
    except (ValueError, RecursionError) as err:
        problems.append(f"{where}: not valid JSON ({err})")
        return None
    if not isinstance(meta, dict):
        problems.append(f"{where}: must be a JSON object, got a {type(meta).__name__}")
        return None
    if meta.get("format") != "wire_fmu.scene/1":
        return None  # someone else's annotation of the same type: read the SSD alone
    signals = meta.get("signals")
    if signals is not None and not isinstance(signals, str):
        problems.append(
            f"{where}: 'signals' must name the signals component, got {_shown(signals)}"
        )
        meta["signals"] = None
    for key, kind in (("drivers", list), ("events", list), ("plots", list), ("effects", dict)):
        if key in meta and not isinstance(meta[key], kind):
            problems.append(f"{where}: '{key}' must be a JSON {_JSON_KIND[kind]}")
            meta[key] = kind()
    return meta


_JSON_KIND = {list: "array", dict: "object"}


def _meta_run(meta: dict[str, Any], problems: list[str]) -> dict[str, Any]:
    where = f"scene annotation ({SCENE_ANNOTATION})"
    run = meta.get("run")
    if not isinstance(run, dict):
        got = "missing" if run is None else f"a {type(run).__name__}"
        problems.append(f"{where}: 'run' must be an object of run settings ({got})")
        return {}
    order = run.get("order")
    if order is not None and not (
        isinstance(order, list) and all(isinstance(u, str) for u in order)
    ):
        problems.append(f"{where}: run 'order' must be a list of unit names, got {_shown(order)}")
        run = {k: v for k, v in run.items() if k != "order"}
    # infinity travels as "inf" (strict JSON has none): energy_guard = inf, off
    return {k: math.inf if v == "inf" else v for k, v in run.items() if v is not None}


def _restore(data: dict[str, Any], meta: dict[str, Any], folder: Path, problems: list[str]) -> None:
    """Put back what SSP has no element for, from our annotation."""
    where = f"scene annotation ({SCENE_ANNOTATION})"
    data["description"] = meta.get("description", "")
    data["drivers"] = []
    for i, d in enumerate(meta.get("drivers", [])):
        spec = d.get("spec") if isinstance(d, dict) else None
        if not isinstance(spec, dict):
            problems.append(f"{where}: driver {i} must be an object with a 'spec' object")
            continue
        if spec.get("kind") == "table" and "file" in spec:  # a file it reads: in the package
            _inside(folder, spec["file"], f"{where}: driver {i}", problems, key="file")
        data["drivers"].append(
            {
                "target": d.get("target"),
                **({"rate_target": d["rate_target"]} if d.get("rate_target") else {}),
                **({"label": d["label"]} if d.get("label") else {}),
                **spec,
            }
        )
    data["events"] = []
    for i, e in enumerate(meta.get("events", [])):
        if not isinstance(e, dict):
            problems.append(f"{where}: event {i} must be an object")
            continue
        event = {"time": e.get("time"), "set": e.get("set")}
        if e.get("label") is not None:
            event["label"] = e["label"]
        data["events"].append(event)
    data["outputs"] = {"variables": meta["outputs"] if meta.get("outputs") is not None else "all"}
    data["plots"] = []
    for i, p in enumerate(meta.get("plots", [])):
        if not isinstance(p, dict):
            problems.append(f"{where}: plot {i} must be an object")
            continue
        data["plots"].append({k: p[k] for k in ("title", "ylabel", "variables") if k in p})
    for name, effects in meta.get("effects", {}).items():
        if name in data["units"]:
            data["units"][name]["effects"] = effects
            data["units"][name]["parameters"].pop("effects", None)
