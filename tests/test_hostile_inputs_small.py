"""Malformed SSDs and hostile driver specs: one clean error naming the item, no traceback.

The SSP cases are tiny packages made on the fly (an SSD, and where a
component needs one, an FMU holding only its model description). The table
driver cases point a driver at files that are not numeric tables (a secret,
a binary file, ``/dev/zero``, a huge sparse file, a folder, a pipe) and
check that the problem names the driver and the file and never quotes the
file's first line.
"""

from __future__ import annotations

import json
import math
import os
import zipfile
from pathlib import Path
from xml.sax.saxutils import escape

import pytest

from wire_fmu.interop import read_ssp
from wire_fmu.interop.ssp import NS, SCENE_ANNOTATION, SSD_NAME
from wire_fmu.interop.ssp_read import ssp_scene_data
from wire_fmu.master.drivers import MAX_TABLE_BYTES, make_driver
from wire_fmu.master.scene import SceneError

WHERE = "driver 7 (crane.heave)"
MODEL_DESCRIPTION = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="u"
    guid="{00000000-0000-0000-0000-000000000000}" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="u"/>
  <ModelVariables>
    <ScalarVariable name="mass" valueReference="0" causality="parameter" variability="fixed">
      <Real start="1"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="1" causality="output" variability="continuous">
      <Real/></ScalarVariable>
    <ScalarVariable name="x" valueReference="2" causality="input" variability="continuous">
      <Real start="0"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="2"/></Outputs></ModelStructure>
</fmiModelDescription>"""
SECRET = "TOKEN=ghp_s3cr3t_do_not_print"


# ------------------------------------------------------------------ making packages


def component(name: str = "u", source: str = "resources/u.fmu", inner: str = "") -> str:
    named = f' name="{name}"' if name is not None else ""
    src = f' source="{source}"' if source is not None else ""
    return f"<ssd:Component{named}{src}>{inner}</ssd:Component>"


def parameters(*rows: tuple[str, str, str]) -> str:
    """An inline parameter binding: (name, SSV type, value text) rows."""
    body = "".join(
        f'<ssv:Parameter name="{n}"><ssv:{k} value="{escape(v, {chr(34): "&quot;"})}"/>'
        f"</ssv:Parameter>"
        for n, k, v in rows
    )
    return (
        "<ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>"
        f'<ssv:ParameterSet version="1.0" name="p"><ssv:Parameters>{body}</ssv:Parameters>'
        "</ssv:ParameterSet></ssd:ParameterValues></ssd:ParameterBinding>"
        "</ssd:ParameterBindings>"
    )


def scene_note(meta: object | str) -> str:
    text = meta if isinstance(meta, str) else json.dumps(meta)
    return (
        f'<ssd:Annotations><ssc:Annotation type="{SCENE_ANNOTATION}">'
        f"<wf:Scene>{escape(text)}</wf:Scene></ssc:Annotation></ssd:Annotations>"
    )


def ssd(
    elements: str = "", *, connections: str = "", system_extra: str = "", root_extra: str = ""
) -> str:
    ns = " ".join(f'xmlns:{k}="{v}"' for k, v in NS.items())
    return (
        f'<?xml version="1.0" encoding="UTF-8"?>\n<ssd:SystemStructureDescription {ns} '
        f'version="1.0" name="x"><ssd:System name="x"><ssd:Elements>{elements}'
        f"</ssd:Elements><ssd:Connections>{connections}</ssd:Connections>{system_extra}"
        f"</ssd:System>{root_extra}</ssd:SystemStructureDescription>"
    )


def fmu_bytes() -> bytes:
    from io import BytesIO

    buffer = BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        archive.writestr("modelDescription.xml", MODEL_DESCRIPTION)
    return buffer.getvalue()


def make_package(tmp_path: Path, text: str | bytes, **extra: str | bytes) -> Path:
    path = tmp_path / "hostile.ssp"
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr(SSD_NAME, text)
        archive.writestr("resources/u.fmu", fmu_bytes())
        for name, data in extra.items():
            archive.writestr(name, data)
    return path


def problems_reading(tmp_path: Path, text: str | bytes, **extra: str | bytes) -> str:
    """The message of the one SceneError reading the package raises."""
    path = make_package(tmp_path, text, **extra)
    with pytest.raises(SceneError) as err:
        read_ssp(path, extract_to=tmp_path / "x")
    message = str(err.value)
    assert message.startswith(f"package {path}: ") and "Traceback" not in message
    return message


GOOD_META = {"format": "wire_fmu.scene/1", "name": "x", "run": {"stop_time": 1.0, "step": 0.1}}


# ------------------------------------------------------------------ SSP: references


def test_a_wellformed_small_package_reads(tmp_path):
    path = make_package(tmp_path, ssd(component(inner=parameters(("mass", "Real", "2.5")))))
    scene = read_ssp(path, extract_to=tmp_path / "x")
    assert scene.units["u"].parameters == {"mass": 2.5}
    assert Path(scene.units["u"].fmu) == (tmp_path / "x" / "resources" / "u.fmu").resolve()


@pytest.mark.parametrize(
    "source",
    [
        "../outside.fmu",
        "resources/../../outside.fmu",
        "/etc/passwd",
        "file:///etc/passwd",
        "file:../outside.fmu",
        "http://example.com/u.fmu",
        "C:/u.fmu",
        "resources\\u.fmu",
    ],
)
def test_a_component_source_outside_the_package_is_a_problem(tmp_path, source):
    (tmp_path / "outside.fmu").write_bytes(fmu_bytes())  # present, but not ours to read
    message = problems_reading(tmp_path, ssd(component(source=source)))
    assert f"component 'u': source {source!r} is outside the package" in message


def test_a_missing_component_file_is_named(tmp_path):
    message = problems_reading(tmp_path, ssd(component(source="resources/nope.fmu")))
    assert "component 'u': source 'resources/nope.fmu' is not a file in the package" in message


def test_a_parameter_file_outside_the_package_is_not_read(tmp_path):
    secret = tmp_path / "secret.ssv"
    secret.write_text(f"<x>{SECRET}</x>")
    binding = (
        '<ssd:ParameterBindings><ssd:ParameterBinding source="../secret.ssv"/>'
        "</ssd:ParameterBindings>"
    )
    message = problems_reading(tmp_path, ssd(component(inner=binding)))
    assert "component 'u': parameter binding: source '../secret.ssv' is outside" in message
    assert "ghp_" not in message


def test_a_table_driver_in_the_annotation_must_read_a_file_in_the_package(tmp_path):
    meta = {
        **GOOD_META,
        "drivers": [{"target": "u.x", "spec": {"kind": "table", "file": "/etc/passwd"}}],
    }
    message = problems_reading(tmp_path, ssd(component(), system_extra=scene_note(meta)))
    assert "driver 0: file '/etc/passwd' is outside the package" in message
    assert "root:" not in message


# ------------------------------------------------------------------ SSP: malformed


def test_every_problem_is_listed_in_one_error(tmp_path):
    text = ssd(
        component(inner=parameters(("mass", "Real", "abc")))
        + component(name="v", source="../v.fmu"),
        connections='<ssd:Connection startElement="u" endElement="u" endConnector="x"/>',
        root_extra='<ssd:DefaultExperiment stopTime="soon"/>',
    )
    message = problems_reading(tmp_path, text)
    assert "4 problems" in message
    assert "component 'u': parameter 'mass': Real value 'abc' is not a number" in message
    assert "component 'v': source '../v.fmu' is outside the package" in message
    assert "DefaultExperiment: stopTime 'soon' is not a number" in message
    assert "connection 0 (u.None -> u.x): 'startConnector' is required" in message


def test_stop_time_soon(tmp_path):
    message = problems_reading(
        tmp_path,
        ssd(component(), root_extra=('<ssd:DefaultExperiment startTime="0" stopTime="soon"/>')),
    )
    assert "DefaultExperiment: stopTime 'soon' is not a number" in message


def test_a_step_that_is_not_a_number(tmp_path):
    osp = (
        '<ssd:Annotations><ssc:Annotation type="com.opensimulationplatform"><osp:Algorithm>'
        '<osp:FixedStepAlgorithm baseStepSize="tiny"/></osp:Algorithm></ssc:Annotation>'
        "</ssd:Annotations>"
    )
    message = problems_reading(
        tmp_path,
        ssd(
            component(),
            root_extra=(f'<ssd:DefaultExperiment stopTime="1">{osp}</ssd:DefaultExperiment>'),
        ),
    )
    assert "FixedStepAlgorithm: baseStepSize 'tiny' is not a number" in message


@pytest.mark.parametrize(
    ("kind", "text", "expected"),
    [
        ("Real", "abc", "Real value 'abc' is not a number"),
        ("Real", "", "Real value '' is not a number"),
        ("Integer", "1.5", "Integer value '1.5' is not an integer"),
        ("Integer", "9" * 30, "is out of the 32-bit range"),
        ("Integer", "9" * 5000, "is not an integer"),
        ("Boolean", "maybe", "Boolean value 'maybe' is not true or false"),
    ],
)
def test_a_parameter_value_of_the_wrong_type(tmp_path, kind, text, expected):
    message = problems_reading(tmp_path, ssd(component(inner=parameters(("p", kind, text)))))
    assert "component 'u': parameter 'p': " in message and expected in message
    assert len(message) < 400  # a huge value is not quoted whole


def test_a_parameter_without_name_or_value(tmp_path):
    inner = (
        parameters(("mass", "Real", "1"))
        .replace('name="mass"', "")
        .replace('<ssv:Real value="1"/>', "")
    )
    inner += parameters(("k", "Real", "1")).replace(' value="1"', "")
    message = problems_reading(tmp_path, ssd(component(inner=inner)))
    assert "component 'u': parameter 0 has no 'name'" in message
    assert "component 'u': parameter 'k': the Real element has no 'value'" in message


def test_missing_required_attributes_are_named(tmp_path):
    text = ssd(
        component(name=None) + component(name="w", source=None),
        connections=('<ssd:Connection startElement="w" startConnector="y" endElement="w"/>'),
    )
    message = problems_reading(tmp_path, text)
    assert "element 0 of the system has no 'name'" in message
    assert "component 'w': 'source' is required" in message
    assert "connection 0 (w.y -> w.None): 'endConnector' is required" in message


def test_a_bond_annotation_without_its_attributes(tmp_path):
    bond = (
        '<ssd:Annotations><ssc:Annotation type="org.wire-fmu.bond"><wf:Bond name="b"/>'
        "</ssc:Annotation></ssd:Annotations>"
    )
    connection = (
        f'<ssd:Connection startElement="u" startConnector="y" endElement="u" '
        f'endConnector="x">{bond}</ssd:Connection>'
    )
    message = problems_reading(tmp_path, ssd(component(), connections=connection))
    assert "connection 0 (u.y -> u.x): the bond annotation needs 'name', 'kind'" in message


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (b"<ssd:SystemStructureDescription", "not well-formed XML"),
        (b"\xff\xfe\x00garbage\x00\x01", "not well-formed XML"),
        (b"", "not well-formed XML"),
        (
            "<?xml version='1.0' encoding='latin-1'?><a>\u00e9</a>".encode("utf-8").replace(
                b"latin-1", b"x-no-such-encoding"
            ),
            f"{SSD_NAME}: not",
        ),
    ],
)
def test_an_ssd_that_is_not_xml(tmp_path, text, expected):
    message = problems_reading(tmp_path, text)
    assert f"{SSD_NAME}: " in message and expected in message


@pytest.mark.parametrize(
    ("meta", "expected"),
    [
        ("{not json", "scene annotation (org.wire-fmu.scene): not valid JSON"),
        ("[" * 100_000, "not valid JSON"),
        (
            '{"format": "wire_fmu.scene/1", "run": {"step": 1' + "0" * 40 + "}}",
            "not valid JSON (integer 10000000000000000000... out of range",
        ),
        ([1, 2], "must be a JSON object, got a list"),
        (
            {"format": "wire_fmu.scene/1", "name": "x"},
            "'run' must be an object of run settings (missing)",
        ),
        ({**GOOD_META, "run": [1]}, "'run' must be an object of run settings (a list)"),
        ({**GOOD_META, "run": {"order": 5}}, "run 'order' must be a list of unit names, got 5"),
        ({**GOOD_META, "drivers": {"a": 1}}, "'drivers' must be a JSON array"),
        ({**GOOD_META, "drivers": [{"target": "u.x"}]}, "driver 0 must be an object with a 'spec'"),
        ({**GOOD_META, "events": ["soon"]}, "event 0 must be an object"),
        ({**GOOD_META, "plots": [3]}, "plot 0 must be an object"),
        ({**GOOD_META, "effects": ["friction"]}, "'effects' must be a JSON object"),
        ({**GOOD_META, "signals": ["u"]}, "'signals' must name the signals component"),
    ],
)
def test_a_scene_annotation_of_the_wrong_shape(tmp_path, meta, expected):
    message = problems_reading(tmp_path, ssd(component(), system_extra=scene_note(meta)))
    assert expected in message


def test_external_entities_are_not_expanded(tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text(SECRET)
    text = ssd(
        component(),
        system_extra=scene_note('{"format": "wire_fmu.scene/1", "description": "XXE", "run": {}}'),
    )
    text = text.replace("XXE", "&xxe;").replace(
        "?>",
        f'?>\n<!DOCTYPE ssd:SystemStructureDescription [<!ENTITY xxe SYSTEM "file://{secret}">]>',
        1,
    )
    folder = tmp_path / "x"
    folder.mkdir()
    (folder / SSD_NAME).write_text(text)
    data, problems = ssp_scene_data(folder)
    assert "ghp_" not in repr(data) + repr(problems)


# ------------------------------------------------------------------ table drivers


def table_problems(file: str | Path, base_dir: Path) -> list[str]:
    driver, problems = make_driver(
        {"kind": "table", "file": str(file)}, where=WHERE, base_dir=base_dir
    )
    assert driver is None and problems
    assert all(p.startswith(f"{WHERE}: ") for p in problems)
    return problems


@pytest.mark.parametrize(
    "content",
    [
        f"{SECRET}\nmore\nlines\n",
        f"{SECRET},second\n1,2\n3,4\n",  # numeric rows under it: still not a header we quote
        "root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1\nbin:x:2:2\n",
        "-----BEGIN OPENSSH PRIVATE KEY-----\nb3BlbnNzaC1rZXktdjEAAAAA\nAAAA\n",
        f'"{SECRET}",time,value\n1,2,3\n',
    ],
)
def test_a_file_that_is_not_a_numeric_table_is_not_quoted(tmp_path, content):
    path = tmp_path / "secrets.txt"
    path.write_text(content)
    problems = table_problems(path, tmp_path)
    first_line = content.splitlines()[0]
    text = "\n".join(problems)
    assert str(path) in text
    assert first_line not in text and "ghp_" not in text and "root:" not in text
    assert "BEGIN" not in text


def test_a_long_bad_cell_is_described_not_quoted(tmp_path):
    (tmp_path / "t.csv").write_text(f"time,value\n0,1\n1,{SECRET}\n")
    (problem,) = table_problems("t.csv", tmp_path)
    assert (
        f"'value' is not a finite number in data row 2 (a {len(SECRET)}-character value)" in problem
    )
    assert "ghp_" not in problem


def test_a_binary_file(tmp_path):
    path = tmp_path / "heave.csv"
    path.write_bytes(bytes(range(256)) * 8)
    (problem,) = table_problems(path, tmp_path)
    assert f"table file '{path}' is not UTF-8 text" in problem and "expected a CSV" in problem


def test_dev_zero_is_refused_without_reading_it():
    if not Path("/dev/zero").exists():
        pytest.skip("no /dev/zero here")
    (problem,) = table_problems("/dev/zero", Path("."))
    assert "table file '/dev/zero' is a character device; expected a CSV" in problem


def test_a_huge_file_is_refused_by_its_size(tmp_path):
    path = tmp_path / "huge.csv"
    with path.open("wb") as handle:  # sparse: nothing written to disk
        handle.truncate(MAX_TABLE_BYTES + 1)
    (problem,) = table_problems(path, tmp_path)
    assert f"table file '{path}' is 64 MiB, more than the 64 MiB a table may have" in problem


def test_a_folder_a_pipe_and_a_missing_file(tmp_path):
    (tmp_path / "folder.csv").mkdir()
    assert "table file" in table_problems("folder.csv", tmp_path)[0]
    assert "is a folder; expected a CSV" in table_problems("folder.csv", tmp_path)[0]
    assert "cannot read table file" in table_problems("nope.csv", tmp_path)[0]
    assert "nope.csv': No such file" in table_problems("nope.csv", tmp_path)[0]
    assert "embedded null byte" in table_problems("a\x00b.csv", tmp_path)[0]
    if hasattr(os, "mkfifo"):
        os.mkfifo(tmp_path / "pipe.csv")  # opening it for reading must not hang
        assert "pipe.csv' is a pipe" in table_problems("pipe.csv", tmp_path)[0]


def test_a_csv_with_nul_bytes_or_a_huge_field(tmp_path):
    (tmp_path / "nul.csv").write_bytes(b"time,value\n0,1\x00\n1,2\n")
    assert "is not UTF-8 text" in table_problems("nul.csv", tmp_path)[0]
    (tmp_path / "field.csv").write_text('time,value\n0,"' + "9" * 200_000 + '"\n1,2\n')
    (problem,) = table_problems("field.csv", tmp_path)
    assert "is not a CSV table (field larger than field limit" in problem and "999" not in problem


# ------------------------------------------------------------------ hostile driver specs


@pytest.mark.parametrize(
    ("spec", "expected"),
    [
        ({"kind": "constant", "value": math.nan}, "'value' must be a finite number, got nan"),
        ({"kind": "constant", "value": 10**400}, "'value' must be a finite number, got 1000"),
        ({"kind": "constant", "value": "3"}, "'value' must be a finite number, got '3'"),
        ({"kind": "sine", "amplitude": 1, "period": -2.0}, "'period' must be > 0 s, got -2.0"),
        ({"kind": "sine", "amplitude": 1, "period": 5e-324}, "angular frequency"),
        ({"kind": "sine", "amplitude": 1e308, "period": 1e-3}, "'amplitude' is too large"),
        ({"kind": "sine", "amplitude": 1, "frequency": math.inf}, "'frequency' must be a finite"),
        ({"kind": "ramp", "points": [[0, 0], [5e-324, 1]]}, "slope between entries 0 and 1"),
        ({"kind": "ramp", "points": [[0, -1e308], [1, 1e308]]}, "too large to represent"),
        ({"kind": "ramp", "points": [[0, 10**400], [1, 0]]}, "'points' must be a list"),
        ({"kind": "ramp", "points": [[0.0, 1.0]] * 200_000}, "'points' times must be strictly"),
        ({"kind": "ramp", "points": [["0", 1], [1, 2]]}, "'points' must be a list"),
        (
            {"kind": "ramp", "end_time": math.inf, "start_value": 0, "end_value": 1},
            "'end_time' must be a finite number in s, got inf",
        ),
        (
            {"kind": "sea_state", "significant_height": 1e300, "peak_period": 1e-300},
            "too large to represent",
        ),
        (
            {"kind": "sea_state", "significant_height": 4, "peak_period": 8, "heave_rao": 1e308},
            "too large to represent",
        ),
        (
            {
                "kind": "sea_state",
                "significant_height": 4,
                "peak_period": 8,
                "cutoff": [0.5, 10**400],
            },
            "'cutoff' must be [low, high]",
        ),
        (
            {"kind": "sea_state", "significant_height": 4, "peak_period": 8, "seed": -1},
            "'seed' must be an integer >= 0",
        ),
        (
            {"kind": "sea_state", "significant_height": 4, "peak_period": 8, "components": 1e9},
            "'components' must be an integer, got 1000000000.0",
        ),
        (
            {"kind": "table", "file": "x.csv", "time_column": ["t"] * 1_000_000},
            "'time_column' must be a non-empty string, got a list of 1000000 items",
        ),
        ({"kind": "s" * 1_000_000}, "unknown kind a text of 1000000 characters"),
        ({"kind": "constant", "value": 1, "v" * 1_000_000: 2}, "unknown key a text of 1000000"),
    ],
)
def test_hostile_specs_give_short_clean_problems(spec, expected):
    driver, problems = make_driver(spec, where=WHERE, base_dir=Path("."))
    assert driver is None and problems
    text = "\n".join(problems)
    assert all(p.startswith(f"{WHERE}: ") for p in problems)
    assert expected in text and len(text) < 1000
